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
