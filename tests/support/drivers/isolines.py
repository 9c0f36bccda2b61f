"""The isoline toggle and count of every view that shows a scalar field, with what polyscope
received read from the :class:`tests.support.legend_ledger.Ledger`."""

from __future__ import annotations

import numpy as np
import pytest
from meshlap_app.state.diffusion import DISTANCE_TITLE, HEAT_TITLES

from tests.support.legend_ledger import Ledger
from tests.support.widgets import compute_basis, drive, frames, settle


def _shown(ledger: Ledger, structure: str, name: str | None = None):
    """The quantity ``name`` of ``structure`` (default: its enabled scalar one)."""
    qs = ledger.quantities.get(structure, {})
    if name is not None:
        return qs[name]
    on = [q for q in qs.values() if q.kind == "scalar" and q.enabled]
    assert len(on) == 1, qs
    return on[0]


def _assert_lines(q, count: int) -> None:
    """Isolines on, ``count`` of them over the uploaded values' finite range (by hand)."""
    v = np.asarray(q.values, dtype=np.float64)
    v = v[np.isfinite(v)]
    assert q.isolines
    assert q.isoline_period == pytest.approx((v.max() - v.min()) / count)


def _toggle(viewer, ledger, panel, structure, name=None, suffix="") -> None:
    """Isolines on with 6 curves, then a bad count (kept), then off."""
    drive(viewer, f"isolines{suffix}", True, panel=panel)
    drive(viewer, f"isoline count{suffix}", 6, panel=panel)
    _assert_lines(_shown(ledger, structure, name), 6)
    drive(viewer, f"isoline count{suffix}", "abc", panel=panel)  # refused: 6 stays
    assert viewer.panels[panel].isolines.of(_field(viewer, panel, suffix)).count == 6
    drive(viewer, f"isolines{suffix}", False, panel=panel)
    q = _shown(ledger, structure, name)
    assert not q.isolines and q.isoline_period is None


def _field(viewer, panel: str, suffix: str) -> str:
    p = viewer.panels[panel]
    if panel == "curvature":
        return viewer.state.curv.field_name
    if panel == "spectral":
        return "eigenfunction" if suffix == " (mode)" else "error"
    if panel == "curvature_lab":
        return p.state.show
    if panel in ("surfaces", "check"):
        return {"surfaces": "Gaussian curvature", "check": "difference"}[panel]
    return p.iso_field()


def drive_isolines(viewer) -> None:
    """The isoline widgets of the curvature, spectral, curvature lab and diffusion views, with
    what polyscope received (an eigenbasis is computed when the spectral view has none)."""
    from meshlap_app.panels.curvature_lab import LAB
    from meshlap_app.panels.spectral import EIGEN, ERROR_NAME
    from meshlap_app.scene import MESH, RECON

    with pytest.MonkeyPatch.context() as mp:
        ledger = Ledger().install(mp)
        viewer.set_panel("curvature")
        frames(viewer, 2)
        _toggle(viewer, ledger, "curvature", MESH)
        if viewer.panels["spectral"].state.basis is None:
            compute_basis(viewer, k=10)
        viewer.set_panel("spectral")
        frames(viewer)
        _toggle(viewer, ledger, "spectral", MESH, EIGEN, " (mode)")
        _toggle(viewer, ledger, "spectral", RECON, ERROR_NAME, " (error)")
        viewer.set_panel("curvature_lab")
        frames(viewer, 2)
        _toggle(viewer, ledger, "curvature_lab", LAB)
        viewer.set_panel("diffusion")
        drive(viewer, "show", "distance")
        assert viewer.panels["diffusion"].select(viewer, 3)
        settle(viewer)
        frames(viewer)
        lines = viewer.panels["diffusion"].isolines.of("distance")
        assert lines.on or lines.count != 12  # on by default (unless a test turned it off)
        lines.on = True
        drive(viewer, "isoline count", 7)
        _assert_lines(_shown(ledger, MESH, DISTANCE_TITLE), 7)
        drive(viewer, "show", "heat")
        settle(viewer)
        frames(viewer)
        heat = HEAT_TITLES["euler"]
        assert not _shown(ledger, MESH, heat).isolines  # off by default
        _toggle(viewer, ledger, "diffusion", MESH, heat)
    drive_surface_isolines(viewer)


def drive_surface_isolines(viewer) -> None:
    """The parametric surface's exact K with its isolines."""
    from meshlap_app.scene import SURFACE

    with pytest.MonkeyPatch.context() as mp:
        ledger = Ledger().install(mp)
        viewer.set_panel("surfaces")
        frames(viewer)
        _toggle(viewer, ledger, "surfaces", SURFACE)


def drive_check_isolines(viewer) -> None:
    """The Check view's difference map (a check made on this mesh) with its isolines."""
    from meshlap_app.scene import MESH
    from meshlap_app.state.check import difference_title

    with pytest.MonkeyPatch.context() as mp:
        ledger = Ledger().install(mp)
        viewer.set_panel("check")
        frames(viewer)
        st = viewer.panels["check"].state
        _toggle(viewer, ledger, "check", MESH, difference_title(st.task, st.check.signed))
