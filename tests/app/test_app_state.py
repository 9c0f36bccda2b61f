"""Viewer state objects, headless (no polyscope)."""

import itertools

import numpy as np
import pytest
from meshlap_app.state import CurvatureState, MeshState, robust_range

from meshlap_core import primitives
from meshlap_core.curvature import all_curvature_fields
from meshlap_core.io import save_mesh


def test_default_mesh_loads():
    m = MeshState()
    assert m.load(None)
    assert m.info["n_vertices"] > 100 and m.info["genus"] == 0 and not m.error


def test_opening_job_reuses_the_edge_table_and_drops_it(tmp_path):
    """The window's opening job (read, describe, every curvature field) gives what the core's
    functions give without the loader's edge table, and leaves the table behind (the viewer
    never uses it; it would double what the child process sends back)."""
    from meshlap_app.state.mesh import read_mesh_with_fields

    from meshlap_core.describe import mesh_info

    path = tmp_path / "torus.obj"
    save_mesh(path, *primitives.torus_mesh())
    loaded, fields = read_mesh_with_fields(path, "voronoi", "pi")
    m = loaded.mesh
    assert m.edge_table is None
    expected = all_curvature_fields(m.V, m.F, "voronoi", "pi")
    assert set(fields) == set(expected)
    for name, values in expected.items():
        np.testing.assert_array_equal(fields[name], values, err_msg=name)
    info = mesh_info(m.V, m.F, m.report, str(path))
    assert loaded.info["n_edges"] == info["n_edges"] == 3 * len(m.F) // 2
    assert loaded.info["genus"] == info["genus"] == 1


def test_bad_file_keeps_last_good_mesh(tmp_path):
    m = MeshState()
    good = tmp_path / "cube.obj"
    save_mesh(good, *primitives.cube())
    assert m.load(good)
    version, V = m.version, m.V.copy()
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    assert not m.load(bad)
    assert "bad.obj" in m.error
    assert m.version == version and np.array_equal(m.V, V)
    assert not m.load(tmp_path / "missing.obj") and "missing.obj" in m.error
    assert m.load(good) and m.error == ""


def test_curvature_state_recomputes_only_on_change():
    m = MeshState()
    m.load(None)
    c = CurvatureState()
    assert c.update(m) and not c.update(m)
    np.testing.assert_allclose(c.fields["cotan"], all_curvature_fields(m.V, m.F)["cotan"])
    c.area = "barycentric"  # the default is the mixed Voronoi area
    assert c.update(m)
    lo, hi = c.color_range("gaussian")
    assert lo == -hi and hi > 0


@pytest.mark.parametrize("estimator", ["cotan", "rusinkiewicz", "normal_cycle"])
def test_shape_operator_patches_share_one_topology_per_mesh(tmp_path, estimator):
    """Clicks on vertices before the whole mesh's estimate exists: each patch's tensor equals
    the whole mesh's at that vertex, the faces' topology is built once for the mesh and made
    again for another mesh."""
    from meshlap_core.curvature.estimators import estimate_curvature

    m = MeshState()
    m.load(None)
    c = CurvatureState()
    c.set_estimator(estimator)
    assert not c.principal_current(m)  # the patch path
    whole = estimate_curvature(m.V, m.F, estimator)
    kept = None
    for v in (0, 17, len(m.V) - 1):
        so = c.shape_operator(m, v)
        S, _, _ = whole.shape_operator(v)
        np.testing.assert_allclose(so["S"], S, atol=1e-10)
        assert so["k1"] == pytest.approx(whole.k1[v]) and so["k1"] >= so["k2"]
        kept = kept or c.topology(m)
        assert c.topology(m) is kept  # one topology for every click on this mesh
    V, F = primitives.torus_mesh(24, 12)
    save_mesh(tmp_path / "torus.obj", V, F)
    m.load(tmp_path / "torus.obj")
    c.shape_operator(m, 5)
    assert c.topology(m) is not kept and c.topology(m).n == len(V)


