"""A job's row keeps its place in the real window (issue 33, item 5): ``meshlap view`` under
Xvfb at 1280×720, the Diffusion view (key 7) showing heat, *play t*: each t is a job (the
system ``M + τK`` refactorized), whose progress row used to come and go above the panel's
widgets, moving them 60 px twice a second (and after Cancel on the scan's exact-distance
job, *clear sources* slid under the pointer).

While *play t* runs, every screenshot's rows of the Diffusion section below its job row are
where they were before it started, and where they are after it paused.
``tests/app/test_job_rows.py`` checks every panel's job row headless.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots.
"""

from __future__ import annotations

import pytest

from tests.support.imgui_screen import Layout, changed_fraction, parse, subject_point
from tests.support.window_session import Session, keep_shots
from tests.support.xwindow import missing_tools

PLAYING_SHOTS = 10  # screenshots taken while t plays (a job starts and ends between them)
HEAT = 0  # the "show" combo's entry for heat (SHOWS)


def rows_below_job(layout: Layout) -> list[int]:
    """The tops of the Diffusion section's rows from its *show* combo on (the job's row,
    above it, is a progress bar, a status line or empty; a slider's kind may read as an input
    with its knob at the left end: only the places are compared)."""
    items = layout.sections[1]
    first = next(i for i, it in enumerate(items) if it.kind == "combo")
    return [it.y0 for it in items[first:]]


@pytest.mark.window
def test_play_t_moves_no_row_of_the_diffusion_panel(tmp_path):
    from meshlap_app.state.diffusion import SHOWS

    assert SHOWS[HEAT] == "heat"
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    s = Session((1280, 720), None, tmp_path)
    try:
        s.goto(7, "Diffusion")
        s.choose(1, 0, HEAT)
        layout = parse(s.settled((0, 0, *s.size), timeout=120))
        point = subject_point(s.img, layout)
        assert point is not None, "no mesh to click left of the panel"
        s.click(point)  # a source: each t of play is then a heat job
        layout = parse(s.settled((0, 0, *s.size), timeout=120))
        items = layout.sections[1]
        combo = next(it for it in items if it.kind == "combo")
        job_row = (layout.left, items[0].y1 + 1, layout.right, combo.y0 - 1)
        still = s.img
        before = rows_below_job(layout)
        play = [it for it in layout.sections[1] if it.kind == "buttons"][1]  # after clear
        s.screenshot("diffusion_heat")
        s.click(play.center)  # play t
        moved, jobs = [], 0
        for k in range(PLAYING_SHOTS):
            s.drawn(2)
            img = s.screenshot(f"diffusion_playing_{k}")
            try:
                now = rows_below_job(parse(img))
            except (LookupError, StopIteration):
                continue  # a panel half drawn
            if now != before:
                moved.append(f"shot {k}: {now} (before: {before})")
            jobs += changed_fraction(still, img, job_row) > 0.01  # a heat job's row
        s.click(play.center)  # pause t
        after = parse(s.settled((0, 0, *s.size), timeout=120))
        s.screenshot("diffusion_paused")
        assert not moved, "\n".join(moved)
        assert jobs, "no heat job's row seen while t played"
        assert rows_below_job(after) == before
        box = (layout.left, layout.sections[1][0].y0, layout.right, s.size[1])
        assert changed_fraction(still, s.img, box) > 0.0, "t did not play (t = ... unchanged)"
        problem = s.problem()
        assert problem is None, problem
    finally:
        keep_shots(s)
        s.close()
