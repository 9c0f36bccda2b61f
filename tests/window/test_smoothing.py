"""Stepping a smoothing run back and forth in the real window (issue 33, item 7):
``meshlap view`` under Xvfb at 1280×720 on the bundled mesh, the Smoothing view (key 4), its
stepper in a child process as always in the window.

``→`` twice, then ``←``: the picture (the smoothed copy and its caption "… 1 step") is
exactly the one after the first ``→`` again, pixel for pixel (the positions kept for that step
come back; before, ``←`` did nothing though the window's page promised it). Then *play* and
*pause*: ``←`` and ``→`` from the paused step come back to the paused picture.
``tests/window/test_scale.py`` checks *pause* on the 692k scan, where the stepper runs ahead.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.imgui_screen import changed_fraction, parse, subjects
from tests.support.window_session import STILL, WAIT, Session, keep_shots, scene_box
from tests.support.xwindow import missing_tools


def both_shown(img: np.ndarray) -> bool:
    try:
        return len(subjects(img, parse(img))) >= 2
    except LookupError:
        return False


def step_key(s: Session, key: str, box: tuple[int, int, int, int]) -> np.ndarray:
    """Press ``key`` on a still picture; the picture once it changed and settled."""
    before = s.settled(box)
    s.key(key)
    s.until(lambda img: changed_fraction(before, img, box) > STILL, WAIT, f"a change after {key}")
    return s.settled(box)


@pytest.mark.window
def test_left_steps_back_to_the_picture_of_the_step_before(tmp_path):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    s = Session((1280, 720), None, tmp_path)
    try:
        s.goto(4, "Smoothing")
        s.until(both_shown, 60, "the input and its smoothed copy once the stepper is built")
        layout = parse(s.settled((0, 0, *s.size)))
        box = scene_box(s, layout)  # the two copies and their captions
        one = step_key(s, "Right", box)
        s.screenshot("smoothing_step_1")
        two = step_key(s, "Right", box)
        assert changed_fraction(one, two, box) > STILL
        back = step_key(s, "Left", box)
        s.screenshot("smoothing_back_to_1")
        assert changed_fraction(one, back, box) <= STILL, "left did not bring step 1 back"
        # play, pause: left then right come back to the paused picture
        start = s.settled(box)
        s.key("space")
        s.until(lambda img: changed_fraction(start, img, box) > STILL, WAIT, "play moving")
        s.key("space")
        paused = s.settled(box)
        step_key(s, "Left", box)
        again = step_key(s, "Right", box)
        assert changed_fraction(paused, again, box) <= STILL, "left, right: not the paused step"
        problem = s.problem()
        assert problem is None, problem
    finally:
        keep_shots(s)
        s.close()
