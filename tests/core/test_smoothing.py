"""Tests of meshlap_core.smoothing and the ``smooth`` / ``denoise-eval`` commands.

Sign convention: L = W⁻¹K negative semidefinite (uniform D⁻¹A − I, cotan M⁻¹C).
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from meshlap_core import laplacian as lap
from meshlap_core import smoothing as S
from meshlap_core.errors import MeshError, MeshWarning
from meshlap_core.metrics import signed_volume
from meshlap_core.noise import add_noise
from meshlap_core.options import LAPLACIAN_KINDS, SMOOTHING_METHODS
from meshlap_core.primitives import bumpy_sphere, grid, icosphere, torus_mesh

ALL = [(m, lp) for m in SMOOTHING_METHODS for lp in LAPLACIAN_KINDS]
# a stable step for each Laplacian on the test meshes below (cotan λ has units of length²)
LAM = {"uniform": 0.5, "cotan": 1e-3}


def _tilted_grid(nx=7, ny=6, jitter=0.0, seed=0):
    """A flat grid embedded in the plane z = 0.3x − 0.2y + 1: every coordinate is linear."""
    V, F = grid(nx, ny)
    if jitter:
        rng = np.random.default_rng(seed)
        inner = (V[:, 0] > 1e-9) & (V[:, 0] < 1 - 1e-9) & (V[:, 1] > 1e-9) & (V[:, 1] < 1 - 1e-9)
        V[inner, :2] += jitter * rng.uniform(-1, 1, size=(inner.sum(), 2))
    V[:, 2] = 0.3 * V[:, 0] - 0.2 * V[:, 1] + 1.0
    return V, F


def _dirichlet(K, X):
    """E = −½ tr(Xᵀ K X) >= 0 (K negative semidefinite)."""
    return -0.5 * float(np.sum(X * (K @ X)))


# ----------------------------------------------------------------------------- fixed points


@pytest.mark.parametrize("method,laplacian", ALL)
def test_linear_positions_on_a_regular_flat_grid_are_fixed(method, laplacian):
    V, F = _tilted_grid()
    s = S.Smoother(V, F, method, laplacian, LAM[laplacian], fix_boundary=True)
    s.run(5)
    np.testing.assert_allclose(s.V, V, atol=1e-12)


@pytest.mark.parametrize("method", SMOOTHING_METHODS)
def test_cotan_keeps_linear_positions_on_an_irregular_flat_grid(method):
    V, F = _tilted_grid(jitter=0.05)
    s = S.Smoother(V, F, method, "cotan", LAM["cotan"], fix_boundary=True)
    s.run(5)
    np.testing.assert_allclose(s.V, V, atol=1e-12)


def test_uniform_moves_interior_vertices_of_an_irregular_flat_grid_within_the_plane():
    # the uniform Laplacian reproduces linear functions only on symmetric neighbourhoods
    V, F = _tilted_grid(jitter=0.05)
    X = S.smooth(V, F, "explicit", "uniform", 0.5, 5, fix_boundary=True)
    assert np.abs(X - V).max() > 1e-3  # tangential drift
    np.testing.assert_allclose(X[:, 2], 0.3 * X[:, 0] - 0.2 * X[:, 1] + 1.0, atol=1e-12)


@pytest.mark.parametrize("method,laplacian", ALL)
def test_constants_are_in_the_kernel_translation_commutes(method, laplacian):
    V, F = bumpy_sphere(2)
    t = np.array([3.0, -1.0, 0.5])
    a = S.smooth(V, F, method, laplacian, LAM[laplacian], 3)
    b = S.smooth(V + t, F, method, laplacian, LAM[laplacian], 3)
    np.testing.assert_allclose(b - t, a, atol=1e-10)


# ----------------------------------------------------------------------------- references


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
def test_explicit_step_is_x_plus_lam_L_x(laplacian):
    V, F = bumpy_sphere(2)
    lam = LAM[laplacian]
    L = (
        lap.uniform_laplacian(F, len(V))
        if laplacian == "uniform"
        else lap.laplace_beltrami(V, F, "voronoi")
    )
    got = S.smooth(V, F, "explicit", laplacian, lam, 1)
    np.testing.assert_allclose(got, V + lam * (L @ V), atol=1e-12)


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
def test_implicit_step_matches_spsolve_on_the_course_system(laplacian, spd_backend):
    V, F = bumpy_sphere(2)
    lam = 2.0 if laplacian == "uniform" else 0.05
    n = len(V)
    L = (
        lap.uniform_laplacian(F, n)
        if laplacian == "uniform"
        else lap.laplace_beltrami(V, F, "voronoi")
    )
    want = sla.spsolve((sp.identity(n) - lam * L).tocsc(), V)  # (I − λL) x′ = x, unsymmetric
    got = S.smooth(V, F, "implicit", laplacian, lam, 1)
    np.testing.assert_allclose(got, want, atol=1e-10)


def test_amplification_per_eigenmode_matches_g():
    V, F = icosphere(2)
    n = len(V)
    W, K = S.operator_parts(V, F, "uniform")
    mu, vec = scipy.linalg.eigh(K.toarray(), np.diag(W))  # K v = μ W v, μ <= 0
    assert mu.max() < 1e-10
    for k in (5, n // 2, n - 1):
        X = V.copy()
        X[:, 0] = vec[:, k]  # the uniform operator depends on connectivity only
        for method in SMOOTHING_METHODS:
            lam = 0.4
            g = S.amplification_curve(method, lam, mu[k])
            out = S.Smoother(X, F, method, "uniform", lam, warn=False).step()
            np.testing.assert_allclose(out[:, 0], g * vec[:, k], atol=1e-10)


def test_amplification_curve_hand_values():
    assert S.amplification_curve("explicit", 0.5, -2.0) == pytest.approx(0.0)
    assert S.amplification_curve("implicit", 1.0, -1.0) == pytest.approx(0.5)
    nu = S.taubin_mu(0.5, 0.1)
    assert 1 / 0.5 + 1 / nu == pytest.approx(0.1) and nu < -0.5
    g = S.amplification_curve("taubin", 0.5, np.array([0.0, -0.1, -0.05]))
    assert g[0] == pytest.approx(1.0) and g[1] == pytest.approx(1.0)  # 0 and the pass band
    assert g[2] > 1.0  # below the pass band Taubin amplifies slightly (no shrinkage)
    mu = np.linspace(-2, 0, 50)
    gi = S.amplification_curve("implicit", 3.0, mu)
    assert np.all((gi > 0) & (gi <= 1))
    with pytest.raises(MeshError, match="mu"):
        S.amplification_curve("explicit", 0.5, [0.5])


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
def test_reported_mu_min_matches_dense_generalized_eigensolver(laplacian):
    V, F = bumpy_sphere(3)  # 642 vertices: the sparse Lanczos path
    W, K = S.operator_parts(V, F, laplacian)
    mu = scipy.linalg.eigh(K.toarray(), np.diag(W), eigvals_only=True)
    st = S.stability(V, F, "explicit", laplacian, 1e-4)
    assert st.mu_min_exact
    assert st.mu_min == pytest.approx(mu.min(), rel=1e-6)
    assert st.explicit_lam_limit == pytest.approx(2 / -mu.min(), rel=1e-6)


# ----------------------------------------------------------------------------- invariants


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
@pytest.mark.parametrize("lam", [1e-4, 1e-2, 1.0, 100.0, 1e4])
def test_implicit_never_increases_dirichlet_energy(laplacian, lam):
    V, F = bumpy_sphere(2)
    V = add_noise(V, F, 0.01, seed=2)
    _, K = S.operator_parts(V, F, laplacian)
    s = S.Smoother(V, F, "implicit", laplacian, lam)
    energies = [_dirichlet(K, s.V)]
    for _ in range(5):
        energies.append(_dirichlet(K, s.step()))
    assert np.all(np.diff(energies) <= 1e-12 * energies[0])
    assert energies[-1] < energies[0]


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
def test_implicit_with_fixed_boundary_never_increases_energy(laplacian, spd_backend):
    V, F = grid(8, 8)
    V[:, 2] = 0.05 * np.random.default_rng(0).standard_normal(len(V))
    _, K = S.operator_parts(V, F, laplacian)
    s = S.Smoother(V, F, "implicit", laplacian, 10.0, fix_boundary=True)
    e = [_dirichlet(K, s.V)] + [_dirichlet(K, s.step()) for _ in range(4)]
    assert np.all(np.diff(e) <= 1e-12 * e[0])


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
def test_explicit_blows_up_above_the_reported_limit_and_not_below(laplacian):
    V, F = icosphere(2)
    V = add_noise(V, F, 0.01, seed=1)
    limit = S.stability(V, F, "explicit", laplacian, 1e-6).max_stable_lam
    assert limit is not None and limit > 0
    with pytest.warns(MeshWarning, match="unstable"):
        above = S.Smoother(V, F, "explicit", laplacian, 1.1 * limit)
    assert not above.stability.stable
    above.run(400)
    assert above.diverged
    assert np.isfinite(above.V).all()  # the blown-up step is discarded
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshWarning)
        below = S.Smoother(V, F, "explicit", laplacian, 0.9 * limit)
    assert below.stability.stable
    below.run(400)
    assert not below.diverged
    assert np.abs(below.V).max() <= 1.5 * np.abs(V).max()
    with pytest.raises(MeshError, match="diverged"):
        S.smooth(V, F, "explicit", laplacian, 1.1 * limit, 400, warn=False)


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
def test_taubin_shrinks_a_sphere_far_less_than_explicit(laplacian):
    V, F = icosphere(3)
    v0 = signed_volume(V, F)
    lam = 0.5 * S.stability(V, F, "explicit", laplacian, 1e-9).explicit_lam_limit
    loss = {}
    for method in ("explicit", "taubin"):
        X = S.smooth(V, F, method, laplacian, lam, 30)
        loss[method] = abs(signed_volume(X, F) - v0) / v0
    assert loss["explicit"] > 0.01
    assert loss["taubin"] < 0.1 * loss["explicit"]


def test_preserve_volume_keeps_the_enclosed_volume():
    V, F = bumpy_sphere(3)
    v0 = signed_volume(V, F)
    s = S.Smoother(V, F, "implicit", "cotan", 0.01, preserve_volume=True)
    s.run(5)
    assert signed_volume(s.V, F) == pytest.approx(v0, rel=1e-12)
    assert all(abs(h["volume_change_pct"]) < 1e-9 for h in s.history)
    plain = S.smooth(V, F, "implicit", "cotan", 0.01, 5)
    assert signed_volume(plain, F) < 0.99 * v0


def test_preserve_volume_refuses_open_meshes():
    V, F = grid(5, 5)
    with pytest.raises(MeshError, match=r"preserve_volume.*closed"):
        S.Smoother(V, F, "explicit", "uniform", 0.5, preserve_volume=True)


@pytest.mark.parametrize("method,laplacian", ALL)
def test_fixed_boundary_vertices_do_not_move(method, laplacian):
    V, F = grid(7, 7)
    V[:, 2] = 0.05 * np.random.default_rng(3).standard_normal(len(V))
    from meshlap_core.topology import boundary_vertex_mask

    b = boundary_vertex_mask(F, len(V))
    X = S.smooth(V, F, method, laplacian, LAM[laplacian], 4, fix_boundary=True)
    assert np.array_equal(X[b], V[b])
    assert np.abs(X[~b] - V[~b]).max() > 0


def test_prepare_factorizes_before_the_first_step(spd_backend):
    """``prepare`` does the implicit factorization up front (a job's work, not the window's
    first step): the steps after it factorize nothing more and give the same mesh; with a
    pinned boundary too (the pinned vertices' pull is set up by ``prepare``)."""
    for V, F, kw in ((*bumpy_sphere(2), {}), (*grid(6, 5), {"fix_boundary": True})):
        V = V + 0.01 * np.sin(7 * V[:, [1, 2, 0]])  # bent: the grid is not already smooth
        ready = S.Smoother(V, F, "implicit", "cotan", 0.01, **kw)
        ready.prepare()
        assert ready.n_factorizations == 1 and ready.iteration == 0
        ready.prepare()  # current: nothing to do
        assert ready.n_factorizations == 1
        lazy = S.Smoother(V, F, "implicit", "cotan", 0.01, **kw)
        np.testing.assert_array_equal(ready.run(3), lazy.run(3))
        assert ready.n_factorizations == lazy.n_factorizations == 1
    taubin = S.Smoother(*bumpy_sphere(1), "taubin", "uniform", 0.5)
    taubin.prepare()  # explicit steps factorize nothing
    assert taubin.n_factorizations == 0


def test_mass_recompute_refactorizes_frozen_reuses():
    V, F = bumpy_sphere(2)
    frozen = S.Smoother(V, F, "implicit", "cotan", 0.01)
    frozen.run(6)
    assert frozen.n_factorizations == 1
    frozen.reset()
    frozen.run(3)
    assert frozen.n_factorizations == 1  # kept across reset
    frozen.set_lam(0.02)
    frozen.run(2)
    assert frozen.n_factorizations == 2
    moving = S.Smoother(V, F, "implicit", "cotan", 0.01, mass_update="recompute")
    moving.run(4)
    assert moving.n_factorizations == 4
    # first step identical (same M), later steps differ
    one = S.Smoother(V, F, "implicit", "cotan", 0.01, mass_update="recompute").step()
    np.testing.assert_allclose(one, S.smooth(V, F, "implicit", "cotan", 0.01, 1), atol=1e-14)
    assert not np.allclose(moving.V, S.smooth(V, F, "implicit", "cotan", 0.01, 4), atol=1e-9)


def test_mass_recompute_matches_the_kazhdan_update():
    V, F = bumpy_sphere(2)
    lam = 0.01
    C = lap.cotan_stiffness(V, F)
    X = V.copy()
    for _ in range(3):
        Mt = lap.mass_matrix(X, F, "voronoi")
        X = sla.spsolve((Mt - lam * C).tocsc(), Mt @ X)
    got = S.smooth(V, F, "implicit", "cotan", lam, 3, mass_update="recompute")
    np.testing.assert_allclose(got, X, atol=1e-10)


# ----------------------------------------------------------------------------- stepper state


def test_stepper_state_history_and_reset():
    V, F = torus_mesh()
    s = S.Smoother(V, F, "explicit", "uniform", 0.5)
    assert s.iteration == 0 and len(s.history) == 1 and s.history[0]["iteration"] == 0
    s.run(4)
    assert s.iteration == 4 and [h["iteration"] for h in s.history] == [0, 1, 2, 3, 4]
    keys = {
        "iteration",
        "time_ms",
        "step_rms",
        "step_max",
        "drift_rms",
        "volume",
        "volume_change_pct",
    }
    assert keys <= set(s.history[-1])
    assert s.history[-1]["volume_change_pct"] < 0  # smoothing shrinks
    assert s.history[-1]["drift_rms"] > s.history[1]["drift_rms"] > 0
    with pytest.raises(ValueError):
        s.V[0, 0] = 1.0  # read-only view
    s.reset()
    assert s.iteration == 0 and len(s.history) == 1 and np.array_equal(s.V, V)


def test_history_records_rmse_against_a_reference_and_open_volume_is_none():
    V, F = grid(6, 6)
    Vn = V.copy()
    Vn[:, 2] = 0.02 * np.random.default_rng(0).standard_normal(len(V))
    s = S.Smoother(Vn, F, "implicit", "uniform", 1.0, reference=V, fix_boundary=True)
    s.run(3)
    assert s.history[0]["rmse"] > s.history[-1]["rmse"]
    assert s.history[-1]["volume"] is None and s.history[-1]["volume_change_pct"] is None
    assert not s.closed and "open" in s.volume_note


def test_inputs_are_not_modified():
    V, F = bumpy_sphere(2)
    V0, F0 = V.copy(), F.copy()
    S.smooth(V, F, "implicit", "cotan", 0.01, 2, preserve_volume=True)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)


