"""Scale work (issue 21): the shared sorted-edge structures equal the graph-based ones."""

import numpy as np
import pytest

from meshlap_core import primitives, topology, validate_mesh
from meshlap_core.topology.edges import EdgeTable


def _wedges_by_graph(t: EdgeTable) -> np.ndarray:
    """Wedges per vertex from the corner graph of :meth:`EdgeTable.wedges` (the reference)."""
    count, labels = t.wedges()
    wedge_vertex = np.empty(count, dtype=np.int64)
    wedge_vertex[labels] = t.F.ravel()
    return np.bincount(wedge_vertex, minlength=t.n)


def _bowtie() -> np.ndarray:
    """Two icospheres glued at one vertex (two closed fans there)."""
    _, F = primitives.icosphere(1)
    n = int(F.max()) + 1
    return np.vstack([F, np.where(F == 0, 0, F + n)])


def _flipped() -> np.ndarray:
    _, F = primitives.icosphere(2)
    F = F.copy()
    F[:10] = F[:10, ::-1]  # 10 faces inconsistently oriented
    return F


def _soup() -> np.ndarray:
    F = np.random.default_rng(0).integers(0, 30, (300, 3))
    return F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]


def _cones_sharing_boundary_vertex() -> np.ndarray:
    """Two fans of a grid corner vertex: an open fan plus a closed fan on the same vertex."""
    _, Fg = primitives.grid(4, 4)
    _, Fs = primitives.icosphere(1)
    n = int(Fg.max()) + 1
    return np.vstack([Fg, np.where(Fs == 0, 5, Fs + n)])


CASES = {
    "icosphere": lambda: primitives.icosphere(3)[1],
    "torus": lambda: primitives.torus_mesh()[1],
    "grid (boundary)": lambda: primitives.grid(7, 5)[1],
    "cube": lambda: primitives.cube(1)[1],
    "bowtie vertex": _bowtie,
    "non-manifold edge": lambda: np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]]),
    "inconsistent orientation": _flipped,
    "open fan + closed fan": _cones_sharing_boundary_vertex,
    "single triangle": lambda: np.array([[0, 1, 2]]),
    "random soup": _soup,
}


@pytest.mark.parametrize("name", list(CASES))
def test_wedge_counts_equal_the_corner_graph(name):
    F = CASES[name]()
    t = EdgeTable.from_faces(F, int(F.max()) + 3)  # two unreferenced vertices
    got = t.wedge_counts()
    np.testing.assert_array_equal(got, _wedges_by_graph(t))
    assert got[-2:].tolist() == [0, 0]


@pytest.mark.parametrize("name", list(CASES))
def test_vertex_components_equal_the_face_graph(name):
    F = CASES[name]()
    n = int(F.max()) + 3
    t = EdgeTable.from_faces(F, n)
    count, labels = t.vertex_components
    ref_count, ref_labels = topology.connected_components(F, n)
    assert count == ref_count
    # the same partition (numbering may differ)
    pairs = np.unique(np.stack([labels, ref_labels], axis=1), axis=0)
    assert len(pairs) == count


def test_bowtie_and_two_fans_are_non_manifold_vertices():
    t = EdgeTable.from_faces(_bowtie())
    assert t.wedge_counts()[0] == 2
    t = EdgeTable.from_faces(_cones_sharing_boundary_vertex())
    assert t.wedge_counts()[5] == 2


def test_validated_mesh_shares_its_edge_table():
    V, F = primitives.icosphere(2)
    mesh = validate_mesh(V, F)
    t = mesh.edge_table
    assert isinstance(t, EdgeTable) and t.n == mesh.n_vertices
    np.testing.assert_array_equal(t.F, mesh.F)
    ref = EdgeTable.from_faces(mesh.F, mesh.n_vertices)
    np.testing.assert_array_equal(t.edges, ref.edges)
    assert topology.surface_summary(mesh.F, mesh.n_vertices, table=t) == (
        topology.surface_summary(mesh.F, mesh.n_vertices)
    )


# ----------------------------------------------------------------------------- solver back ends


def _implicit_run(lam: float = 0.5, iters: int = 3) -> np.ndarray:
    from meshlap_core import Smoother

    V, F = primitives.bumpy_sphere(2)
    s = Smoother(V, F, method="implicit", laplacian="cotan", lam=lam * 1e-2)
    for _ in range(iters):
        s.step()
    return s.V.copy()


