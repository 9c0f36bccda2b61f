"""Playing a smoothing run (issue 33, item 7): *pause* shows the step on screen when it was
pressed (a child-process stepper's steps computed ahead are thrown away), *play* on a
diverged run is refused with a message, and ``←`` / *back* steps back through the kept
positions, in this process and in a child process (:mod:`meshlap_app.smoother_process`),
through the state, the keys and the widgets (``openGL_mock``)."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from meshlap_app.jobs import Reporter
from meshlap_app.smoother_process import PIPELINE, RemoteSmoother, _steps
from meshlap_app.state.kept_steps import KeptSteps
from meshlap_app.state.smoothing import SmoothingState

from meshlap_core.errors import MeshError
from meshlap_core.primitives import bumpy_sphere

OPTIONS = ("implicit", "cotan", 0.01, 0.01, 3)  # method, Laplacian, λ, noise α, seed


@pytest.fixture(scope="module")
def mesh():
    return bumpy_sphere(3)


def reporter() -> Reporter:
    return Reporter(threading.Event())


def wait_for(poll, timeout: float = 120.0) -> None:
    end = time.monotonic() + timeout
    while not poll():
        assert time.monotonic() < end, "no answer from the child process"
        time.sleep(0.01)


def reference_path(V, F, options, steps: int) -> list[np.ndarray]:
    """Positions at iterations 0..steps of the stepper in this process."""
    local = SmoothingState.build(V, F, options)
    out = [np.array(local.V)]
    for _ in range(steps):
        local.step()
        out.append(np.array(local.V))
    return out


# ----------------------------------------------------------------------------- the child
def test_a_rewind_throws_away_the_steps_computed_ahead_unread(mesh):
    """The window shows iteration 2; two requests of steps are on their way (the child runs
    ahead); *pause* asks to go back to 2: the answers of those steps are never adopted, the
    positions are iteration 2's."""
    V, F = mesh
    path = reference_path(V, F, OPTIONS, 6)
    remote = RemoteSmoother.start(V, F, OPTIONS, reporter())
    adopted: list[int] = []
    plain = remote._adopt

    def watched(snap):
        adopted.append(snap["iteration"])
        plain(snap)

    remote._adopt = watched
    try:
        remote.steps(2)
        assert remote.request_step(2) and remote.request_step(2)
        assert not remote.request_step()  # PIPELINE requests on their way
        remote.request_rewind(2)  # always sent
        wait_for(lambda: remote.poll() or not remote.pending)
        remote.finish()
        assert adopted == [2, 2], adopted  # the steps' answers (4 and 6) were never read
        assert remote.iteration == 2 and np.abs(remote.V - path[2]).max() <= 1e-10
        assert remote.history[-1]["iteration"] == 2
        remote.step()  # the run goes on from there
        assert remote.iteration == 3 and np.abs(remote.V - path[3]).max() <= 1e-10
    finally:
        remote.close()


def test_the_child_steps_back_and_says_how_far_its_kept_steps_go(mesh):
    V, F = mesh
    path = reference_path(V, F, OPTIONS, 3)
    remote = RemoteSmoother.start(V, F, OPTIONS, reporter())
    try:
        assert remote.kept == KeptSteps(len(V)).capacity and remote.kept_from == 0
        remote.steps(3)
        assert remote.kept_from == 1
        for k in (2, 1, 0):
            remote.request_rewind(k)
            wait_for(remote.poll)
            assert remote.iteration == k and np.abs(remote.V - path[k]).max() <= 1e-10
        remote.request_rewind(2)  # not reached any more: refused, nothing changes
        with pytest.raises(MeshError, match="not reached yet"):
            wait_for(remote.poll)
        assert remote.iteration == 0
    finally:
        remote.close()


class FakeConn:
    """The child's end of the pipe with the messages a window sent meanwhile."""

    def __init__(self, *messages) -> None:
        self.messages = list(messages)

    def poll(self) -> bool:
        return bool(self.messages)

    def recv(self):
        return self.messages.pop(0)


@pytest.mark.parametrize(
    ("waiting", "steps"), [((), 5), ((("step", 1, None),), 5), ((("rewind", 0),), 1)]
)
def test_a_batch_of_steps_ends_early_when_a_pause_arrives(mesh, waiting, steps):
    """In the child, a batch of 5 steps reads what arrives between two steps: a step request
    waits its turn (the batch goes on), a rewind (a pause, a step back) ends the batch: the
    child does not compute steps nobody will see."""
    V, F = mesh
    sm = SmoothingState.build(V, F, OPTIONS)
    kept = KeptSteps(len(V))
    held = _steps(sm, kept, 5, FakeConn(*waiting))
    assert sm.iteration == steps and kept.oldest == 1
    assert held == (waiting[0] if waiting else None)


