"""The Curvature lab's widgets with good and bad values."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps
import pytest
from meshlap_app.state.curvature_lab import STUDY_LEVELS

from tests.support.widgets import drive, frames, settle_jobs


def drive_panel_curvature_lab(viewer, tmp_path=None) -> None:
    """Every lab widget with good and bad values (also run by the every-widget tour)."""
    from meshlap_app.panels.curvature_lab import LAB

    viewer.set_panel("curvature_lab")
    frames(viewer, 2)
    lab = viewer.panels["curvature_lab"].state
    assert lab.result is not None and ps.has_surface_mesh(LAB), viewer.state.errors
    drive(viewer, "resolution", 12)
    assert lab.res == 12 and lab.result.V.shape[0] == 2 * 12 * 12
    # the log-log plot of the error against h, with the fitted order in the legend: a
    # second job, kept per (surface, estimator, noise, jitter, flips)
    conv = lab.convergence()
    assert [row["res"] for row in conv] == list(STUDY_LEVELS)
    order = conv[-1]["H_order"]
    assert order == pytest.approx(2.0, abs=0.3)  # cotan on the regular torus grid
    size = ps.get_window_size()
    ps.set_window_size(size[0], 4000)  # ImPlot skips a plot scrolled out of the window: a
    try:  # window tall enough for the panel, whatever the tests before left open
        frames(viewer, 2)
        _kind, x, y = viewer.ui.plots[("curvature_lab", f"H, order {order:.2f}")]
    finally:
        ps.set_window_size(*size)
    np.testing.assert_allclose(x, np.log10([row["h"] for row in conv]))
    assert len(x) == len(STUDY_LEVELS)
    assert np.all(np.diff(x) < 0) and np.all(np.diff(y) < 0)  # finer: smaller
    # a resolution move recomputes the error map, never the study (nor its figure)
    drive(viewer, "resolution", 14)
    assert lab.result.V.shape[0] == 2 * 14 * 14 and lab.convergence() is conv
    assert len(lab.studies) == 1
    drive(viewer, "resolution", 12)
    drive(viewer, "vertex", 5)
    assert lab.vertex == 5
    # what the Euler plot draws (the plot itself is clipped when the panel is long)
    so = lab.shape_operator()
    assert so["kn"][0] == pytest.approx(lab.result.principal.k1[5])
    assert so["exact_kn"] is not None
    drive(viewer, "vertex", 10**6)
    assert lab.vertex == 5 and "vertex" in viewer.state.errors["curvature_lab"]
    drive(viewer, "noise", 0.001)
    drive(viewer, "jitter", 0.2)
    drive(viewer, "edge flips", 0.1)
    assert lab.computed_for[-3:] == (0.001, 0.2, 0.1)
    drive(viewer, "noise", -1.0)
    assert lab.noise == 0.001 and "noise" in viewer.state.errors["curvature_lab"]
    drive(viewer, "estimator", "rusinkiewicz")
    principal = lab.result.principal
    drive(viewer, "quantity", "k1")
    assert lab.result.principal is principal  # recoloured, the estimator not run again
    drive(viewer, "show", "estimate")
    assert lab.result.label == "k1 (rusinkiewicz) [1/length]"
    np.testing.assert_allclose(lab.result.values, lab.result.principal.k1)
    drive(viewer, "lab surface", "saddle")
    assert lab.result.V.shape[0] == 13 * 13
    drive(viewer, "lab surface", "ellipsoid")  # its exact curvature is the closed form
    k1 = lab.result.exact[0]
    assert np.isfinite(k1).sum() == len(k1) - 2  # all but the two poles
    drive(viewer, "lab surface", "saddle")
    drive(viewer, "crosses", False)
    drive(viewer, "crosses", True)
    drive(viewer, "source", "mesh")
    drive(viewer, "show", "disagreement")
    assert lab.result.V.shape == viewer.state.mesh.V.shape
    assert "disagree" in lab.result.summary
    drive(viewer, "source", "surface")
    drive(viewer, "show", "error")


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path: Path) -> Any:
    """What the view shows for the export test (``tests/app/test_export_views.py``): its
    fields and copies; a generator yields once per state to export."""
    drive(viewer, "resolution", 12)
    settle_jobs(viewer)