@pytest.mark.parametrize("lam", [0, -1.0, float("nan"), float("inf"), "abc", None])
def test_bad_lam_raises_naming_lam(lam):
    V, F = icosphere(1)
    with pytest.raises(MeshError, match=r"^lam: "):
        S.smooth(V, F, "explicit", "uniform", lam, 1)


@pytest.mark.parametrize("iters", [-1, 2.5, "x"])
def test_bad_iters_raises_naming_iters(iters):
    V, F = icosphere(1)
    with pytest.raises(MeshError, match=r"^iters: "):
        S.smooth(V, F, "explicit", "uniform", 0.5, iters)


def test_bad_method_and_laplacian_and_taubin_mu():
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="method"):
        S.Smoother(V, F, "gauss", "uniform", 0.5)  # type: ignore[arg-type]
    with pytest.raises(MeshError, match="laplacian"):
        S.Smoother(V, F, "explicit", "graph", 0.5)  # type: ignore[arg-type]
    with pytest.raises(MeshError, match="taubin_nu"):
        S.Smoother(V, F, "taubin", "uniform", 0.5, taubin_nu=-0.1)
    with pytest.raises(MeshError, match="pass_band"):
        S.taubin_mu(0.5, 3.0)


def test_zero_iterations_return_the_input():
    V, F = icosphere(1)
    np.testing.assert_array_equal(S.smooth(V, F, "implicit", "cotan", 1.0, 0), V)


