"""Framing in the real window (issue 33, item 6): ``meshlap view`` under Xvfb at 1280×720.

- The Curvature lab (key 8) opened with the camera inside its torus, every time until R: its
  torus is computed after the view is shown, and the view was framed before it existed. Now
  the lab's surface is on screen left of meshlap's panel, not running behind it, on the
  first visit and on the next.
- After a second mesh was opened in another view, the Smoothing view (key 4) stayed empty
  until re-entered or R: its copies came back registered but hidden. Now both copies are
  shown once the new stepper is built.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.support.imgui_screen import parse, subjects
from tests.support.window_session import WAIT, Session, keep_shots, scene_box
from tests.support.xwindow import missing_tools

ROOT = Path(__file__).resolve().parents[2]

LAB_KEY = 8  # the Curvature lab's number (the registry's eighth view)


def shown(n: int):
    """A test of a screenshot: at least ``n`` objects left of the panel."""

    def test(img: np.ndarray) -> bool:
        try:
            return len(subjects(img, parse(img))) >= n
        except LookupError:
            return False

    return test


@pytest.fixture
def session(tmp_path):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    s = Session((1280, 720), None, tmp_path)
    try:
        yield s
    finally:
        keep_shots(s)
        s.close()


@pytest.mark.window
def test_the_lab_opens_with_its_torus_framed_left_of_the_panel(session):
    from meshlap_app.registry import VIEWS

    assert VIEWS[LAB_KEY - 1] == "curvature_lab"
    s = session
    for visit in ("first", "second"):
        s.goto(LAB_KEY, "Curvature lab")
        s.until(shown(1), WAIT, "the lab's surface left of the panel")
        layout = parse(s.settled((0, 0, *s.size), timeout=120))
        s.screenshot(f"lab_{visit}_visit")
        s.subject_ok(layout, 1, f"the lab's torus ({visit} visit)")
        x0, y0, x1, y1 = scene_box(s, layout)
        mask = s.img[y0:y1, x0:x1].astype(int).sum(axis=2) < 600  # not the white background
        assert mask.mean() < 0.6, f"the surface fills the scene ({visit} visit): camera inside"
        s.goto(1, "Curvature")


@pytest.mark.window
def test_smoothing_shows_its_copies_after_a_mesh_opened_in_another_view(session):
    s = session
    s.goto(4, "Smoothing")
    s.until(shown(2), 60, "the input and its smoothed copy")
    s.goto(3, "Spectral")
    layout = parse(s.settled((0, 0, *s.size)))
    before = s.img
    s.click(layout.find(0, "input", 0).center)  # the Mesh section's path field
    s.x.xdotool("type", "--delay", "30", str(ROOT / "assets" / "torus.obj"))
    s.drawn()
    s.key("Return")
    s.until(
        lambda img: "torus.obj" in s.app.title() and (img != before).any(), 60, "the torus opened"
    )
    s.goto(4, "Smoothing")
    s.until(shown(2), 60, "the torus and its smoothed copy in the Smoothing view")
    layout = parse(s.settled((0, 0, *s.size)))
    s.screenshot("smoothing_after_second_mesh")
    s.subject_ok(layout, 2, "the smoothing copies of the second mesh")
