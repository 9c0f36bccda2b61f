"""A job's progress row keeps its place (issue 33, item 5), headless: every widget of the panel
is where it was before a job started, while it runs and after it ended or was cancelled, as
imgui lays the panel out on ``openGL_mock`` (the rectangles the UI adapter records).

Before, a job's progress bar and Cancel button took two rows that came and went: the
Diffusion panel jumped 60 px twice a second while *play t* ran its jobs, and after Cancel on
the scan's exact-distance job *clear sources* slid under the pointer. Now a job's row is one
row (bar and Cancel), kept empty while no job runs (or taken by a button of the same height:
*compute eigenbasis*, *check*). A text too long for the bar is cut at its end, keeping the
elapsed time; the bar ends inside the panel. ``tests/window/test_job_rows.py`` checks the
same in the real window.
"""

from __future__ import annotations

import threading

import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.ui import fit_text  # noqa: E402


def layout(viewer, frames: int = 2) -> dict:
    """The widgets' rectangles after ``frames`` frames (the last frame's)."""
    for _ in range(frames):
        viewer.ui.rects.clear()
        ps.frame_tick()
    return dict(viewer.ui.rects)


def quiet(viewer) -> dict:
    """The layout once the jobs a view starts by itself (a factorization ahead of the first
    click) are done."""
    for _ in range(20):
        assert viewer.state.jobs.wait(timeout=120)
        ps.frame_tick()
        if not viewer.state.jobs.busy:
            break
    return layout(viewer)


def held_job(viewer, owner: str, title: str) -> threading.Event:
    """Start a job for ``owner`` that runs until the returned event is set."""
    release = threading.Event()

    def work(reporter):
        reporter(0.4, "a phase whose name is long enough to be cut at the end of the bar")
        release.wait(60)
        return None

    viewer.state.jobs.start(owner, title, work, lambda r: None, background=True)
    return release


def moved(before: dict, after: dict, skip: tuple[str, ...] = ()) -> list[str]:
    """The widgets drawn in both layouts at different places (labels in ``skip`` aside)."""
    out = []
    for key, rect in before.items():
        if key in after and key[1] not in skip and rect != after[key]:
            out.append(f"{key}: {rect} -> {after[key]}")
    return out


# (view, job owner, a widget that takes the row's place when no job runs)
CASES = [
    ("diffusion", "diffusion", None),
    ("curvature", "curvature", None),
    ("curvature", "principal curvatures", None),  # (the estimator's job: PRINCIPAL_JOB)
    ("smoothing", "smoothing", None),
    ("curvature_lab", "curvature_lab", None),
    ("curvature_lab", "curvature_lab study", None),
    ("spectral", "spectral", "compute eigenbasis"),
    ("curvature", "mesh_info", None),  # opening a mesh: the Mesh section's row
]


@pytest.mark.parametrize(("view", "owner", "button"), CASES, ids=[c[1] for c in CASES])
def test_widgets_keep_their_place_before_while_and_after_a_job(viewer, view, owner, button):
    from meshlap_app.panels.curvature import PRINCIPAL_JOB

    assert PRINCIPAL_JOB in {c[1] for c in CASES}
    viewer.background = True
    viewer.set_panel(view)
    before = quiet(viewer)
    assert before, "nothing drawn"
    release = held_job(viewer, owner, f"a held job of {owner}")
    try:
        during = layout(viewer)
        cancel = f"Cancel##{owner}"
        assert any(k[1] == cancel for k in during), "no Cancel button while the job runs"
        skip = (cancel, *([button] if button else []))
        assert not moved(before, during, skip), moved(before, during, skip)
        viewer.ui.script(cancel, True)  # Cancel, under the pointer
        ps.frame_tick()
        assert viewer.state.jobs.running(owner) is None
        after = layout(viewer)
        assert not moved(before, after), moved(before, after)
        assert set(before) <= set(after)
    finally:
        release.set()
        viewer.state.jobs.cancel_all()


def test_a_job_ending_by_itself_moves_nothing_either(viewer):
    viewer.background = True
    viewer.set_panel("diffusion")
    before = quiet(viewer)
    release = held_job(viewer, "diffusion", "a job that ends")
    layout(viewer)
    release.set()
    assert viewer.state.jobs.wait("diffusion", timeout=30)
    assert not moved(before, layout(viewer)), moved(before, layout(viewer))


def test_a_job_of_a_view_not_shown_is_drawn_after_every_widget(viewer):
    """A job whose panel is not on screen gets its row at the panel's end: nothing above
    moves when it comes or goes."""
    viewer.background = True
    viewer.set_panel("curvature")
    before = quiet(viewer)
    release = held_job(viewer, "spectral", "an eigenbasis elsewhere")
    try:
        during = layout(viewer)
        assert not moved(before, during), moved(before, during)
        bottom = max(r[3] for k, r in before.items())
        cancel = during[("jobs", "Cancel##spectral")]
        assert cancel[1] >= bottom  # below every widget
    finally:
        release.set()
        viewer.state.jobs.cancel_all()


def test_long_progress_text_is_cut_at_its_end_keeping_the_elapsed_time(viewer, monkeypatch):
    drawn: list[tuple[float, str, float]] = []
    im = viewer.ui.im
    real = im.ProgressBar

    def spy(fraction, size, text):  # at the row.s start: its right end is the content.s
        right = float(im.GetCursorScreenPos()[0]) + float(im.GetContentRegionAvail()[0])
        drawn.append((float(size[0]), text, right))
        return real(fraction, size, text)

    monkeypatch.setattr(im, "ProgressBar", spy)
    viewer.background = True
    viewer.set_panel("diffusion")
    release = held_job(viewer, "diffusion", "computing the exact geodesic distance on a scan")
    try:
        layout(viewer, 1)
        width, text, content_right = drawn[-1]
        assert text.startswith("computing the exact geodesic") and "..." in text
        assert text.endswith(" s (40 %)")  # the tail that moves stays whole
        pad = 2 * float(im.GetStyle().FramePadding[0])
        assert float(im.CalcTextSize(text)[0]) <= width - pad  # fits in its bar
        # the bar and its Cancel button end inside the panel's content region
        right = viewer.ui.rects[("diffusion", "Cancel##diffusion")][2]
        assert right <= content_right + 0.5
    finally:
        release.set()
        viewer.state.jobs.cancel_all()


def test_fit_text_cuts_at_the_end():
    def measure(s: str) -> tuple[float, float]:
        return (7.0 * len(s), 13.0)

    assert fit_text("short", 100, measure) == "short"
    # at most 10 characters of 7 px: "a long l..." is 11; the space before the dots goes
    assert fit_text("a long line of text", 70, measure) == "a long..."
    assert fit_text("abc", 10, measure) == "..."