def test_unreferenced_vertices_stay_put():
    V, F = icosphere(1)
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])
    for method in SMOOTHING_METHODS:
        X = S.smooth(V, F, method, "cotan", 1e-3, 2)
        assert np.array_equal(X[-1], V[-1])


# ----------------------------------------------------------------------------- sweep


def test_denoise_sweep_rows_and_improvement():
    V, F = bumpy_sphere(3)
    rows = S.denoise_sweep(
        V,
        F,
        noise_levels=(0.002, 0.01),
        methods=("explicit", "implicit", "taubin"),
        lams=(0.1, 0.5),
        iters=(1, 5),
    )
    assert len(rows) == 2 * 3 * 2 * 2
    required = {
        "noise",
        "method",
        "laplacian",
        "lam",
        "iters",
        "rmse",
        "rmse_noisy",
        "volume_change_pct",
        "dihedral_mae_deg",
    }
    assert all(required <= set(r) for r in rows)
    assert all(r["stable"] and not r["diverged"] for r in rows)
    best = S.best_rows(rows, "rmse")
    assert [b["noise"] for b in best] == [0.002, 0.01]
    for b in best:
        assert b["rmse"] < b["rmse_noisy"]
    # same seed: the noisy input is reproducible
    again = S.denoise_sweep(V, F, noise_levels=(0.01,), methods=("explicit",), lams=(0.5,))
    match = next(r for r in rows if r["noise"] == 0.01)
    assert again[0]["rmse_noisy"] == match["rmse_noisy"]


