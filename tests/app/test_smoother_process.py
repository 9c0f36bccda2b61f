"""The smoothing stepper in a child process (:mod:`meshlap_app.smoother_process`, issue 21):
the same positions as the stepper in this process, steps asked for and collected later,
Cancel and failures that leave the state as it was, the normals polyscope would compute, and
the panel stepping a child-process stepper in the window's way."""

from __future__ import annotations

import gc
import threading
import time

import numpy as np
import pytest
from meshlap_app.jobs import Cancelled, Jobs, Reporter
from meshlap_app.smoother_process import PIPELINE, RemoteSmoother, build, vertex_normals
from meshlap_app.state.smoothing import MAX_BATCH, SmoothingState

from meshlap_core.errors import MeshError
from meshlap_core.primitives import bumpy_sphere

OPTIONS = ("implicit", "cotan", 0.01, 0.01, 3)  # method, Laplacian, λ, noise α, seed


@pytest.fixture(scope="module")
def mesh():
    return bumpy_sphere(3)


def reporter() -> Reporter:
    return Reporter(threading.Event())


def host_values(buf, n: int) -> np.ndarray:
    """A polyscope vertex buffer's host values ``(n,3)``."""
    return np.array([buf.get_value(i).as_tuple() for i in range(n)])


def wait_for(poll, timeout: float = 120.0) -> None:
    end = time.monotonic() + timeout
    while not poll():
        assert time.monotonic() < end, "no answer from the child process"
        time.sleep(0.01)


@pytest.mark.parametrize("options", [OPTIONS, ("taubin", "uniform", 0.5, 0.0, 0)])
def test_child_stepper_matches_the_stepper_in_this_process(mesh, options, spd_backend):
    V, F = mesh
    remote = RemoteSmoother.start(V, F, options, reporter())
    local = SmoothingState.build(V, F, options)
    try:
        assert np.abs(remote.V0 - local.V0).max() <= 1e-10  # the same noise (same seed)
        assert np.abs(remote.V - local.V).max() <= 1e-10
        for _ in range(3):
            remote.step()
            local.step()
        assert remote.iteration == local.iteration == 3
        assert np.abs(remote.V - local.V).max() <= 1e-10
        assert remote.history[-1]["rmse"] == pytest.approx(local.history[-1]["rmse"], abs=1e-12)
        # (ARPACK starts from a random vector: μ_min agrees to its tolerance)
        assert remote.stability.mu_min == pytest.approx(local.stability.mu_min, rel=1e-6)
        assert remote.stability.stable == local.stability.stable
        remote.set_lam(2 * options[2])  # λ changed mid-run: the implicit system refactorized
        local.set_lam(2 * options[2])
        remote.step()
        local.step()
        assert np.abs(remote.V - local.V).max() <= 1e-10
        assert remote.n_factorizations == local.n_factorizations
        remote.reset()
        assert remote.iteration == 0 and np.array_equal(remote.V, remote.V0)
    finally:
        remote.close()


def test_a_step_asked_for_arrives_later_with_its_normals(mesh):
    """Up to PIPELINE requests travel at once (the child starts the next while the window
    draws the last); each answer in its own slot: the positions after all of them are the
    stepper's here, with their normals."""
    V, F = mesh
    remote = RemoteSmoother.start(V, F, OPTIONS, reporter())
    local = SmoothingState.build(V, F, OPTIONS)
    try:
        assert all(remote.request_step() for _ in range(PIPELINE))
        assert not remote.request_step()  # the child has work queued: refused
        wait_for(remote.poll)
        remote.finish()
        for _ in range(PIPELINE):
            local.step()
        assert remote.iteration == PIPELINE and np.abs(remote.V - local.V).max() <= 1e-10
        assert np.abs(remote.normals - vertex_normals(local.V, local.F)).max() <= 1e-6
        remote.poll()
        assert not remote.poll()  # collected once
        remote.request_step()
        remote.set_lam(0.02)  # a synchronous call waits for the steps on their way first
        assert remote.iteration == PIPELINE + 1 and remote.lam == 0.02 and remote.poll()
        local.step()
        assert np.abs(remote.V - local.V).max() <= 1e-10
    finally:
        remote.close()


