"""The Spectral view's widgets: modes to compute, the eigenbasis, eigenmode i and k."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps
import pytest

from tests.support.widgets import drive, settle_jobs, wait_for_basis


def drive_spectral_widgets(viewer):
    viewer.set_panel("spectral")
    st = viewer.panels["spectral"].state
    n = len(viewer.state.mesh.V)
    drive(viewer, "modes to compute", 30)
    assert st.k_request == 30
    for bad in ("", "nan", "1e309", "abc"):
        drive(viewer, "modes to compute", bad)
        assert st.k_request == 30
    drive(viewer, "modes to compute", -5, 0, 10**9)  # clamped to [2, n]
    assert st.k_request == n
    drive(viewer, "modes to compute", 30)
    drive(viewer, "compute eigenbasis", True)
    wait_for_basis(viewer)
    assert st.basis is not None and st.basis.k_max == 30
    assert ps.has_surface_mesh("reconstruction")
    drive(viewer, "eigenmode i", 3)
    _, lam = st.eigenfunction()
    assert st.mode == 3 and lam == pytest.approx(st.basis.eigenvalues[3])
    drive(viewer, "eigenmode i", -1, 10**6)
    assert st.mode == 29  # clamped
    drive(viewer, "k (reconstruct)", 12)
    assert st.k == 12
    np.testing.assert_allclose(st.reconstruction, st.basis.reconstruct(12))
    drive(viewer, "k (reconstruct)", 0, 10**6, "nan")
    assert st.k == 30 and "k (reconstruct)" in viewer.state.errors["spectral"]


def drive_panel_spectral(viewer, tmp_path: Path) -> None:
    drive_spectral_widgets(viewer)


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path: Path) -> Any:
    """What the view shows for the export test (``tests/app/test_export_views.py``): its
    fields and copies; a generator yields once per state to export."""
    drive(viewer, "modes to compute", 12)
    drive(viewer, "compute eigenbasis", True)
    settle_jobs(viewer)
    drive(viewer, "k (reconstruct)", 5)