def test_denoise_sweep_with_a_given_noisy_mesh_and_open_volume():
    V, F = grid(8, 8)
    Vn = V + 0.01 * np.random.default_rng(0).standard_normal(V.shape)
    rows = S.denoise_sweep(V, F, V_noisy=Vn, methods=("implicit",), lams=(1.0,), iters=(3,))
    assert len(rows) == 1
    r = rows[0]
    assert r["noise"] == pytest.approx(0.01 / np.sqrt(2), rel=0.1)  # RMS offset / diagonal
    assert r["volume_change_pct"] is None
    with pytest.raises(MeshError, match="V_noisy"):
        S.denoise_sweep(V, F, V_noisy=Vn[:-1])


def test_denoise_sweep_flags_unstable_explicit_cotan():
    V, F = bumpy_sphere(2)
    rows = S.denoise_sweep(
        V,
        F,
        noise_levels=(0.01,),
        methods=("explicit",),
        laplacians=("cotan",),
        lams=(1.0,),
        iters=(50,),
    )
    assert not rows[0]["stable"] and rows[0]["diverged"]
    assert np.isnan(rows[0]["rmse"])


# ----------------------------------------------------------------------------- CLI


def _write_obj(path, V, F):
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in V.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in F.tolist()]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture
def cli():
    pytest.importorskip("meshlap_core.io")
    from meshlap_core.cli import main

    return main


