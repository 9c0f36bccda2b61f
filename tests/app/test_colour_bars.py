"""Colour bars: every visible colour-mapped quantity has one on screen, with its name and range,
and belongs to the view shown (in every view, field, side-by-side setting, with and without an
eigenbasis); the k sweep's error map keeps one range for every k."""

from __future__ import annotations

import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.viewer import Viewer  # noqa: E402

from tests.support.widgets import compute_basis, drive, frames  # noqa: E402

KEPT_ON_PURPOSE = {"curvature": "the views that shows_curvature keep the mesh's field"}


def legend_problems(viewer: Viewer, ledger, where: str) -> list[str]:
    """Every visible colour-mapped quantity has an on-screen colour bar with its name and a
    range, and belongs to the active view (or to the curvature field a view keeps)."""
    active = viewer.active()
    out = []
    for structure, qs in ledger.quantities.items():
        for name, q in qs.items():  # polyscope draws these bars even for a hidden structure
            if q.enabled and q.colorbar and not ledger.structure_enabled(structure):
                out.append(f"{where}: colour bar of hidden {structure} / {name!r} on screen")
    for (structure, name), q in ledger.visible().items():
        if q.kind != "scalar":
            continue  # RGB colours carry no colour map (their meaning is in the panel's text)
        if not (q.colorbar and name and q.vminmax is not None):
            out.append(f"{where}: {structure} / {name!r} is visible without a colour bar")
        kept = q.owner in KEPT_ON_PURPOSE and active.shows_curvature
        if q.owner != active.name and not kept:
            out.append(f"{where}: {structure} / {name!r} of {q.owner!r} visible in {active.name}")
    return out


def test_every_visible_quantity_has_a_legend_and_belongs_to_the_view(viewer, sphere, monkeypatch):
    from meshlap_app.registry import VIEWS

    from meshlap_core.options import CURVATURE_FIELD_LABELS
    from tests.support.legend_ledger import Ledger

    ledger = Ledger().install(monkeypatch)
    assert viewer.open(sphere)  # everything registered again, through the ledger
    frames(viewer)
    problems: list[str] = []
    fields = list(CURVATURE_FIELD_LABELS)
    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)  # the ring and the inspector's weights are on screen
    assert viewer.panels["onering"].state.vertex == 5
    for basis in (False, True):
        if basis:
            viewer.set_panel("spectral")
            drive(viewer, "modes to compute", 12)
            drive(viewer, "compute eigenbasis", True)
            st = viewer.panels["spectral"].state
            while st.busy:
                frames(viewer)
            frames(viewer, 2)
            assert st.basis is not None
        for i, field in enumerate(fields):
            for side in (False, True):
                viewer.set_panel("curvature")
                drive(viewer, "field", field)
                c = viewer.state.curv
                if c.side_by_side != side:
                    drive(viewer, "side by side", side)
                if side:
                    drive(viewer, "second field", fields[(i + 1) % len(fields)])
                for view in VIEWS:
                    viewer.set_panel(view)
                    frames(viewer, 2)
                    where = f"basis={basis} field={field} side={side} view={view}"
                    problems += legend_problems(viewer, ledger, where)
    assert not problems, "\n".join(dict.fromkeys(problems))


def test_k_sweep_error_colour_bar_keeps_one_range(viewer, monkeypatch):
    from meshlap_app.panels.spectral import ERROR_NAME

    from tests.support.legend_ledger import Ledger

    ledger = Ledger().install(monkeypatch)
    compute_basis(viewer, 12)
    panel = viewer.panels["spectral"]
    ranges = []
    for _ in panel.frames(viewer, {"k": (1, 8)}):
        q = ledger.quantities["reconstruction"][ERROR_NAME]
        assert q.colorbar
        ranges.append(q.vminmax)
    assert len(ranges) == 8 and len(set(ranges)) == 1, ranges