def test_vertex_normals_are_polyscopes_smooth_shading_normals(polyscope_mock, mesh):
    """polyscope's own normals after ``update_vertex_positions`` (its host buffer) equal
    :func:`vertex_normals`; the panel's two-buffer upload leaves the same buffers."""
    from meshlap_app.panels.smoothing import upload_positions

    ps = polyscope_mock
    V, F = mesh
    W = V + 0.05 * np.sin(7 * V[:, [1, 2, 0]])  # some other shape
    m = ps.register_surface_mesh("normals_check", V, F, smooth_shade=True)
    try:
        m.update_vertex_positions(W)
        ps.frame_tick()
        buf = m.get_buffer("vertexNormals")
        theirs = host_values(buf, len(V))
        assert np.abs(theirs - vertex_normals(W, F)).max() <= 1e-5
        upload_positions(m, V, vertex_normals(V, F))
        ps.frame_tick()
        pos = m.get_buffer("vertexPositions")
        assert np.abs(host_values(pos, len(V)) - V).max() <= 1e-6
        got = host_values(buf, len(V))
        assert np.abs(got - vertex_normals(V, F)).max() <= 1e-6
    finally:
        ps.remove_surface_mesh("normals_check")


def test_vertex_normals_hand_computed():
    """Two triangles folded at a right angle along the x axis: the shared vertices' normal is
    the normalized sum of the two faces' area-weighted normals."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 1, 2], [0, 3, 1]])  # normals +z and +y, areas 1/2 each
    N = vertex_normals(V, F)
    s = 1 / np.sqrt(2)
    assert np.allclose(N, [[0, s, s], [0, s, s], [0, 0, 1], [0, 1, 0]], atol=1e-7)


def test_cancel_ends_the_child_and_leaves_the_state(mesh):
    V, F = mesh
    st = SmoothingState()
    st.rebuild(V, F)
    before = st.smoother
    rep = reporter()
    rep.cancel.set()
    with pytest.raises(Cancelled):
        RemoteSmoother.start(V, F, OPTIONS, rep)
    jobs = Jobs()
    job = jobs.start(
        "smoothing", "build", lambda r: build(V, F, OPTIONS, r, st.build), st.adopt, None
    )
    jobs.cancel("smoothing")
    job.thread.join(60)
    jobs.poll()
    assert not job.thread.is_alive() and st.smoother is before and st.error == ""


def test_a_failed_build_says_why_and_ends_the_child(mesh):
    V, F = mesh
    with pytest.raises(MeshError, match="laplacian"):
        RemoteSmoother.start(V, F, ("implicit", "bogus", 0.01, 0.0, 0), reporter())


def test_steps_asked_for_together_count_each_step(mesh):
    """*play* on a big mesh asks for several steps at once (as many as the stepper solves
    while the window draws): each is counted at its λ, the positions are the same."""
    V, F = mesh
    st = SmoothingState(method="implicit", laplacian="cotan", lam=0.01)
    st.adopt(RemoteSmoother.start(V, F, st.options(), reporter()))
    try:
        local = SmoothingState.build(V, F, st.options())
        st.show_s = 1e9  # drawing far slower than a step
        assert st.play_batch() == 1  # the step's own time is not known before the first one
        st.advance(st.play_batch())
        wait_for(st.poll)
        st.advance(st.play_batch())  # now the largest batch
        wait_for(st.poll)
        for _ in range(1 + MAX_BATCH):
            local.step()
        assert st.smoother.iteration == 1 + MAX_BATCH
        assert st.lam_steps == [[0.01, 1 + MAX_BATCH]]
        assert np.abs(st.V - local.V).max() <= 1e-10
        st.show_s = 0.0  # drawing quicker than a step: one at a time
        assert st.play_batch() == 1
        st.advance(2)
        st.set_lam(0.02)  # the steps on their way count at the λ they were taken with
        local.step()
        local.step()
        assert st.lam_steps == [[0.01, 3 + MAX_BATCH]] and st.smoother.lam == 0.02
        assert np.abs(st.V - local.V).max() <= 1e-10
    finally:
        st.drop()


def test_a_dropped_stepper_ends_its_process(mesh):
    V, F = mesh
    remote = RemoteSmoother.start(V, F, OPTIONS, reporter())
    proc = remote.process
    st = SmoothingState()
    st.adopt(remote)
    st.drop()
    proc.join(10)
    assert not proc.is_alive()
    remote = RemoteSmoother.start(V, F, OPTIONS, reporter())
    proc = remote.process
    del remote
    gc.collect()
    proc.join(10)
    assert not proc.is_alive()


def test_state_counts_asynchronous_steps_and_play_goes_on(mesh):
    V, F = mesh
    st = SmoothingState(method="implicit", laplacian="cotan", lam=0.01)
    st.adopt(RemoteSmoother.start(V, F, st.options(), reporter()))
    try:
        local = SmoothingState.build(V, F, st.options())
        st.advance()
        wait_for(st.poll)
        st.toggle_play()
        while st.smoother.iteration < 4:
            assert st.play_step()
            st.poll()
            time.sleep(0.005)
        wait_for(lambda: st.poll() or not st.smoother.pending)
        n = st.smoother.iteration
        for _ in range(n):
            local.step()
        assert st.lam_steps == [[0.01, n]] and st.playing
        assert np.abs(st.V - local.V).max() <= 1e-10
    finally:
        st.drop()


def test_the_panel_steps_a_child_process_stepper(viewer):
    """The window's way: the panel's build job starts a child-process stepper, the *step*
    button asks for a step, a later frame shows it (positions uploaded with their normals)."""
    import polyscope as ps
    from meshlap_app.scene import SMOOTHED

    viewer.background = True
    viewer.state.jobs.processes = True
    panel = viewer.panels["smoothing"]
    st = panel.state
    st.method, st.laplacian, st.lam = "implicit", "cotan", 0.01
    try:
        viewer.set_panel("smoothing")
        wait_for(lambda: (ps.frame_tick(), st.smoother is not None)[1])
        assert isinstance(st.smoother, RemoteSmoother)
        panel.on_key(viewer, "right")
        wait_for(lambda: (ps.frame_tick(), st.smoother.iteration == 1)[1])
        ps.frame_tick()
        local = SmoothingState.build(viewer.state.mesh.V, viewer.state.mesh.F, st.options())
        local.step()
        assert np.abs(st.V - local.V).max() <= 1e-10
        d = viewer.state.display
        pos = ps.get_surface_mesh(SMOOTHED).get_buffer("vertexPositions")
        shown = host_values(pos, len(st.V))
        shift = shown[0] - d.points(st.V[:1])[0]
        assert np.abs(shown - (d.points(local.V) + shift)).max() <= 1e-5
        normals = ps.get_surface_mesh(SMOOTHED).get_buffer("vertexNormals")
        expected = vertex_normals(d.points(local.V), st.F)  # what polyscope would derive
        assert np.abs(host_values(normals, len(st.V)) - expected).max() <= 1e-5
        assert not st.error and not any(viewer.state.errors.values()), viewer.state.errors
    finally:
        panel.on_new_mesh(viewer)


def test_a_rebuild_moves_the_shown_copies_to_the_new_stepper(viewer):
    """A new stepper of the same mesh (new noise) is shown by moving the two copies already
    registered: the input shows the new noisy positions, the smoothed copy the new stepper's."""
    import polyscope as ps
    from meshlap_app.scene import SMOOTH_INPUT, SMOOTHED

    panel = viewer.panels["smoothing"]
    st = panel.state
    viewer.set_panel("smoothing")
    ps.frame_tick()
    assert st.smoother is not None and st.noise_alpha == 0.0
    panel.start_build(viewer, noise_alpha=0.01)
    ps.frame_tick()
    assert st.noise_alpha == 0.01
    d = viewer.state.display
    n = len(st.V)
    shown_in = host_values(ps.get_surface_mesh(SMOOTH_INPUT).get_buffer("vertexPositions"), n)
    assert np.abs(shown_in - d.points(st.V_start)).max() <= 1e-5
    assert np.abs(st.V_start - viewer.state.mesh.V).max() > 1e-4  # the noise is there
    st.step()
    panel.push(viewer)
    assert not any(viewer.state.errors.values()), viewer.state.errors
    shown = host_values(ps.get_surface_mesh(SMOOTHED).get_buffer("vertexPositions"), n)
    shift = shown[0] - d.points(st.V[:1])[0]
    assert np.abs(shown - (d.points(st.V) + shift)).max() <= 1e-5
    panel.on_new_mesh(viewer)