def test_cli_smooth_json_and_out(cli, tmp_path, capsys):
    V, F = bumpy_sphere(2)
    src, out = tmp_path / "in.obj", tmp_path / "out.obj"
    _write_obj(src, V, F)
    rc = cli(
        [
            "smooth",
            str(src),
            "--method",
            "implicit",
            "--laplacian",
            "cotan",
            "--lam",
            "0.01",
            "--iters",
            "3",
            "--out",
            str(out),
            "--json",
        ]
    )
    assert rc == 0
    r = json.loads(capsys.readouterr().out)
    assert r["iters"] == 3 and len(r["iterations"]) == 4
    assert r["volume_change_pct"] < 0 and r["stability"]["stable"]
    assert r["n_factorizations"] == 1
    from meshlap_core.io import load_mesh

    np.testing.assert_allclose(
        load_mesh(out).V, S.smooth(V, F, "implicit", "cotan", 0.01, 3), atol=1e-12
    )


def test_cli_smooth_errors(cli, tmp_path, capsys):
    V, F = grid(5, 5)
    src = tmp_path / "g.obj"
    _write_obj(src, V, F)
    assert cli(["smooth", str(src), "--lam", "0"]) == 2
    assert "--lam" in capsys.readouterr().err
    assert cli(["smooth", str(src), "--iters", "-2"]) == 2
    assert "--iters" in capsys.readouterr().err
    assert cli(["smooth", str(src), "--out", str(src)]) == 2
    assert "overwrite" in capsys.readouterr().err
    assert cli(["smooth", str(src), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["volume_change_pct"] is None and "open" in r["volume_note"]


def test_cli_denoise_eval_json_rows_and_csv(cli, tmp_path, capsys):
    V, F = bumpy_sphere(2)
    src, csv_path = tmp_path / "c.obj", tmp_path / "t.csv"
    _write_obj(src, V, F)
    rc = cli(
        [
            "denoise-eval",
            str(src),
            "--noise",
            "0.005,0.01",
            "--lam",
            "0.1,0.5",
            "--iters",
            "2,4",
            "--csv",
            str(csv_path),
            "--json",
        ]
    )
    assert rc == 0
    r = json.loads(capsys.readouterr().out)
    assert len(r["rows"]) == 2 * 2 * 2 * 2
    keys = {
        "noise",
        "method",
        "laplacian",
        "lam",
        "iters",
        "rmse",
        "rmse_noisy",
        "volume_change_pct",
        "dihedral_mae_deg",
    }
    assert all(keys <= set(row) for row in r["rows"])
    assert csv_path.read_text().count("\n") == 1 + len(r["rows"])
    noisy = tmp_path / "n.obj"
    _write_obj(noisy, add_noise(V, F, 0.01, seed=5), F)
    assert cli(["denoise-eval", str(src), "--noisy", str(noisy), "--lam", "0.5"]) == 0
    text = capsys.readouterr().out
    assert "lowest RMSE" in text and "lowest dihedral error" in text
    assert cli(["denoise-eval", str(src), "--noisy", str(noisy), "--noise", "0.1"]) == 2
    assert "--noise" in capsys.readouterr().err
    other = tmp_path / "o.obj"
    _write_obj(other, *icosphere(1))
    assert cli(["denoise-eval", str(src), "--noisy", str(other)]) == 2
    assert "same faces" in capsys.readouterr().err


@pytest.mark.shared
def test_fandisk_pair_smoothing_reduces_the_error(shared_mesh):
    pytest.importorskip("meshlap_core.io")
    from meshlap_core.io import load_mesh

    clean, noisy = load_mesh(shared_mesh("fandisk.obj")), load_mesh(shared_mesh("fandisk_ns.obj"))
    assert np.array_equal(clean.F, noisy.F)
    rows = S.denoise_sweep(
        clean.V, clean.F, V_noisy=noisy.V, methods=("explicit", "taubin"), lams=(0.5,), iters=(5,)
    )
    for r in rows:
        assert r["rmse"] < 0.7 * r["rmse_noisy"]
        assert r["dihedral_mae_deg"] < 0.5 * r["dihedral_mae_noisy_deg"]


def test_explicit_with_mass_recompute_uses_the_current_areas():
    V, F = bumpy_sphere(2)
    lam = 1e-3
    C = lap.cotan_stiffness(V, F)
    X = V.copy()
    for _ in range(3):  # x ← x + λ M(x)⁻¹ C₀ x, stiffness frozen
        X = X + lam * (C @ X) / lap.vertex_areas(X, F, "voronoi")[:, None]
    got = S.smooth(V, F, "explicit", "cotan", lam, 3, mass_update="recompute")
    np.testing.assert_allclose(got, X, atol=1e-12)


# ----------------------------------------------------------------------------- linalg.spd


def test_spd_solver_matches_a_direct_solve_and_is_reused(spd_backend):
    from meshlap_core.linalg.spd import SPDSolver, surely_positive_definite

    V, F = bumpy_sphere(2)
    W, K = S.operator_parts(V, F, "cotan")
    A = (sp.diags(W) - 0.01 * K).tocsr()  # W − λK: symmetric positive definite
    assert surely_positive_definite(A)
    solver = SPDSolver(A)
    for B in (V, V[:, 0], 2.0 * V + 1.0):
        np.testing.assert_allclose(solver.solve(B), sla.spsolve(A.tocsc(), B), atol=1e-12)


def test_spd_solver_refuses_an_indefinite_matrix_without_printing(capfd, spd_backend):
    from meshlap_core.linalg.spd import SPDSolver, surely_positive_definite

    A = sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]]))  # eigenvalues 3 and −1
    assert not surely_positive_definite(A)
    with pytest.raises(np.linalg.LinAlgError, match="positive definite"):
        SPDSolver(A)
    out, _ = capfd.readouterr()
    assert out == ""  # CHOLMOD's printf never reaches standard output


