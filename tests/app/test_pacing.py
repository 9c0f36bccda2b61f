"""The viewer's frame pacing with input (issue 33), through the viewer's own frame on
polyscope's ``openGL_mock`` backend: a frame that starts with input pending is never paused
(the answer is drawn at once, whatever the idle rate was), the pause is the window's wait for
events only when a GLFW window exists, and ``MESHLAP_PACING_TRACE`` writes one line per
frame. ``tests/window/test_idle.py`` checks the same in the real window."""

from __future__ import annotations

import json

import pytest

ps = pytest.importorskip("polyscope")


class Clock:
    """A clock the test moves (seconds)."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def paced(viewer) -> tuple[Clock, list[float]]:
    """Pace ``viewer`` with a clock the test moves; returns it and the pauses asked for."""
    from meshlap_app.pacing import Pacer

    clock, slept = Clock(), []

    def sleep(s: float) -> None:
        slept.append(s)
        clock.now += s

    viewer.pace, viewer.pacer = True, Pacer(clock=clock, sleep=sleep)
    return clock, slept


def test_a_key_down_after_a_long_idle_is_answered_in_a_frame_that_does_not_pause(
    viewer, monkeypatch
):
    clock, slept = paced(viewer)
    ps.frame_tick()
    clock.now += 60.0  # a minute without input: the deep idle rate
    ps.frame_tick()
    ps.frame_tick()
    p = viewer.pacer
    assert p.mode == "idle" and slept[-1] == pytest.approx(1 / p.deep_fps)
    n = len(slept)
    monkeypatch.setattr(viewer.ui, "keys_down", lambda: True)  # a key arrived meanwhile
    viewer.ui.script("key 2", True)  # ... the one-ring view's number
    ps.frame_tick()
    assert len(slept) == n, "the frame that reads the key paused first"
    assert viewer.state.panel == "onering" and p.mode == "active"
    monkeypatch.setattr(viewer.ui, "keys_down", lambda: False)
    clock.now += 0.001
    ps.frame_tick()  # the next frames: the full rate
    assert slept[-1] == pytest.approx(1 / p.full_fps - 0.001)


def test_a_mouse_move_is_input_pending_a_still_mouse_is_not(viewer, monkeypatch):
    """The input the frame reads before pausing: the UI's activity changed since the last
    frame ended (the mouse moved, a button, the wheel ...), or a key is down."""
    ps.frame_tick()
    assert not viewer.input_pending()  # nothing changed since the last frame
    moved = (*viewer._activity[:1], True, *viewer._activity[2:])  # a button went down
    monkeypatch.setattr(viewer.ui, "activity", lambda: moved)
    assert viewer.input_pending()


def test_without_a_glfw_window_the_pause_is_a_nap_and_the_trace_is_written(
    viewer, tmp_path, monkeypatch
):
    """On the headless backends there is no GLFW window: ``FrameWait.listen`` keeps the nap
    (woken by jobs' news) and sets no wake hook; ``MESHLAP_PACING_TRACE`` gets one JSON line
    a frame."""
    trace = tmp_path / "pacing.jsonl"
    monkeypatch.setenv("MESHLAP_PACING_TRACE", str(trace))
    viewer.wait.listen(viewer.pacer)
    assert not viewer.wait.events and viewer.state.jobs.wake is None
    napped: list[float] = []
    monkeypatch.setattr(viewer.state.jobs, "nap", napped.append)
    viewer.wait(0.25)
    assert napped == [0.25]
    viewer.state.jobs.news.set()  # a result waits: no pause at all
    viewer.wait(0.25)
    assert napped == [0.25]
    viewer.state.jobs.news.clear()
    viewer.pace = True
    for _ in range(3):
        ps.frame_tick()
    lines = [json.loads(x) for x in trace.read_text().splitlines()]
    assert len(lines) == 3
    assert {"frame", "start", "end", "pause", "fps", "mode", "input"} <= set(lines[0])
    assert [x["frame"] for x in lines] == [1, 2, 3]