def test_without_child_processes_the_stepper_is_built_here(mesh, monkeypatch):
    """Where no child process can start, the job builds the stepper in its own thread (the
    pure in-process path): the same stepper."""
    from meshlap_app import ipc

    from meshlap_core.smoothing import Smoother

    def refuse() -> None:
        raise OSError("no processes here")

    monkeypatch.setattr(ipc, "context", refuse)
    V, F = mesh
    got = build(V, F, OPTIONS, reporter(), SmoothingState.build)
    assert isinstance(got, Smoother)
    got.step()
    local = SmoothingState.build(V, F, OPTIONS)
    local.step()
    assert np.abs(got.V - local.V).max() <= 1e-10


def test_a_new_steppers_copies_are_registered_one_per_frame(viewer):
    """In the window the frame that adopts a stepper registers the smoothed copy only, the
    next one the input (one polyscope registration per frame), each at the display positions
    the build job prepared; framing reads each copy's box from eight corners, the box of the
    positions uploaded."""
    import polyscope as ps
    from meshlap_app.scene import SMOOTH_INPUT, SMOOTHED, box_of, front_view, side_offset

    viewer.background = True
    viewer.state.jobs.processes = True
    panel = viewer.panels["smoothing"]
    st = panel.state
    st.method, st.laplacian, st.lam, st.noise_alpha = "implicit", "cotan", 0.01, 0.01
    try:
        panel.on_new_mesh(viewer)
        viewer.set_panel("smoothing")
        wait_for(lambda: (ps.frame_tick(), st.smoother is not None)[1])
        assert ps.has_surface_mesh(SMOOTHED) and not ps.has_surface_mesh(SMOOTH_INPUT)
        ps.frame_tick()
        assert ps.has_surface_mesh(SMOOTH_INPUT)
        d, n = viewer.state.display, len(st.V)
        shown_in = host_values(ps.get_surface_mesh(SMOOTH_INPUT).get_buffer("vertexPositions"), n)
        assert np.abs(shown_in - d.points(st.V_start)).max() <= 1e-5
        shown = host_values(ps.get_surface_mesh(SMOOTHED).get_buffer("vertexPositions"), n)
        shift = shown[0] - d.points(st.V[:1])[0]
        assert np.abs(shown - (d.points(st.V) + shift)).max() <= 1e-5
        expected = side_offset(d.points(st.V_start), front_view(viewer.state.mesh.name))
        assert np.abs(shift - expected).max() <= 1e-5  # beside the input
        for name, P in ((SMOOTH_INPUT, shown_in), (SMOOTHED, shown)):
            corners = panel.points(viewer, name)
            assert corners.shape == (8, 3)
            assert np.abs(box_of(corners) - box_of(P)).max() <= 1e-5
        assert not st.error and not any(viewer.state.errors.values()), viewer.state.errors
    finally:
        panel.on_new_mesh(viewer)