def test_implicit_system_beyond_double_precision_is_refused_naming_lam(spd_backend):
    V, F = icosphere(1)
    with (
        pytest.raises(MeshError, match=r"^lam: the implicit system .* cannot be factorized"),
        pytest.warns(MeshWarning, match="ill-conditioned"),
    ):
        S.smooth(V, F, "implicit", "cotan", 1e200, 1)


# ----------------------------------------------------------------------------- bounded work


def test_iteration_counts_beyond_the_limit_are_refused():
    V, F = icosphere(1)
    assert S.check_iters(S.MAX_ITERS) == S.MAX_ITERS
    with pytest.raises(MeshError, match=r"^iters: must be at most 10000000"):
        S.smooth(V, F, "explicit", "uniform", 0.5, S.MAX_ITERS + 1)
    s = S.Smoother(V, F, "implicit", "uniform", 1.0)
    with pytest.raises(MeshError, match=r"^n: must be at most"):
        s.run(10**20)  # beyond int64 too
    assert s.iteration == 0
    with pytest.raises(MeshError, match=r"^iters: .*about 5000 digits"):
        S.check_iters(10**4999)
    with pytest.raises(MeshError, match="iters"):
        S.denoise_sweep(V, F, noise_levels=(0.01,), iters=(2, S.MAX_ITERS + 1))


def _entries_without_time(history):
    return [{k: v for k, v in h.items() if k != "time_ms"} for h in history]


def test_history_samples_keeps_a_decimated_history_with_the_first_and_last_step():
    V, F = icosphere(2)
    full = S.Smoother(V, F, "explicit", "uniform", 0.5)
    full.run(1001)
    s = S.Smoother(V, F, "explicit", "uniform", 0.5, history_samples=40)
    for k in range(1, 1002):
        s.step()
        assert len(s.history) <= 40
        assert s.history[0]["iteration"] == 0 and s.history[-1]["iteration"] == k
    its = [h["iteration"] for h in s.history]
    assert s.history_stride == 32 and len(s.history) >= 20  # never fewer than half
    assert all(i % s.history_stride == 0 for i in its[:-1])
    assert its[:-1] == list(range(0, 1001, s.history_stride))
    # every kept entry is exactly the one a full history would hold for that iteration
    want = _entries_without_time(full.history[i] for i in its)
    assert _entries_without_time(s.history) == want
    s.reset()
    assert s.history_stride == 1 and [h["iteration"] for h in s.history] == [0]


def test_history_options_are_checked():
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="history_samples"):
        S.Smoother(V, F, history_samples=3)
    with pytest.raises(MeshError, match=r"history_samples.*not both"):
        S.Smoother(V, F, history_limit=10, history_samples=10)