def test_robust_range_ignores_one_spike():
    v = np.concatenate([np.linspace(-1, 1, 1000), [1e6]])
    lo, hi = robust_range(v, signed=True, percentile=1.0)
    assert lo == -hi and hi < 2
    assert robust_range(v, signed=False, percentile=0.0) == (-1.0, 1e6)
    assert (
        robust_range(np.zeros(5), signed=False)[0] < 0 < robust_range(np.zeros(5), signed=False)[1]
    )


def test_one_ring_state_draws_the_ordered_ring():
    from meshlap_app.state.onering import OneRingState

    from meshlap_core.topology import one_ring

    m = MeshState()
    assert m.load(None)
    c = CurvatureState()
    r = OneRingState()
    assert not r.select(m, c, len(m.V))  # out of range keeps no selection
    assert r.select(m, c, 10)
    ring = one_ring(m.F, len(m.V))
    assert r.neighbors == ring[10].tolist() and not r.boundary
    np.testing.assert_allclose(r.polyline, m.V[ring[10]])
    assert len(r.edges) == r.valence  # a closed cycle
    np.testing.assert_allclose(r.arrows[0], r.polyline[1] - r.polyline[0])
    assert r.H == c.fields["cotan"][10] and r.K == c.fields["gaussian"][10]
    r.toggle_reverse(m, c)
    assert r.neighbors == ring[10].tolist()[::-1]


def test_one_ring_state_open_fan(tmp_path):
    from meshlap_app.state.onering import OneRingState

    path = tmp_path / "grid.obj"
    save_mesh(path, *primitives.grid(4, 4))
    m = MeshState()
    assert m.load(path)
    r = OneRingState()
    assert r.select(m, CurvatureState(), 1)  # an edge vertex of the grid
    assert r.boundary and len(r.edges) == r.valence - 1
    np.testing.assert_allclose(r.arrows[-1], 0.0)  # the fan ends at its last neighbour


def test_one_ring_of_a_vertex_from_its_own_faces_equals_the_whole_meshs(tmp_path):
    """The selection reads the ring and normal from the vertex's own faces only (a big scan's
    whole-mesh ring took minutes): the same ordered fans, flags and angle-weighted normal as the
    whole mesh's, at interior, boundary and corner vertices, in both orders."""
    from meshlap_app.state.onering import OneRingState

    from meshlap_core.curvature import vertex_normals
    from meshlap_core.topology import one_ring

    V, F = primitives.grid(5, 4)
    V = V.copy()
    V[:, 2] = 0.2 * np.sin(4 * V[:, 0] + V[:, 1])
    path = tmp_path / "bent.obj"
    save_mesh(path, V, F)
    m = MeshState()
    assert m.load(path)
    ring, N = one_ring(m.F, len(m.V)), vertex_normals(m.V, m.F)
    back = ring.reversed()
    c, r = CurvatureState(), OneRingState()
    for v in range(len(m.V)):
        assert r.select(m, c, v)
        assert r.neighbors == ring[v].tolist(), v
        assert (r.boundary, r.ordered) == (bool(ring.boundary[v]), bool(ring.regular[v]))
        np.testing.assert_array_equal(r.normal, N[v])
        r.toggle_reverse(m, c)
        assert r.neighbors == back[v].tolist(), v
        r.toggle_reverse(m, c)


def test_spectral_state_k_slider(tmp_path, monkeypatch):
    from meshlap_app.state.spectral import SpectralState

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path))
    V, F = primitives.icosphere(2)
    s = SpectralState(k_request=40, k=5)
    s.start(V, F, background=False)
    assert s.basis is not None and s.basis.k_max == 40 and not s.error
    s.mode = 0
    f, lam0 = s.eigenfunction()
    assert abs(lam0) < 1e-8 and np.ptp(f) < 1e-8  # the constant mode
    s.mode = 1
    _, lam1 = s.eigenfunction()
    assert lam1 == pytest.approx(2.0, rel=0.05)  # l(l+1) with l = 1 on the unit sphere
    errs = []
    for k in (1, 4, 9, 16, 25, 40, 9):
        s.set_k(k)
        # the M-norm of the error never grows with k (an M-orthogonal projection)
        errs.append(float(np.sum(s.basis.mass * s.vertex_error**2)))
        np.testing.assert_allclose(s.reconstruction, s.basis.reconstruct(k))
    assert all(a >= b - 1e-12 for a, b in itertools.pairwise(errs[:6]))
    assert errs[-1] == pytest.approx(errs[2])