def test_prepared_display_arrays_are_the_displayed_positions(mesh):
    """:func:`prepare_shown` (the build job's thread) gives the display transform of the input
    and of the current positions, the copy shifted by ``side_offset`` of the input."""
    from meshlap_app.panels.smoothing import prepare_shown
    from meshlap_app.scene import side_offset
    from meshlap_app.state.display import Display

    V, F = mesh
    local = SmoothingState.build(V, F, OPTIONS)
    local.step()
    d = Display()
    d.fit(V, "z")
    front = (0.0, 0.15, -1.0)
    view = (tuple(d.centre.tolist()), d.scale, tuple(map(tuple, d.rotation.tolist())), front)
    shown = prepare_shown(local, view)
    shift = side_offset(d.points(local.V0), front)
    assert np.abs(shown.P_in - d.points(local.V0)).max() <= 1e-12
    assert np.abs(shown.P - (d.points(local.V) + shift)).max() <= 1e-12
    assert np.allclose(shown.box_in, [local.V0.min(axis=0), local.V0.max(axis=0)])
    assert shown.N is None  # an in-process stepper has no normals: polyscope derives them


def test_play_hides_the_input_copy_of_a_big_mesh_and_pause_shows_it(viewer, monkeypatch):
    """Above ``LARGE_MESH_FACES`` (lowered here) *play* draws the smoothed copy alone, says so,
    and the caption of the input goes; pause shows the input again."""
    import polyscope as ps
    from meshlap_app.panels import smoothing
    from meshlap_app.scene import SMOOTH_INPUT

    panel = viewer.panels["smoothing"]
    st = panel.state
    viewer.set_panel("smoothing")
    ps.frame_tick()
    assert ps.get_surface_mesh(SMOOTH_INPUT).is_enabled()
    monkeypatch.setattr(smoothing, "LARGE_MESH_FACES", 0)
    panel.on_key(viewer, "space")
    ps.frame_tick()
    assert st.playing and not ps.get_surface_mesh(SMOOTH_INPUT).is_enabled()
    assert SMOOTH_INPUT not in panel.captions(viewer)
    panel.on_key(viewer, "space")
    ps.frame_tick()
    assert not st.playing and ps.get_surface_mesh(SMOOTH_INPUT).is_enabled()
    assert SMOOTH_INPUT in panel.captions(viewer)
    monkeypatch.setattr(smoothing, "LARGE_MESH_FACES", 10**12)
    panel.on_key(viewer, "space")  # a small mesh keeps both copies while playing
    ps.frame_tick()
    assert ps.get_surface_mesh(SMOOTH_INPUT).is_enabled()
    panel.on_key(viewer, "space")
    panel.on_new_mesh(viewer)