def test_divergence_stops_at_the_first_step_farther_than_the_bounding_box_diagonal():
    V, F = icosphere(2)
    V = add_noise(V, F, 0.01, seed=1)
    lam = 1.5 * S.stability(V, F, "explicit", "uniform", 1e-6).max_stable_lam
    s = S.Smoother(V, F, "explicit", "uniform", lam, warn=False)
    s.run(500)
    assert s.diverged
    # the same iteration by hand: x ← x + λ D⁻¹(A − D) x
    W, K = S.operator_parts(V, F, "uniform")
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    x, k = V.copy(), 0
    while True:
        nxt = x + lam * (K @ x) / W[:, None]
        if np.sqrt(np.mean(np.sum((nxt - V) ** 2, axis=1))) > diag:
            break
        x, k = nxt, k + 1
    assert s.iteration == k and s.divergence_limit == pytest.approx(diag)
    for method in ("taubin", "implicit"):  # these only stop on a blow-up (see the docstring)
        other = S.Smoother(V, F, method, "uniform", 0.5, warn=False)
        assert other.divergence_limit == pytest.approx(1000 * diag)
    np.testing.assert_allclose(s.V, x, rtol=1e-9, atol=1e-9 * diag)
    msg = s.divergence_message()
    limit = s.stability.max_stable_lam
    assert f"diverged at iteration {k + 1}" in msg and f"{limit:.4g}" in msg
    before = s.V.copy()
    s.step()  # a diverged smoother does nothing
    assert s.iteration == k and np.array_equal(s.V, before)
    with pytest.raises(S.DivergenceError, match=r"^lam: explicit smoothing diverged") as exc:
        S.smooth(V, F, "explicit", "uniform", lam, 500, warn=False)
    assert isinstance(exc.value, MeshError)
    assert S.Smoother(V, F, "explicit", "uniform", 0.5).divergence_message() is None


@pytest.mark.parametrize("laplacian", LAPLACIAN_KINDS)
def test_stable_runs_never_trip_the_divergence_check(laplacian):
    V, F = icosphere(2)
    for method in SMOOTHING_METHODS:
        lam = LAM[laplacian] if method != "implicit" else 1e4  # implicit: collapse to a point
        s = S.Smoother(V, F, method, laplacian, lam, warn=False)
        s.run(300)
        assert not s.diverged


def test_set_lam_keeps_the_current_mesh_and_only_refactorizes():
    V, F = bumpy_sphere(2)
    W, K = S.operator_parts(V, F, "cotan")  # frozen mass: the operator of the input
    s = S.Smoother(V, F, "implicit", "cotan", 0.01)
    s.run(3)
    here = s.V.copy()
    s.set_lam(0.05)
    assert np.array_equal(s.V, here) and s.iteration == 3 and len(s.history) == 4
    assert s.n_factorizations == 1  # refactorized lazily, on the next step
    s.step()
    want = sla.spsolve((sp.diags(W) - 0.05 * K).tocsc(), W[:, None] * here)
    np.testing.assert_allclose(s.V, want, atol=1e-12)
    assert s.n_factorizations == 2 and s.iteration == 4
    assert [h["iteration"] for h in s.history] == [0, 1, 2, 3, 4]
    s.set_lam(0.05)  # unchanged λ: no refactorization
    s.step()
    assert s.n_factorizations == 2
    # explicit: the next step is x + λ' W⁻¹K x from the current positions
    e = S.Smoother(V, F, "explicit", "cotan", 1e-4)
    e.run(2)
    here = e.V.copy()
    e.set_lam(2e-4)
    np.testing.assert_allclose(e.step(), here + 2e-4 * (K @ here) / W[:, None], atol=1e-12)
    assert e.n_factorizations == 0 and e.stability.lam == 2e-4


def test_set_lam_refuses_a_bad_lam_without_changing_anything():
    V, F = icosphere(1)
    s = S.Smoother(V, F, "taubin", "uniform", 0.5, taubin_nu=-0.6)
    s.run(2)
    here = s.V.copy()
    for bad in (0.0, float("nan"), 0.7):  # 0.7: the given ν = −0.6 is no longer below −λ
        with pytest.raises(MeshError):
            s.set_lam(bad)
        assert s.lam == 0.5 and s.taubin_nu == -0.6 and np.array_equal(s.V, here)


def test_set_lam_resumes_a_diverged_smoother_from_its_last_good_positions():
    V, F = icosphere(2)
    V = add_noise(V, F, 0.01, seed=1)
    limit = S.stability(V, F, "explicit", "uniform", 1e-6).max_stable_lam
    s = S.Smoother(V, F, "explicit", "uniform", 1.5 * limit, warn=False)
    s.run(500)
    assert s.diverged
    k, good = s.iteration, s.V.copy()
    s.set_lam(0.5 * limit)
    assert not s.diverged and s.divergence_message() is None
    s.run(10)
    assert not s.diverged and s.iteration == k + 10
    W, K = S.operator_parts(V, F, "uniform")
    x = good
    for _ in range(10):
        x = x + 0.5 * limit * (K @ x) / W[:, None]
    np.testing.assert_allclose(s.V, x, atol=1e-12)


