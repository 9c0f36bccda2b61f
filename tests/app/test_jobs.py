"""The viewer's job system (``meshlap_app.jobs``) and frame pacing (``meshlap_app.pacing``),
headless: progress, cancel, failures that keep the state, results applied only on poll, one job
per owner; the pacer's full / busy / idle rates."""

from __future__ import annotations

import threading

import pytest
from meshlap_app.jobs import Cancelled, Jobs, Reporter, accepts, call_hooked
from meshlap_app.pacing import Pacer

from meshlap_core.errors import MeshError


class Clock:
    """A settable clock (seconds)."""

    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_result_applied_only_on_poll_on_the_calling_thread():
    jobs = Jobs()
    release = threading.Event()
    applied: list[tuple[int, str]] = []

    def work(report: Reporter) -> int:
        report(0.5, "half way")
        release.wait(10)
        return 42

    job = jobs.start(
        "a", "answer", work, lambda r: applied.append((r, threading.current_thread().name))
    )
    assert job is not None and job.running and jobs.busy
    assert jobs.poll() == [] and applied == []  # still working
    release.set()
    job.thread.join(10)
    assert applied == []  # finished, but nothing applied before poll
    assert jobs.poll() == [job]
    assert applied == [(42, threading.current_thread().name)]
    assert job.status == "done" and not jobs.busy and jobs.running("a") is None


def test_progress_line_phase_fraction_and_elapsed():
    clock = Clock()
    jobs = Jobs(clock=clock, background=False)
    lines: list[str] = []

    def work(report: Reporter) -> None:
        report(None, "reading")
        clock.t += 2.0
        lines.append(job_line())
        report(0.4, "validating")
        clock.t += 1.0
        lines.append(job_line())

    def job_line() -> str:
        return jobs.running("m").line()

    jobs.start("m", "opening x.obj", work, lambda r: None)
    assert lines == ["opening x.obj: reading, 2.0 s", "opening x.obj: validating, 3.0 s (40 %)"]


def test_cancel_discards_the_result_and_keeps_the_state():
    jobs = Jobs()
    state = {"mesh": "old"}
    started = threading.Event()

    def work(report: Reporter) -> str:
        started.set()
        for _ in range(1000):
            report(None, "working")  # raises Cancelled once cancelled
            threading.Event().wait(0.005)
        return "new"

    job = jobs.start("m", "load", work, lambda r: state.update(mesh=r))
    started.wait(10)
    assert jobs.cancel("m") and jobs.running("m") is None and not jobs.busy
    job.thread.join(10)
    assert job.outcome == "cancelled"
    jobs.poll()
    assert state == {"mesh": "old"} and jobs.cancelled == 1


def test_a_result_that_arrives_after_cancel_is_thrown_away():
    jobs = Jobs()
    go = threading.Event()
    state: list[str] = []
    job = jobs.start("m", "load", lambda r: go.wait(10) and "new", state.append)
    jobs.cancel("m")
    go.set()
    job.thread.join(10)
    assert jobs.poll() == [] and state == []


def test_failure_reports_on_poll_and_keeps_the_state():
    jobs = Jobs(background=False)
    state = {"mesh": "old"}
    errors: list[str] = []

    def work(report: Reporter) -> str:
        raise MeshError("face 3 has index 9", "bad.obj")

    job = jobs.start("m", "load", work, lambda r: state.update(mesh=r), errors.append)
    assert job.status == "failed" and errors == ["bad.obj: face 3 has index 9"]
    assert state == {"mesh": "old"}

    def crash(report: Reporter) -> None:
        raise ZeroDivisionError("boom")

    jobs.start("m", "load", crash, lambda r: None, errors.append)
    assert errors[-1] == "ZeroDivisionError: boom"


def test_one_job_per_owner_new_replaces_old_or_is_refused():
    jobs = Jobs()
    hold = threading.Event()
    out: list[str] = []
    first = jobs.start("p", "one", lambda r: hold.wait(10) and "one", out.append)
    refused = jobs.start("p", "two", lambda r: "two", out.append, replace=False)
    assert refused is None and jobs.running("p") is first
    other = jobs.start("q", "other owner", lambda r: "q", out.append)
    second = jobs.start("p", "three", lambda r: "three", out.append)  # replaces: first cancelled
    assert first.cancel_event.is_set() and jobs.running("p") is second
    hold.set()
    assert jobs.wait(timeout=10)
    assert sorted(out) == ["q", "three"] and other.status == "done"


