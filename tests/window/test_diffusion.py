"""The Diffusion view in a real window (``meshlap view`` under Xvfb, driven with xdotool): its
number key (7), a click on the mesh, and what a user then sees: the distance from that vertex
coloured over the mesh with its colour bar and its isolines; a shift-click adds a second source
(the field changes, the first source stays: a plain click afterwards changes it again).

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.imgui_screen import (
    COLORBAR_BOX,
    Layout,
    changed_fraction,
    parse,
    subject_mask,
    subject_point,
)
from tests.support.window_session import WAIT, Session, keep_shots, scene_box
from tests.support.xwindow import missing_tools

DIFFUSION_KEY = "7"  # the registry's seventh view (app/registry.py)


def hues(img: np.ndarray, layout: Layout) -> int:
    """How many of 12 hue sectors hold at least 0.5 % of the subject's coloured pixels (the
    blue mesh, shaded: 1; viridis over it, lit: 4 measured, purple to teal on the side seen)."""
    mask = subject_mask(img, layout)
    c = img[:, : layout.left][mask].astype(np.float64)
    spread = c.max(axis=1) - c.min(axis=1)
    c = c[spread > 30]
    if len(c) < 500:
        return 0
    r, g, b = c.T
    hue = np.degrees(np.arctan2(np.sqrt(3.0) * (g - b), 2 * r - g - b)) % 360
    counts = np.bincount((hue // 30).astype(int), minlength=12)
    return int(np.count_nonzero(counts >= 0.005 * len(c)))


def bands(img: np.ndarray, layout: Layout, x: int) -> int:
    """Edges of polyscope's isoline stripes (alternate bands darkened) down the column ``x``
    inside the subject: brightness steps over 8 from one pixel to the next (measured 10–22 at
    the edges; smooth shading changes by at most 3.3)."""
    mask = subject_mask(img, layout)[:, x]
    ys = np.flatnonzero(mask)
    if len(ys) < 20:
        return 0
    col = img[ys[0] : ys[-1] + 1, x].astype(np.int32).sum(axis=1) / 3.0
    return int(np.count_nonzero(np.abs(np.diff(col)) > 8))


def colour_bar(img: np.ndarray) -> int:
    """Strongly coloured pixels where polyscope draws the on-screen colour bar."""
    x0, y0, x1, y1 = COLORBAR_BOX
    c = img[y0:y1, x0:x1].astype(np.int16)
    return int(((c.max(axis=-1) - c.min(axis=-1)) > 80).sum())


@pytest.mark.window
def test_diffusion_view_click_shows_the_distance_and_its_isolines(tmp_path_factory):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    s = Session((1280, 720), None, tmp_path_factory.mktemp("diffusion"))
    try:
        layout = s.goto(int(DIFFUSION_KEY), "Diffusion")
        before = s.settled((0, 0, *s.size))
        s.screenshot("diffusion_opened")
        assert hues(before, layout) <= 1, "the mesh is coloured before any click"
        point = subject_point(before, layout)
        assert point is not None, "no mesh to click left of the panel"
        s.click(point)

        def distance_shown(img: np.ndarray) -> bool:
            return hues(img, layout) >= 3 and colour_bar(img) > 500

        one = s.until(distance_shown, 2 * WAIT, f"distance field after a click at {point}")
        one = s.settled(scene_box(s, layout))
        s.screenshot("diffusion_distance")
        crossings = max(bands(one, layout, point[0] + dx) for dx in (-30, 0, 30))
        assert crossings >= 4, f"{crossings} isoline crossings down the mesh"

        # shift-click a second vertex: a second source, the field changes
        mask = subject_mask(one, layout)
        row = np.flatnonzero(mask[point[1]])
        second = (int(row[len(row) // 6]), point[1])  # left part of the mesh, same height
        s.x.xdotool("keydown", "shift")
        s.drawn()
        s.click(second)
        s.x.xdotool("keyup", "shift")
        s.drawn()
        two = s.until(
            lambda img: changed_fraction(one, img, scene_box(s, layout)) > 0.01,
            WAIT,
            "a new field after a shift-click",
        )
        two = s.settled(scene_box(s, layout))
        s.screenshot("diffusion_two_sources")
        assert distance_shown(two)
        # the panel lists both sources: its text changed too
        panel = (layout.left, 0, layout.right, s.size[1])
        assert changed_fraction(one, two, panel) > 0.0005, "the panel still lists one source"
        assert parse(two).left == layout.left  # the panel did not move
        assert s.problem() is None, s.problem()
    finally:
        s.screenshot("diffusion_last")
        keep_shots(s)
        s.close()