class _Stream:
    """A text stream that says whether it is a terminal."""

    def __init__(self, tty):
        self.tty, self.text = tty, ""

    def isatty(self):
        return self.tty

    def write(self, s):
        self.text += s

    def flush(self):
        pass


def _run_progress(tty, seconds_per_step, steps=100):
    from meshlap_core.cli.smooth import iteration_progress

    now = [0.0]
    stream = _Stream(tty)
    p = iteration_progress(steps, stream, clock=lambda: now[0])
    for k in range(1, steps + 1):
        now[0] += seconds_per_step
        p.update(k)
    p.close()
    return stream.text


def test_progress_is_silent_on_short_runs_and_reports_long_ones():
    assert _run_progress(tty=False, seconds_per_step=0.05) == ""  # 5 s in all: nothing
    lines = _run_progress(tty=False, seconds_per_step=1.0).splitlines()  # 100 s
    assert [ln.split()[1] for ln in lines] == ["10/100", "40/100", "70/100", "100/100"]
    assert all(ln.startswith("smooth: ") for ln in lines)
    assert "about 90 s left" in lines[0]  # 10 of 100 steps in 10 s
    text = _run_progress(tty=True, seconds_per_step=0.1)  # a terminal: redrawn in place
    assert "\n" not in text and text.count("\r") >= 10
    assert text.endswith("\r\x1b[K")  # erased at the end
    assert _run_progress(tty=True, seconds_per_step=0.001) == ""  # under a second


def test_cli_smooth_refuses_iteration_counts_beyond_the_limit(cli, tmp_path, capsys):
    V, F = icosphere(1)
    src = tmp_path / "s.obj"
    _write_obj(src, V, F)
    for text in ("99999999999999999999", str(S.MAX_ITERS + 1), "9" * 5000):
        assert cli(["smooth", str(src), "--iters", text]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("meshlap: error: --iters: must be at most")
    assert cli(["denoise-eval", str(src), "--iters", "5,99999999999999999999"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--iters: must be at most" in err


def test_cli_smooth_long_run_keeps_a_decimated_history(cli, tmp_path, capsys):
    V, F = icosphere(1)
    src = tmp_path / "s.obj"
    _write_obj(src, V, F)
    assert cli(["smooth", str(src), "--iters", "60", "--json"]) == 0
    out, err = capsys.readouterr()
    r = json.loads(out)
    assert err == ""  # a short run prints no progress
    assert r["iterations_stride"] == 1 and r["iterations_note"] is None
    assert [h["iteration"] for h in r["iterations"]] == list(range(61))
    assert cli(["smooth", str(src), "--iters", "4001", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    its = [h["iteration"] for h in r["iterations"]]
    assert len(its) <= 2000 and its[0] == 0 and its[-1] == 4001 and r["iters"] == 4001
    assert r["iterations_stride"] == 4 and its[:-1] == list(range(0, 4001, 4))
    assert "decimated" in r["iterations_note"]
    assert cli(["smooth", str(src), "--iters", "4001"]) == 0
    assert "history decimated" in capsys.readouterr().out


def test_cli_smooth_divergence_names_the_stable_lam(cli, tmp_path, capsys):
    V, F = icosphere(2)
    src = tmp_path / "s.obj"
    _write_obj(src, add_noise(V, F, 0.01, seed=1), F)
    assert cli(["smooth", str(src), "--lam", "2.5", "--iters", "500"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("meshlap: error: --lam: explicit smoothing diverged at iteration")
    assert "largest stable lam for this mesh: 1." in err and "nothing written" in err


def test_an_ill_conditioned_implicit_lam_is_announced():
    V, F = icosphere(2)
    V = V + np.array([5.0, 0.0, 0.0])
    W, _ = S.operator_parts(V, F, "uniform")
    centroid = (W[:, None] * V).sum(axis=0) / W.sum()  # an exact implicit step conserves it
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshWarning)
        X = S.smooth(V, F, "implicit", "uniform", 1e4, 1)  # 1e4 x max(-L_ii) = 1e4: fine
    np.testing.assert_allclose((W[:, None] * X).sum(axis=0) / W.sum(), centroid, atol=1e-10 * 5)
    lam = 10 * S.ILL_CONDITIONED  # max(-L_ii) = 1 for the uniform Laplacian
    with pytest.warns(MeshWarning, match=r"ill-conditioned.*1e\+11 > 1e\+10"):
        S.Smoother(V, F, "implicit", "uniform", lam)


def test_cli_smooth_announces_an_ill_conditioned_implicit_lam(cli, tmp_path, capsys):
    V, F = icosphere(1)
    src = tmp_path / "s.obj"
    _write_obj(src, V, F)
    argv = ["smooth", str(src), "--method", "implicit", "--lam", "1e12", "--json"]
    assert cli(argv) == 0
    out, err = capsys.readouterr()
    assert any("ill-conditioned" in w for w in json.loads(out)["warnings"])
    assert "meshlap: warning: implicit smoothing with lam=1e+12 is ill-conditioned" in err