def test_spectral_state_background_thread(tmp_path, monkeypatch):
    import time

    from meshlap_app.state.spectral import SpectralState

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path))
    V, F = primitives.icosphere(2)
    s = SpectralState(k_request=10)
    s.start(V, F)
    t0 = time.monotonic()
    while not s.poll():
        assert time.monotonic() - t0 < 120, "worker never finished"
        time.sleep(0.01)
    assert s.basis.k_max == 10 and not s.busy


def _clusters(lam: np.ndarray, rtol: float = 1e-8) -> list[tuple[int, int]]:
    """The runs ``[a, b)`` of equal eigenvalues (relative gap ≤ ``rtol``) whose end ``b`` is
    known to close its cluster (the last run, whose next eigenvalue is not computed, is left
    out)."""
    gaps = np.diff(lam) > rtol * np.maximum(np.abs(lam[1:]), 1.0)
    ends = [int(i) + 1 for i in np.flatnonzero(gaps)]
    return list(itertools.pairwise([0, *ends]))


def test_spectral_state_in_a_child_process_matches_the_thread(tmp_path, monkeypatch):
    """The window (``jobs.processes``) computes the eigenbasis in a child process (where the
    eigensolver may use CHOLMOD, which holds the GIL): the basis that comes back is the one
    computed here, M-orthonormal, with its errors, and still extends in place.

    The icosphere's eigenvalues are degenerate (l = 1: 3 modes, l = 2: 5; icosahedral
    symmetry), and the basis of a degenerate eigenspace is arbitrary (the solver, its
    ordering or a cached basis may pick another): what must agree is each eigenspace, and
    the errors and reconstructions at every k that closes a cluster (k = 1, 4, 9), not the
    errors at a k inside one."""
    import pickle
    import time

    from meshlap_app.jobs import Jobs
    from meshlap_app.state.spectral import SpectralState

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path))
    V, F = primitives.icosphere(3)
    here = SpectralState(k_request=12)
    here.start(V, F, background=False)
    jobs = Jobs()
    jobs.processes = True
    s = SpectralState(k_request=12)
    s.start(V, F, jobs=jobs)
    t0 = time.monotonic()
    while not s.poll():
        assert time.monotonic() - t0 < 120, "child never finished"
        time.sleep(0.02)
    b, ref = s.basis, here.basis
    assert b is not None and b.k_max == 12 and not s.busy and not s.error
    assert b.vectors.flags.f_contiguous  # (mapped from the child's shared-memory file)
    np.testing.assert_allclose(b.eigenvalues, ref.eigenvalues, rtol=1e-8, atol=1e-10)
    G = b.vectors.T @ (b.mass[:, None] * b.vectors)
    np.testing.assert_allclose(G, np.eye(12), atol=1e-9)
    clusters = _clusters(ref.eigenvalues)
    assert clusters == [(0, 1), (1, 4), (4, 9)]  # l = 0, 1, 2 (l = 3 is cut at k = 12)
    for a, z in clusters:  # the same eigenspace: Uᵀ M U_ref is orthogonal on it
        S = b.vectors[:, a:z].T @ (ref.mass[:, None] * ref.vectors[:, a:z])
        np.testing.assert_allclose(np.linalg.svd(S, compute_uv=False), 1.0, atol=1e-7)
    closing = [0] + [z for _, z in clusters]
    np.testing.assert_allclose(
        s.errors.mean[closing], here.errors.mean[closing], rtol=1e-6, atol=1e-12
    )
    for k in closing[1:]:
        s.set_k(k)
        np.testing.assert_allclose(s.reconstruction, here.basis.reconstruct(k), atol=1e-9)
    again = pickle.loads(pickle.dumps(b))  # locks and BLAS controller rebuilt
    again.ensure(16)
    assert again.k_max == 16 and again.eigenvalues[:12] == pytest.approx(b.eigenvalues)


