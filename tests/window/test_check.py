"""The Check panel in a real window (``meshlap view`` under Xvfb, driven with xdotool like a
user, as ``tests/window/test_tour.py``): its number key, a student file typed into the path field,
its task picked, *check*: the difference map appears on the mesh, red around the one vertex the
student got wrong and nowhere else in the scene.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshlap_core.exercises.tasks import EXERCISE_TASKS
from tests.support.imgui_screen import parse
from tests.support.students import ONE_VERTEX_WRONG, facing_vertex
from tests.support.window_session import Session, keep_shots, scene_box
from tests.support.xwindow import missing_tools

CHECK_KEY = 6  # the Check panel's number key (its place among the registry's views)


def red_in_scene(img: np.ndarray, box: tuple[int, int, int, int]) -> np.ndarray:
    """(y, x) of reddish pixels (coolwarm's positive side) in the scene, right of the colour
    bar's strip at the window's left edge."""
    x0, y0, x1, y1 = box
    part = img[y0:y1, x0:x1].astype(int)
    red = (part[..., 0] - part[..., 2] > 50) & (part[..., 0] > 115)
    red[:, : int(0.1 * img.shape[1])] = False  # the colour bar (red at its top)
    return np.argwhere(red)


@pytest.mark.window
def test_check_panel_shows_where_the_student_is_wrong(tmp_path):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    from meshlap_app.registry import VIEWS

    assert VIEWS.index("check") + 1 == CHECK_KEY
    student = tmp_path / "one_wrong.py"
    student.write_text(ONE_VERTEX_WRONG.replace("{target}", str(facing_vertex())))
    s = Session((1280, 720), None, tmp_path / "window")
    try:
        layout = s.goto(CHECK_KEY, "Check")
        s.screenshot("check_panel")
        s.click(layout.find(1, "input", 0).center)  # the student file field
        s.x.xdotool("type", "--delay", "30", str(student))
        s.drawn()
        s.key("Return")
        s.choose(1, 0, EXERCISE_TASKS.index("barycentric_areas"))  # the task combo
        layout = parse(s.settled((0, 0, *s.size)))
        box = scene_box(s, layout)
        assert len(red_in_scene(s.img, box)) == 0, "red in the scene before any check"
        s.screenshot("check_file_typed")
        row = layout.find(1, "buttons", 0)  # "check"
        s.click(((row.buttons[0][0] + row.buttons[0][1]) // 2, row.center[1]))
        img = s.until(
            lambda img: len(red_in_scene(img, box)) > 10, 120, "the difference map's red spot"
        )
        img = s.settled((0, 0, *s.size))
        s.screenshot("check_map")
        red = red_in_scene(img, box)
        spread = red.max(axis=0) - red.min(axis=0)
        assert (spread < 0.08 * s.size[1]).all(), f"red spread over {spread} pixels"
        assert s.problem() is None, s.problem()
    finally:
        keep_shots(s)
        s.close()