def test_play_meter_counts_steps_and_frames_apart():
    """Hand-counted: play from t=10; steps arrive 2 at t=11 and 3 at t=12, frames show a
    step at t=11 and t=12: 2.5 steps/s and 1 frame/s at t=12; events older than the window
    are forgotten; a pause keeps the rates of its moment."""
    from meshlap_app.state.play_meter import METER_WINDOW_S, PlayMeter

    m = PlayMeter()
    assert m.rates(5.0) == (0.0, 0.0)
    m.start(10.0)
    m.stepped(11.0, 2)
    m.shown(11.0)
    m.stepped(12.0, 3)
    m.shown(12.0)
    assert m.rates(12.0) == pytest.approx((2.5, 1.0))
    late = 11.0 + METER_WINDOW_S + 0.5  # the events of t=11 are out of the window
    assert m.rates(late) == pytest.approx((3 / METER_WINDOW_S, 1 / METER_WINDOW_S))
    m.stop(12.0)
    assert m.rates(100.0) == pytest.approx((2.5, 1.0))


def test_a_session_replayed_in_the_window_steps_in_a_child_process(viewer):
    """Restoring a saved run in the window builds the child-process stepper (as the panel's
    builds do) and replays each run of steps, at its λ, in one request: the positions and
    the counts of the same run stepped here."""
    panel = viewer.panels["smoothing"]
    st = panel.state
    viewer.background = True
    viewer.state.jobs.processes = True
    values = {
        "method": "implicit",
        "laplacian": "cotan",
        "lam": 0.02,
        "noise_alpha": 0.01,
        "seed": 3,
        "iterations": 5,
        "lam_steps": [[0.01, 3], [0.02, 2]],
    }
    try:
        panel.restore(viewer, values, active=True)
        assert isinstance(st.smoother, RemoteSmoother)
        assert st.smoother.iteration == 5 and st.lam_steps == [[0.01, 3], [0.02, 2]]
        V, F = viewer.state.mesh.V, viewer.state.mesh.F
        local = SmoothingState.build(V, F, ("implicit", "cotan", 0.01, 0.01, 3))
        for _ in range(3):
            local.step()
        local.set_lam(0.02)
        for _ in range(2):
            local.step()
        assert np.abs(st.V - local.V).max() <= 1e-10
        assert panel.capture(viewer)["lam_steps"] == [[0.01, 3], [0.02, 2]]
    finally:
        panel.on_new_mesh(viewer)


def test_the_child_makes_the_display_arrays_of_the_view_asked_for(mesh):
    """A step asked for with the window's view brings the positions and normals in display
    coordinates (``((V − c) s) Rᵀ + shift``, ``N Rᵀ``), made by the child; another view has
    none until asked for."""
    from meshlap_app.state.display import Display

    V, F = mesh
    d = Display()
    d.fit(V, "z")  # a rotation that permutes and flips axes
    shift = np.array([0.7, 0.0, -0.1])
    view = (*d.centre.tolist(), d.scale, *d.rotation.ravel().tolist(), *shift.tolist())
    remote = RemoteSmoother.start(V, F, OPTIONS, reporter())
    try:
        assert remote.display(view) is None  # none asked for yet
        remote.request_step(2, view)
        wait_for(remote.poll)
        P, N = remote.display(view)
        assert P.dtype == np.float32 and N.dtype == np.float32
        assert np.abs(P - (d.points(remote.V) + shift)).max() <= 1e-5
        assert np.abs(N - remote.normals @ d.rotation.T).max() <= 1e-6
        other = (*view[:-3], 0.0, 0.0, 0.0)
        assert remote.display(other) is None
        remote.reset()  # the view stays with the child: the arrays follow every answer
        P, _ = remote.display(view)
        assert np.abs(P - (d.points(remote.V0) + shift)).max() <= 1e-5
    finally:
        remote.close()


def test_a_batch_of_steps_shows_the_figures_of_its_last_step_and_the_solver(mesh):
    """The child measures only the step it shows (an implicit batch); the figures are those
    of the last step, as the same steps taken here give them; the solver line comes along."""
    V, F = mesh
    remote = RemoteSmoother.start(V, F, OPTIONS, reporter())
    try:
        local = SmoothingState.build(V, F, OPTIONS)
        remote.steps(5)
        local.run(5)
        last, want = remote.history[-1], local.history[-1]
        assert last["iteration"] == remote.iteration == want["iteration"] == 5
        for key in ("step_rms", "drift_rms", "volume", "rmse"):
            assert last[key] == pytest.approx(want[key], rel=1e-9, abs=1e-14)
        assert remote.solver_line() == local.solver_line() and remote.solver_line()
        assert remote.solver_report()["answering"] == local.solver_report()["answering"]
    finally:
        remote.close()
