"""Isolines of every scalar field the viewer shows: the shared, polyscope-free settings
(:mod:`meshlap_app.state.isolines`) tested headless, and each panel's toggle and count driven
through the widgets (ScriptedUI on polyscope's ``openGL_mock``) with the options polyscope
received read from the :class:`legend_ledger.Ledger`. ``drive_isolines`` is also part of the
widget tour of ``tests/test_viewer_widgets.py`` (every widget driven)."""

from __future__ import annotations

import numpy as np
import pytest
from meshlap_app.state.isolines import COUNT_RANGE, Isolines, isoline_period

ps = pytest.importorskip("polyscope")

from legend_ledger import Ledger  # noqa: E402
from test_viewer_widgets import drive, frames  # noqa: E402


# ---------------------------------------------------------------- the settings, headless
def test_period_divides_the_finite_range_by_the_count():
    # range [-1, 3] (the inf ignored): 4 / 8 = 0.5 by hand
    assert isoline_period(np.array([-1.0, 0.0, 3.0, np.inf]), 8) == pytest.approx(0.5)
    assert isoline_period(np.array([2.0, 2.0]), 5) == 1.0  # flat: any positive period
    assert isoline_period(None, 5) == 1.0
    assert isoline_period(np.array([np.nan]), 5) == 1.0


def test_each_field_has_its_own_toggle_and_count():
    iso = Isolines()
    assert iso.options("mean", np.arange(3.0)) == {"isolines_enabled": False}
    assert iso.of("distance", on=True).on  # a field may start shown
    iso.of("mean").on = True
    iso.of("mean").set_count(4)
    opts = iso.options("mean", np.array([0.0, 2.0]))
    assert opts == {"isolines_enabled": True, "isoline_period": pytest.approx(0.5)}
    assert not iso.of("gaussian").on  # another field is untouched
    iso.of("mean").set_count(0)
    assert iso.of("mean").count == COUNT_RANGE[0]
    iso.of("mean").set_count(10**9)
    assert iso.of("mean").count == COUNT_RANGE[1]


# ---------------------------------------------------------------- through the widgets
@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


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
    from meshlap_app.panels.spectral import ERROR_NAME
    from meshlap_app.scene import EIGEN, MESH, RECON
    from test_viewer_diffusion import compute_basis, settle

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
        _assert_lines(_shown(ledger, MESH, "diffusion field"), 7)
        drive(viewer, "show", "heat")
        settle(viewer)
        frames(viewer)
        assert not _shown(ledger, MESH, "diffusion field").isolines  # off by default
        _toggle(viewer, ledger, "diffusion", MESH, "diffusion field")
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
    from meshlap_app.panels.check import DIFF
    from meshlap_app.scene import MESH

    with pytest.MonkeyPatch.context() as mp:
        ledger = Ledger().install(mp)
        viewer.set_panel("check")
        frames(viewer)
        _toggle(viewer, ledger, "check", MESH, DIFF)


def test_isolines_of_every_panel_reach_polyscope(viewer):
    drive_isolines(viewer)


def test_heat_animation_frames_carry_the_distance_isolines(viewer, monkeypatch):
    """``meshlap animate --heat``: each frame's field has the isolines of the view's setting,
    the count over its range [0, peak]."""
    ledger = Ledger().install(monkeypatch)
    panel = viewer.panels["diffusion"]
    viewer.set_panel("diffusion")
    frames(viewer)
    panel.isolines.of("distance", True).set_count(5)
    opts = {"heat_vertex": 3, "heat_t": (-1.0, 1.0), "heat_frames": 2}
    captions = list(panel.frames(viewer, opts))
    assert len(captions) == 2 and "vertex 3" in captions[0]
    q = ledger.quantities["mesh"]["diffusion field"]
    assert q.isolines and q.isoline_period == pytest.approx(float(np.max(q.values)) / 5)
    panel.isolines.of("distance").on = False
    list(panel.frames(viewer, opts))
    assert not ledger.quantities["mesh"]["diffusion field"].isolines
