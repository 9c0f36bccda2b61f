"""Robustness (issue 8) of ``meshlap spectral`` on the hostile corpus.

Every loadable hostile file gets its eigenpairs ``−C u = λ M u`` (cotangent stiffness,
Voronoi mass: frequencies ``λ ≥ 0`` of ``−Δ``, the negative semidefinite Laplace–Beltrami
operator), checked against a dense solve of the same pencil with SciPy; ``k = n`` (the full
basis) works, ``k > n`` is one error line naming ``--k``; disconnected meshes and tiny
components get one zero eigenvalue per component.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.sparse.csgraph import connected_components

from meshlap_core.cli import COMMANDS, main
from meshlap_core.io import load_mesh
from meshlap_core.laplacian import cotan_stiffness, vertex_areas
from tests.support import hostile

pytestmark = [
    pytest.mark.skipif(
        "spectral" not in COMMANDS, reason="the spectral command is not registered yet"
    ),
    # each case under each plan of the eigensolver (one slice worker and two, forced)
    pytest.mark.usefixtures("slice_plan"),
]


@pytest.fixture(autouse=True)
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def dense_spectrum(path) -> np.ndarray:
    """The generalized eigenvalues of ``(−C, M)`` by SciPy, one connected component at a time
    (the pencil is block diagonal; one dense solve of components of very different size
    loses the small eigenvalues to round-off)."""
    m = load_mesh(path)
    C = cotan_stiffness(m.V, m.F)
    M = vertex_areas(m.V, m.F, "voronoi")
    _, labels = connected_components(C, directed=False)
    parts = []
    for c in np.unique(labels):
        idx = np.flatnonzero(labels == c)
        Cc = C[idx][:, idx].toarray()
        parts.append(sla.eigh(-Cc, np.diag(M[idx]), eigvals_only=True))
    return np.sort(np.concatenate(parts))


@pytest.mark.parametrize("case", hostile.LOADABLE, ids=lambda h: h.name)
def test_spectral_full_basis_matches_a_dense_solve(capsys, tmp_path, case):
    mesh = case.build(tmp_path)
    n = case.n_vertices
    reference = dense_spectrum(mesh)
    scale = max(abs(reference).max(), 1e-300)
    for k in sorted({min(3, n), n}):  # a few modes, then the full basis (k = n)
        code, out, err = run_cli(capsys, "spectral", mesh, "--k", k, "--json")
        assert code == 0, err
        r = json.loads(out)
        lam = np.array(r["eigenvalues"], dtype=float)
        assert lam.shape == (k,) and np.isfinite(lam).all()
        np.testing.assert_allclose(lam, reference[:k], rtol=1e-6, atol=1e-9 * scale)
        assert all(np.isfinite(row["mean_error"]) for row in r["reconstruction"])
    # the full basis reconstructs the shape exactly
    assert r["reconstruction"][-1]["max_error"] <= 1e-8 * max(r["bbox_diagonal"], 1e-300)
    code, out, err = run_cli(capsys, "spectral", mesh, "--k", n + 1)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("meshlap: error: --k: ") and f"{n} vertices" in err


def test_disconnected_mesh_and_tiny_components(capsys, tmp_path):
    """A tetrahedron, an icosphere and a lone triangle: three zero eigenvalues, then the
    smallest positive frequency of the three parts."""
    mesh = hostile.build("components.obj", tmp_path)
    reference = dense_spectrum(mesh)
    code, out, err = run_cli(capsys, "spectral", mesh, "--k", 6, "--json")
    assert code == 0, err
    r = json.loads(out)
    assert r["n_components"] == 3
    lam = np.array(r["eigenvalues"])
    assert np.all(np.abs(lam[:3]) <= 1e-9 * reference.max()) and lam[3] > 1e-6
    np.testing.assert_allclose(lam, reference[:6], rtol=1e-6, atol=1e-9 * reference.max())


@pytest.mark.parametrize("k", ["0", "-1", "abc", "2.5", ""])
def test_bad_k(capsys, tmp_path, k):
    mesh = hostile.build("relative.obj", tmp_path)
    code, out, err = run_cli(capsys, "spectral", mesh, "--k", k)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("meshlap: error: --k: ")


def test_spectral_outputs_are_checked_first_and_kept_on_failure(capsys, tmp_path):
    good = hostile.build("relative.obj", tmp_path)
    bad = hostile.build("truncated.ply", tmp_path)
    out = tmp_path / "basis.npz"
    out.write_bytes(b"previous basis")
    code, _, err = run_cli(capsys, "spectral", bad, "--k", 3, "--out", out)
    assert code == 2 and err.count("\n") == 1 and str(bad) in err
    assert out.read_bytes() == b"previous basis"
    for target in (tmp_path / "missing" / "b.npz", good, tmp_path / "b.txt"):
        code, _, err = run_cli(capsys, "spectral", good, "--k", 3, "--out", target)
        assert code == 2 and err.count("\n") == 1 and err.startswith("meshlap: error: ")
    assert not (tmp_path / "missing").exists() and not (tmp_path / "b.txt").exists()
    code, _, err = run_cli(
        capsys, "spectral", good, "--k", 3, "--save-reconstruction", out
    )  # an existing file, not a folder
    assert code == 2 and err.count("\n") == 1 and out.read_bytes() == b"previous basis"