# ----------------------------------------------------------------------------- the state
def test_pause_shows_the_step_on_screen_when_it_was_pressed(mesh):
    """*play* with the child running ahead (batches, PIPELINE requests on their way), then
    *pause*: once every answer is in, the positions and the run's count are those of the
    iteration shown at the press."""
    V, F = mesh
    st = SmoothingState(method="implicit", laplacian="cotan", lam=0.01)
    st.adopt(RemoteSmoother.start(V, F, st.options(), reporter()))
    try:
        path = reference_path(V, F, st.options(), 40)
        st.show_s = 1e9  # drawing far slower than a step: batches
        st.toggle_play()
        while st.smoother.iteration < 3 or not st.smoother.pending:
            st.play_step()
            st.poll()
            time.sleep(0.002)
        shown = st.smoother.iteration
        st.toggle_play()  # pause, with steps on their way
        assert not st.playing
        wait_for(lambda: (st.poll(), not st.smoother.pending)[1])
        assert st.smoother.iteration == shown
        assert sum(n for _, n in st.lam_steps) == shown
        assert np.abs(st.V - path[shown]).max() <= 1e-10
    finally:
        st.drop()


def test_play_batches_never_outrun_the_kept_steps(mesh):
    """A pause goes back to the step shown: the steps on their way must be within what the
    child keeps (8 steps of the 692k scan: batches of 3 with two requests on their way)."""
    V, F = mesh
    st = SmoothingState(method="implicit", laplacian="cotan", lam=0.01)
    st.adopt(RemoteSmoother.start(V, F, st.options(), reporter()))
    try:
        st.advance()
        wait_for(st.poll)
        st.show_s = 1e9
        assert st.play_batch() == 8  # MAX_BATCH: 200 steps kept of this small mesh
        st.smoother.kept = 8  # as on the scan
        assert st.play_batch() == (8 - 1) // PIPELINE == 3
    finally:
        st.drop()


@pytest.mark.parametrize("in_child", [False, True], ids=["in-process", "child"])
def test_play_on_a_diverged_run_is_refused_with_a_message(mesh, in_child):
    V, F = mesh
    st = SmoothingState(method="explicit", laplacian="uniform", lam=1.9)
    if in_child:
        st.adopt(RemoteSmoother.start(V, F, st.options(), reporter()))
    else:
        st.adopt(SmoothingState.build(V, F, st.options()))
    try:
        for _ in range(500):
            st.advance()
            if in_child:
                wait_for(lambda: st.poll() or st.smoother.diverged)
            if st.smoother.diverged:
                break
        assert st.smoother.diverged
        st.error = ""
        st.toggle_play()
        assert not st.playing and st.meter.started is None
        assert "diverged" in st.error and "lower lambda" in st.error and "reset" in st.error
        st.set_lam(0.5)  # a smaller λ goes on from the last good step
        st.toggle_play()
        assert st.playing
    finally:
        st.drop()


def test_step_back_in_this_process_goes_through_the_kept_steps(mesh):
    V, F = mesh
    st = SmoothingState(method="implicit", laplacian="cotan", lam=0.01, noise_alpha=0.01, seed=3)
    st.adopt(SmoothingState.build(V, F, st.options()))
    path = reference_path(V, F, st.options(), 4)
    for _ in range(3):
        st.advance()
    st.set_lam(0.02)
    st.advance()
    assert st.lam_steps == [[0.01, 3], [0.02, 1]]
    assert st.step_back() and st.smoother.iteration == 3
    assert st.lam_steps == [[0.01, 3]] and np.abs(st.V - path[3]).max() <= 1e-10
    for k in (2, 1, 0):
        assert st.step_back() and st.smoother.iteration == k
    assert np.array_equal(st.V, st.V_start) and st.lam_steps == []
    assert not st.step_back() and "input" in st.error  # nothing before the input
    st.kept.capacity = 2  # iterations 3 and 4 kept after four steps: one step back
    for _ in range(4):
        st.advance()
    assert st.step_back() and st.smoother.iteration == 3
    assert not st.step_back() and "last 2 steps are kept" in st.error
    assert st.smoother.iteration == 3


# ----------------------------------------------------------------------------- the window
def test_left_and_back_step_back_and_space_refuses_a_diverged_run(viewer):
    """Through the panel: ``right`` steps, ``left`` steps back (the caption's count with it),
    the *back* button too; ``space`` on a diverged run plays nothing and says why."""
    import polyscope as ps

    viewer.set_panel("smoothing")
    ps.frame_tick()
    st = viewer.panels["smoothing"].state
    for _ in range(3):
        viewer.ui.script("key right", True)
        ps.frame_tick()
    assert st.smoother.iteration == 3
    viewer.ui.script("key left", True)
    ps.frame_tick()
    assert st.smoother.iteration == 2 and "2 steps" in " ".join(viewer.captions().values())
    viewer.ui.script("back", True)
    ps.frame_tick()
    assert st.smoother.iteration == 1
    st.smoother.diverged = True  # as after a diverging step
    viewer.ui.script("key space", True)
    ps.frame_tick()
    ps.frame_tick()
    assert not st.playing and "diverged" in st.error
    assert st.meter.started is None  # no dead "playing: 0.00 steps/s" line