def test_call_hooked_passes_progress_and_cancel_only_when_accepted():
    reporter = Reporter(threading.Event())
    got: dict[str, object] = {}

    def old_core(x: int) -> int:
        return x

    def new_core(x: int, progress=None, cancel=None) -> int:
        got.update(progress=progress, cancel=cancel)
        return x + 1

    assert call_hooked(old_core, 1, reporter=reporter) == 1
    assert call_hooked(new_core, 1, reporter=reporter) == 2
    assert got == {"progress": reporter, "cancel": reporter.cancel}
    assert accepts(new_core, "cancel") and not accepts(old_core, "cancel")
    reporter.cancel.set()
    with pytest.raises(Cancelled):
        reporter(0.5, "next phase")


def test_pacer_full_rate_on_input_busy_then_idle():
    clock = Clock()
    slept: list[float] = []

    def sleep(s: float) -> None:
        slept.append(s)
        clock.t += s

    p = Pacer(clock=clock, sleep=sleep)
    p.wait(busy=False)
    assert p.mode == "active" and slept == []  # the first frame never waits
    clock.t += 0.001
    p.wait(busy=False)
    assert p.mode == "active" and slept[-1] == pytest.approx(1 / p.full_fps - 0.001)
    clock.t += 2.0  # no input for 2 s
    p.wait(busy=True)
    assert p.mode == "busy"
    p.wait(busy=True)
    assert slept[-1] == pytest.approx(1 / p.busy_fps)
    assert p.max_busy_gap == pytest.approx(2.0)  # the longest gap between two busy frames
    p.wait(busy=False)
    assert p.mode == "idle" and slept[-1] == pytest.approx(1 / p.idle_fps)
    clock.t += p.deep_after  # longer without input: the deep idle rate
    p.wait(busy=False)
    p.wait(busy=False)
    assert p.mode == "idle" and slept[-1] == pytest.approx(1 / p.deep_fps)
    p.touch()
    p.wait(busy=False)
    assert p.mode == "active"
    assert p.rate(busy=False, animating=True) == p.full_fps


def _child_work(n: int, progress=None) -> int:
    """A child process's work: reports, then sleeps (cancelled from the parent) or fails."""
    import time

    progress(0.5, "in the child")
    if n < 0:
        raise MeshError("refused", "child")
    if n == 0:
        time.sleep(60)
    return n * 2


def test_in_child_reports_returns_fails_and_is_ended_by_cancel():
    from meshlap_app.jobs import in_child

    jobs = Jobs()
    out: list[int] = []
    errors: list[str] = []
    job = jobs.start("c", "child", in_child(_child_work, 21), out.append, errors.append)
    assert jobs.wait(timeout=120) and out == [42] and job.reporter.phase == "in the child"
    jobs.start("c", "child", in_child(_child_work, -1), out.append, errors.append)
    assert jobs.wait(timeout=120) and errors == ["child: refused"]
    job = jobs.start("c", "child", in_child(_child_work, 0), out.append, errors.append)
    for _ in range(2000):  # until the child reported
        if job.reporter.reports:
            break
        threading.Event().wait(0.01)
    jobs.cancel("c")
    job.thread.join(30)  # the child was ended: no 60 s wait
    assert not job.thread.is_alive() and job.outcome == "cancelled" and out == [42]


def test_nap_is_woken_by_a_partial_result_and_by_a_finished_job():
    """The window's pause between frames ends as soon as a job has something to show (a
    partial result, a result); without news it sleeps its whole time."""
    import time

    jobs = Jobs()
    go, handed = threading.Event(), threading.Event()

    def work(reporter):
        go.wait(30)
        reporter.partial("half")
        handed.wait(30)
        return "whole"

    shown, done = [], []
    jobs.start("j", "t", work, done.append, preview=shown.append)
    t0 = time.monotonic()
    jobs.nap(0.05)  # no news: the whole pause
    assert time.monotonic() - t0 >= 0.05 and not jobs.news.is_set()
    go.set()
    t0 = time.monotonic()
    jobs.nap(60.0)  # woken by the partial result, long before 60 s
    assert time.monotonic() - t0 < 30 and jobs.news.is_set()
    jobs.poll()
    assert shown == ["half"] and not jobs.news.is_set()  # poll takes the news
    handed.set()
    jobs.nap(60.0)  # woken by the result
    assert jobs.news.is_set()
    jobs.poll()
    assert done == ["whole"] and not jobs.busy


