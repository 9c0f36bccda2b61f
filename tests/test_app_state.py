"""Viewer state objects, headless (no polyscope)."""

import numpy as np

from app.state import CurvatureState, MeshState, robust_range
from meshlap_core import primitives
from meshlap_core.curvature import curvature_fields
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
    np.testing.assert_allclose(c.fields["cotan"], curvature_fields(m.V, m.F)["cotan"])
    c.area = "voronoi"
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
