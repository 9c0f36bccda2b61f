"""The Deform view in a real window (``meshlap view`` under Xvfb, driven with xdotool): its
number key, a click on the mesh (a handle: its disc drawn, the panel lists it), then that
handle dragged up with the mouse: the mesh's shape changes on screen (its top rises with the
handle, the held bottom stays), and undo (Z) brings the shape back.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots.
"""

from __future__ import annotations

import numpy as np
import pytest
from imgui_screen import Layout, changed_fraction, subject_mask, subject_point
from meshlap_app.registry import VIEWS
from test_window import WAIT, Session, keep_shots, scene_box
from xwindow import missing_tools

DEFORM_KEY = str(VIEWS.index("deform") + 1)  # the view's number key


def top_row(img: np.ndarray, layout: Layout) -> int:
    """The highest row of the mesh on screen (its silhouette's top)."""
    rows = np.flatnonzero(subject_mask(img, layout).any(axis=1))
    return int(rows[0]) if len(rows) else img.shape[0]


def handle_dots(img: np.ndarray, layout: Layout) -> int:
    """Pixels of the handle's disc drawn in yellow (the active handle's points) on the mesh."""
    c = img[:, : layout.left].astype(np.int16)
    r, g, b = c[..., 0], c[..., 1], c[..., 2]
    return int(((r > 200) & (g > 150) & (b < 80)).sum())


def drag_a_handle(s: Session) -> None:
    """The deform step of a tour (also ``tests/test_window.py``'s): the view's key, a click on
    the mesh (a handle: its disc drawn), the handle dragged up (the mesh's top rises, its held
    bottom stays), Z (the rest shape back)."""
    layout = s.goto(int(DEFORM_KEY), "Deform")
    scene = scene_box(s, layout)
    before = s.settled(scene)
    s.screenshot("deform_opened")
    assert handle_dots(before, layout) < 20, "a handle drawn before any click"
    point = subject_point(before, layout)
    assert point is not None, "no mesh to click left of the panel"
    s.click(point)  # press and release in place: a click, the vertex becomes a handle
    s.until(
        lambda img: handle_dots(img, layout) >= 20,
        2 * WAIT,
        f"the handle's disc drawn after a click at {point}",
    )
    one = s.settled(scene)
    s.screenshot("deform_handle")
    rest_top = top_row(one, layout)
    # press on the handle's disc (beside its centre, where the gizmo's arrows start) and drag
    # it up: it follows the mouse in the screen plane, the mesh follows it
    a = (point[0] + 4, point[1] + 4)
    s.drag(a, (a[0], a[1] - 120), steps=8)
    s.until(
        lambda img: top_row(img, layout) < rest_top - 20,
        2 * WAIT,
        "the mesh's top rising after dragging the handle up",
    )
    moved = s.settled(scene)
    s.screenshot("deform_dragged")
    assert changed_fraction(one, moved, scene) > 0.01
    h = s.size[1]
    low = (0, int(0.85 * h), layout.left, h)  # the held bottom (and its shadow) stays
    assert changed_fraction(one, moved, low) < 0.05
    s.key("z")  # undo the drag: the rest shape comes back
    back = s.until(
        lambda img: abs(top_row(img, layout) - rest_top) <= 3,
        2 * WAIT,
        "the rest shape back after Z (undo)",
    )
    s.screenshot("deform_undone")
    assert changed_fraction(one, back, scene) < changed_fraction(one, moved, scene)


@pytest.mark.window
def test_deform_view_click_a_handle_and_drag_it(tmp_path_factory):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    s = Session((1280, 720), None, tmp_path_factory.mktemp("deform"))
    try:
        drag_a_handle(s)
        assert s.problem() is None, s.problem()
    finally:
        s.screenshot("deform_last")
        keep_shots(s)
        s.close()