def test_the_eigenbasis_travels_from_the_child_with_its_eigenvectors_mapped(tmp_path, monkeypatch):
    """The eigenbasis job's result as the child sends it (:func:`meshlap_app.ipc.pack`): the
    eigenvectors go through the shared-memory file, not the pickle, and come back equal and
    F-ordered; the file is unlinked once mapped, and a result never opened (a cancelled job)
    leaves no file once discarded."""
    import os

    from meshlap_app import ipc
    from meshlap_app.state.spectral import solve_basis

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path))
    V, F = primitives.icosphere(4)
    basis, errors = solve_basis(V, F, 60)  # 2562 × 60 float64: 1.2 MB
    packed = ipc.pack((basis, errors))
    assert packed.path and os.path.exists(packed.path)
    assert len(packed.data) < basis.vectors.nbytes  # not in the pickle
    got, got_errors = ipc.unpack(packed)
    assert not os.path.exists(packed.path)
    assert got.vectors.flags.f_contiguous and got.vectors.shape == (len(V), 60)
    np.testing.assert_array_equal(got.vectors, basis.vectors)
    np.testing.assert_array_equal(got_errors.mean, errors.mean)
    lost = ipc.pack((basis, errors))
    ipc.discard(lost)
    assert not os.path.exists(lost.path)


def test_smoothing_state_steps_and_reports(tmp_path):
    from meshlap_app.state.smoothing import SmoothingState

    V, F = primitives.icosphere(3)
    s = SmoothingState(method="implicit", lam=1.0, noise_alpha=0.01, seed=1)
    assert s.rebuild(V, F)
    rmse0 = s.figures()["rmse"]
    for _ in range(3):
        assert s.step()
    fig = s.figures()
    assert fig["iteration"] == 3 and fig["rmse"] < rmse0  # denoising moves towards the original
    assert fig["volume_change_pct"] < 0  # smoothing shrinks a sphere
    _, g = s.amplification()
    assert np.all((g > 0) & (g <= 1 + 1e-12))  # implicit: 0 < g <= 1 for every mode
    s.reset()
    assert s.figures()["iteration"] == 0


def test_smoothing_state_unstable_explicit_stops():
    from meshlap_app.state.smoothing import SmoothingState

    V, F = primitives.icosphere(2)
    s = SmoothingState(method="explicit", laplacian="uniform", lam=5.0)
    assert s.rebuild(V, F)
    assert s.figures()["warning"]
    _, g = s.amplification()
    assert np.abs(g).max() > 1
    s.playing = True
    for _ in range(200):
        if not s.step():
            break
    assert not s.playing and "diverged" in s.error
    assert not SmoothingState(lam=float("nan")).rebuild(V, F)


def test_smoother_build_does_the_slow_work_the_panel_reads(monkeypatch):
    """The smoothing panel's build job leaves nothing slow for the UI thread: the implicit
    system is factorized and the stability estimate (an eigensolve) computed there, so the
    panel's figures and its first step compute neither again."""
    from meshlap_app.state.smoothing import SmoothingState

    from meshlap_core.smoothing import stepper

    calls = []
    real = stepper.most_negative_eigenvalue

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(stepper, "most_negative_eigenvalue", counted)
    V, F = primitives.icosphere(2)
    st = SmoothingState(method="implicit", laplacian="cotan", lam=1e-3)
    smoother = SmoothingState.build(V, F, st.options())
    assert smoother.n_factorizations == 1 and len(calls) == 1
    st.adopt_built(st.options(), smoother)
    fig = st.figures()
    mu, g = st.amplification()
    assert st.step() and smoother.iteration == 1
    assert smoother.n_factorizations == 1 and len(calls) == 1  # nothing more on the UI side
    assert fig["stable_limit"] is None  # implicit: unconditionally stable
    assert mu[0] < 0 and np.all((g > 0) & (g <= 1 + 1e-12))  # backward Euler damps every mode
