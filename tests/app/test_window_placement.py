"""Where the window goes and what it is called (pure parts of :mod:`meshlap_app.window`; the real
window in ``tests/window/test_open.py`` and the tour): fitted inside the screen's work area with
its frame, centred when smaller, titled after its mesh only when the title can follow it."""

from __future__ import annotations

import pytest
from meshlap_app.window import PRODUCT, fit_window, window_title


@pytest.mark.parametrize(
    ("area", "wanted", "frame", "expected"),
    [
        # polyscope's 1280×720 on a 1280×720 screen without a window manager: the whole screen
        ((0, 0, 1280, 720), (1280, 720), (0, 0, 0, 0), (0, 0, 1280, 720)),
        # on 1920×1080: kept, centred ((1920-1280)/2, (1080-720)/2)
        ((0, 0, 1920, 1080), (1280, 720), (0, 0, 0, 0), (320, 180, 1280, 720)),
        # a 30-pixel title bar and 2-pixel borders on 1280×720: the content shrinks so the
        # frame fits too (1276 = 1280-2-2, 688 = 720-30-2), its corner inside the frame
        ((0, 0, 1280, 720), (1280, 720), (2, 30, 2, 2), (2, 30, 1276, 688)),
        # a work area less a 40-pixel top panel, on a second monitor at x = 1920
        ((1920, 40, 1024, 728), (1280, 720), (0, 0, 0, 0), (1920, 44, 1024, 720)),
    ],
)
def test_the_window_and_its_frame_fit_inside_the_work_area(area, wanted, frame, expected):
    x, y, w, h = fit_window(area, wanted, frame)
    assert (x, y, w, h) == expected
    ax, ay, aw, ah = area
    left, top, right, bottom = frame
    assert ax <= x - left and x + w + right <= ax + aw
    assert ay <= y - top and y + h + bottom <= ay + ah


def test_a_window_smaller_than_the_screen_keeps_its_size_and_is_centred():
    for wanted in ((800, 600), (1, 1), (1919, 1079)):
        x, y, w, h = fit_window((0, 0, 1920, 1080), wanted)
        assert (w, h) == wanted
        assert abs(x - (1920 - x - w)) <= 1 and abs(y - (1080 - y - h)) <= 1


def test_the_title_names_the_mesh_only_when_it_can_follow_it():
    assert window_title("bumpy.obj", True) == f"{PRODUCT} — bumpy.obj"
    # set once at the window's creation, a mesh name would go on naming the first mesh
    assert window_title("bumpy.obj", False) == PRODUCT
    assert window_title(None, True) == PRODUCT