def test_pacer_never_pauses_a_frame_that_starts_with_input():
    """A frame that starts with input pending (the key arrived while the last frame was
    drawn, or ended the last pause) is answered at once: no pause, the full rate from then on.
    Before, the pause came before the frame read its input: a key at 2 frames/s waited out
    a whole idle period more."""
    clock = Clock()
    slept: list[float] = []

    def sleep(s: float) -> None:
        slept.append(s)
        clock.t += s

    records: list[dict] = []
    p = Pacer(clock=clock, sleep=sleep, trace=records.append)
    p.wait(busy=False)
    clock.t += p.deep_after + 1.0  # long idle
    p.wait(busy=False)
    p.wait(busy=False)
    assert p.mode == "idle" and slept[-1] == pytest.approx(1 / p.deep_fps)
    n = len(slept)
    assert p.wait(busy=False, input_now=True) == 0.0
    assert len(slept) == n and p.mode == "active"  # no pause at all
    clock.t += 0.001
    p.wait(busy=False)  # the frames after it: the full rate
    assert p.mode == "active" and slept[-1] == pytest.approx(1 / p.full_fps - 0.001)
    # the trace: one record per frame, the input frame's pause 0, the idle ones 1/deep_fps
    assert [r["frame"] for r in records] == list(range(1, 6))
    assert records[3]["input"] and records[3]["pause"] == 0.0
    assert records[3]["end"] == records[3]["start"]
    assert records[2]["pause"] == pytest.approx(1 / p.deep_fps) and records[2]["mode"] == "idle"
    assert records[2]["end"] - records[2]["start"] == pytest.approx(records[2]["pause"])


def test_a_pause_that_ends_early_leaves_the_next_frame_to_answer():
    """The window's pause may end early (GLFW's wait returns on an input event): the pacer
    does not sleep the rest, and the next frame, reading the input, does not pause."""
    clock = Clock()

    def woken(s: float) -> None:
        clock.t += s / 10  # an event a tenth of the way in

    p = Pacer(clock=clock, sleep=woken)
    p.wait(busy=False)
    clock.t += 60.0
    p.wait(busy=False)
    start = clock.t
    p.wait(busy=False)
    assert clock.t - start == pytest.approx(0.1 / p.deep_fps)  # ended on the event
    assert p.wait(busy=False, input_now=True) == 0.0


def test_jobs_news_calls_the_wake_hook_from_the_jobs_thread():
    """What ends the window's wait for events: a partial result and a finished job call
    ``Jobs.wake`` (from the job's thread), besides setting ``news``."""
    jobs = Jobs()
    woken: list[str] = []
    called = threading.Event()

    def wake() -> None:
        woken.append(threading.current_thread().name)
        called.set()

    jobs.wake = wake
    go = threading.Event()

    def work(reporter):
        reporter(0.5, "a progress line: no news")
        reporter.partial("half")
        go.wait(30)
        return 1

    jobs.start("j", "t", work, lambda r: None, preview=lambda v: None)
    assert called.wait(30) and jobs.news.is_set()
    assert len(woken) == 1 and woken[0] != threading.current_thread().name
    jobs.poll()
    go.set()
    assert jobs.wait("j", timeout=30)
    assert len(woken) == 2  # the result


def test_the_last_outcome_of_an_owners_job_for_its_kept_row():
    """A job's row, kept when no job runs, says how the owner's last job ended."""
    clock = Clock()
    jobs = Jobs(clock=clock, background=False)
    assert jobs.last_outcome("a") == ""

    def work(reporter):
        clock.t += 1.25
        return 1

    jobs.start("a", "computing a", work, lambda r: None)
    assert jobs.last_outcome("a") == "done: computing a (1.2 s)"
    go = threading.Event()
    threaded = Jobs(clock=clock)
    threaded.start("b", "computing b", lambda r: go.wait(30), lambda r: None)
    clock.t += 2.0
    threaded.cancel("b")
    go.set()
    assert threaded.last_outcome("b") == "cancelled: computing b (after 2.0 s)"
    clock.t += 1.0
    threaded.start("c", "computing c", lambda r: (_ for _ in ()).throw(MeshError("no")), None)
    assert threaded.wait("c", timeout=30)
    assert threaded.last_outcome("b", "c").startswith("failed: computing c")  # the latest