def test_both_solver_backends_give_the_same_solutions(monkeypatch):
    import scipy.sparse as sp

    from meshlap_core.linalg import spd

    if spd.solver_backend() != "cholmod":
        pytest.skip("scikit-sparse is not installed (README: Fast solver)")
    V, F = primitives.bumpy_sphere(2)
    from meshlap_core.smoothing.stepper import operator_parts

    W, K = operator_parts(V, F, "cotan")
    A = (sp.diags(W) - 0.01 * K).tocsr()
    assert spd.SPDSolver(A).backend == "cholespy"  # small: the bundled solver's solves win
    monkeypatch.setenv(spd.SOLVER_ENV, "cholmod")
    fast = spd.SPDSolver(A)
    assert fast.backend == "cholmod"
    fast_run = _implicit_run()
    monkeypatch.setenv(spd.SOLVER_ENV, "fallback")
    slow = spd.SPDSolver(A)
    assert slow.backend == "cholespy"
    for B in (V, V[:, 0]):
        np.testing.assert_allclose(fast.solve(B), slow.solve(B), rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast_run, _implicit_run(), rtol=0, atol=1e-12)


def test_info_names_the_solver_backend(monkeypatch, spd_backend, capsys):
    import json

    from meshlap_core.cli import main

    path = str(__import__("pathlib").Path(__file__).resolve().parents[2] / "assets" / "bumpy.obj")
    assert main(["info", path, "--json"]) == 0
    solver = json.loads(capsys.readouterr().out)["solver"]
    assert solver["backend"] == spd_backend
    assert solver["fast"] == (spd_backend == "cholmod")
    assert main(["info", path]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    assert line.startswith("solver") and spd_backend in line
    if spd_backend != "cholmod":
        assert "[fast]" in line and "libsuitesparse-dev" in line


# ----------------------------------------------------------------------------- cancel hooks


class _CancelAfter:
    """A ``cancel`` callable that asks to stop from its ``after``-th poll on (counts polls)."""

    def __init__(self, after: int) -> None:
        self.after, self.polls = after, 0

    def __call__(self) -> bool:
        self.polls += 1
        return self.polls >= self.after


def test_cancel_stops_the_eigensolver_between_lanczos_blocks(tmp_path):
    from meshlap_core import SpectralBasis
    from meshlap_core.errors import Cancelled

    V, F = primitives.icosphere(4)  # 2,562 vertices: the sparse (Lanczos) solver
    seen = []
    cancel = _CancelAfter(5)
    with pytest.raises(Cancelled, match="eigenbasis cancelled"):
        SpectralBasis.compute(
            V, F, 30, cache_dir=tmp_path, progress=lambda f, m: seen.append(f), cancel=cancel
        )
    assert cancel.polls == 5  # stopped at the first poll that asked, not at the end
    assert not list(tmp_path.iterdir())  # nothing cached
    basis = SpectralBasis.compute(V, F, 30, cache_dir=tmp_path, cancel=_CancelAfter(10**9))
    assert basis.k_max == 30


def test_cancel_event_already_set_stops_before_any_work():
    import threading

    from meshlap_core import Smoother, SpectralBasis, load_mesh
    from meshlap_core.errors import Cancelled

    V, F = primitives.icosphere(2)
    ev = threading.Event()
    ev.set()
    with pytest.raises(Cancelled, match="eigenbasis cancelled"):
        SpectralBasis.compute(V, F, 5, cache=False, cancel=ev)
    s = Smoother(V, F, "implicit", "cotan", lam=1e-3)
    with pytest.raises(Cancelled, match="smoothing cancelled"):
        s.run(5, cancel=ev)
    assert s.iteration == 0
    bumpy = __import__("pathlib").Path(__file__).resolve().parents[2] / "assets" / "bumpy.obj"
    with pytest.raises(Cancelled, match="loading cancelled"):
        load_mesh(bumpy, cancel=ev)


def test_smoothing_run_reports_progress_and_cancels_between_iterations():
    from meshlap_core import Smoother
    from meshlap_core.errors import Cancelled

    V, F = primitives.bumpy_sphere(2)
    s = Smoother(V, F, "implicit", "cotan", lam=1e-3)
    seen = []
    s.run(3, progress=lambda f, m: seen.append((f, m)))
    assert "factorizing" in seen[0][1] and seen[-1][0] == 1.0 and s.iteration == 3
    with pytest.raises(Cancelled):
        s.run(10, cancel=_CancelAfter(3))
    assert s.iteration == 5  # two more done, the third was cancelled before it started


def test_load_mesh_reports_its_phases():
    from meshlap_core import load_mesh

    bumpy = __import__("pathlib").Path(__file__).resolve().parents[2] / "assets" / "bumpy.obj"
    seen = []
    mesh = load_mesh(bumpy, progress=lambda f, m: seen.append((f, m)))
    assert [f for f, _ in seen] == [0.0, 0.1, 0.5, 1.0] and mesh.n_faces > 0


def test_shift_invert_on_both_backends_counts_and_solves_alike(spd_backend):
    import scipy.sparse as sp

    from meshlap_core.linalg import factor

    rng = np.random.default_rng(6)
    n = 400
    A = sp.random(n, n, density=0.01, random_state=6)
    A = (A + A.T + sp.diags(rng.uniform(-3.0, 5.0, n))).tocsr()
    op = factor.ShiftInvert(A, 0.25, rng=rng, spacing=1.0)
    kind = factor.CholmodLDLFactor if spd_backend == "cholmod" else factor.QDLDLFactor
    assert isinstance(op.factor, kind)
    assert op.n_below == np.count_nonzero(np.linalg.eigvalsh(A.toarray()) < op.sigma)
    Y = np.asfortranarray(rng.standard_normal((n, 4)))
    out = np.empty_like(Y)
    op(Y, out)
    S = (A - op.sigma * sp.identity(n)).toarray()
    np.testing.assert_allclose(out, np.linalg.solve(S, Y), rtol=1e-8, atol=1e-10)


def test_cholmod_inertia_with_metis_ordering_counts_like_the_dense_spectrum(monkeypatch):
    """The nested-dissection ordering used on scans (METIS_MIN_N) on a small indefinite
    matrix: same inertia as LAPACK, solves to round-off, and a refactorization at another
    shift (the analysis reused) still counts right."""
    import scipy.sparse as sp

    from meshlap_core.linalg import factor, spd

    pytest.importorskip("sksparse", reason="scikit-sparse (CHOLMOD) is not installed")
    monkeypatch.setenv(spd.SOLVER_ENV, "cholmod")
    monkeypatch.setattr(spd, "_GIL_FREE", {"eigen": False})
    monkeypatch.setattr(factor, "METIS_MIN_N", 0)
    rng = np.random.default_rng(8)
    V, F = primitives.bumpy_sphere(2)
    from meshlap_core.spectral.operators import spectral_operators

    K, m = spectral_operators(V, F, "cotan", "voronoi")
    inv = sp.diags(1.0 / np.sqrt(m))
    A = (inv @ K @ inv).tocsr()
    ev = np.linalg.eigvalsh(A.toarray())
    eye = sp.identity(len(m), format="csr")
    ldl = None
    for sigma in (0.5 * (ev[10] + ev[11]), 0.5 * (ev[40] + ev[41])):
        S = (A - sigma * eye).tocsr()
        ldl, count = factor.cholmod_inertia(S, rng, ldl)
        assert count == np.count_nonzero(ev < sigma)
        b = rng.standard_normal((len(m), 3))
        np.testing.assert_allclose(S @ ldl.solve(b), b, atol=1e-8)


def test_eigenbasis_is_the_same_on_both_backends(spd_backend):
    from meshlap_core.linalg.eigsolve import pencil_eigenpairs
    from meshlap_core.spectral.operators import spectral_operators

    V, F = primitives.bumpy_sphere(3)  # 642 vertices: forced onto the sparse solver below
    K, m = spectral_operators(V, F, "cotan", "voronoi")
    lam, U, _ = pencil_eigenpairs(K, m, 40, method="sparse")
    lam_d, U_d, _ = pencil_eigenpairs(K, m, 40, method="dense")
    np.testing.assert_allclose(lam, lam_d, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(np.abs(U.T @ (m[:, None] * U_d)).max(axis=1), 1.0, atol=1e-6)


def test_prefer_gil_free_keeps_the_eigensolver_on_qdldl(spd_backend):
    import scipy.sparse as sp

    from meshlap_core.linalg import factor, spd

    A = (sp.random(50, 50, density=0.1, random_state=1) + sp.identity(50) * 3).tocsr()
    A = ((A + A.T) * 0.5).tocsr()
    rng = np.random.default_rng(0)
    try:
        spd.prefer_gil_free(True)
        assert spd.eigen_backend() == "qdldl"
        op = factor.ShiftInvert(A, 0.5, rng=rng, spacing=1.0)
        assert isinstance(op.factor, factor.QDLDLFactor)
    finally:
        spd.prefer_gil_free(False)
    assert spd.eigen_backend() == ("cholmod" if spd_backend == "cholmod" else "qdldl")


def test_duplicate_faces_beyond_two_million_vertices_match_np_unique():
    from meshlap_core.validate import duplicate_faces

    rng = np.random.default_rng(0)
    n = 3_000_000  # n³ overflows int64: the (S0·n + S1, S2) lexsort path
    F = rng.integers(0, n, (5000, 3))
    F = np.vstack([F, F[:50, [1, 2, 0]], F[:7, [2, 1, 0]]])
    F = F[rng.permutation(len(F))]
    _, first = np.unique(np.sort(F, axis=1), axis=0, return_index=True)
    ref = np.ones(len(F), dtype=bool)
    ref[first] = False
    np.testing.assert_array_equal(duplicate_faces(F, n), ref)
    assert ref.sum() == 57
