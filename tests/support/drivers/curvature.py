"""The Curvature view's widgets (field, area, boundary rule, clip, side by side) and its
estimator combo with the One-ring view's shape-operator row."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps
import pytest

from meshlap_core.curvature import estimators as ce
from meshlap_core.errors import MeshError
from tests.support.drivers.host import drive_view_combo_switches_every_panel
from tests.support.widgets import drive, frames


def drive_curvature_widgets(viewer):
    c = viewer.state.curv
    drive(viewer, "field", "gaussian")
    assert c.field_name == "gaussian"
    drive(viewer, "area", "voronoi")
    assert c.area == "voronoi" and "gaussian" in c.fields
    drive(viewer, "boundary rule", "pi")
    for good in (5.0, 0.0, 49.0):
        drive(viewer, "clip %", good)
        assert c.percentile == good
    drive(viewer, "clip %", 80.0, -3.0)  # out of range (Ctrl+click types any value): clamped
    assert c.percentile == 0.0
    drive(viewer, "clip %", "nan", "1e309")
    assert c.percentile == 0.0 and "clip %" in viewer.state.errors["curvature"]
    drive(viewer, "side by side", True)
    assert ps.has_surface_mesh("mesh (second estimator)")
    drive(viewer, "second field", "k1")
    assert viewer.state.curv.second_field == "k1"
    drive(viewer, "side by side", False)
    assert not ps.has_surface_mesh("mesh (second estimator)")
    lo, hi = c.color_range("gaussian")
    assert lo < hi and np.isfinite(lo)


def drive_curvature_estimator(viewer) -> None:
    """The Curvature view's estimator combo (k1, k2 from the chosen estimator, a bad name
    refused) and the One-ring view's shape-operator row at a vertex (run by
    ``drive_panel_curvature`` of the every-widget tour)."""
    from meshlap_app.state.curvature import ESTIMATOR_HELP

    viewer.set_panel("curvature")
    c, mesh = viewer.state.curv, viewer.state.mesh
    assert all(f"{e}:" in ESTIMATOR_HELP for e in ce.ESTIMATOR_FUNCTIONS)  # each with its paper
    assert "Rusinkiewicz 2004" in ESTIMATOR_HELP and "Meyer et al. 2003" in ESTIMATOR_HELP
    drive(viewer, "field", "k1")
    drive(viewer, "estimator", "rusinkiewicz")
    ref = ce.estimate_curvature(mesh.V, mesh.F, "rusinkiewicz")
    np.testing.assert_allclose(c.values("k1"), ref.k1, atol=1e-12)
    np.testing.assert_allclose(c.values("k2"), ref.k2, atol=1e-12)
    assert c.summary("k1")["max"] == pytest.approx(ref.k1.max())
    with pytest.raises(MeshError, match="estimator"):
        c.set_estimator("magic")
    assert c.estimator == "rusinkiewicz"
    # the One-ring view's row: the estimator's 2x2 tensor at the vertex, in its basis
    drive(viewer, "vertex", 7, panel="onering")
    so = c.shape_operator(mesh, 7)
    S, t1, _ = ref.shape_operator(7)
    np.testing.assert_allclose(so["S"], S, atol=1e-12)
    np.testing.assert_allclose(so["t1"], t1)
    assert so["k1"] == pytest.approx(ref.k1[7]) and so["estimator"] == "rusinkiewicz"
    drive(viewer, "estimator", "jet", panel="curvature")  # the whole mesh's run (inline here)
    assert c.principal_current(mesh) and c.principal.estimator == "jet"
    viewer.set_panel("onering")
    frames(viewer, 1)
    np.testing.assert_allclose(c.shape_operator(mesh, 7)["k1"], c.principal.k1[7])
    drive(viewer, "estimator", "cotan", panel="curvature")
    np.testing.assert_array_equal(c.values("k1"), c.fields["k1"])  # cotan: the course fields
    drive(viewer, "field", "cotan")


def drive_panel_curvature(viewer, tmp_path: Path) -> None:
    drive_view_combo_switches_every_panel(viewer)
    drive_curvature_widgets(viewer)
    drive_curvature_estimator(viewer)


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path: Path) -> Any:
    """What the view shows for the export test (``tests/app/test_export_views.py``): its
    fields and copies; a generator yields once per state to export."""
    drive(viewer, "field", "gaussian")
    drive(viewer, "side by side", True)  # a second mesh with a second field beside it
