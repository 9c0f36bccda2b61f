"""Colour bars: every visible colour-mapped quantity has one on screen, with its name and range,
and belongs to the view shown (in every view, field, side-by-side setting, with and without an
eigenbasis); the k sweep's error map keeps one range for every k.

Every colour bar's title names its quantity and its unit (``quantity [unit]``, checked by
:func:`tests.support.legend_ledger.title_problem`), in the window (each view made to show what
it shows, as the export test does) and in recordings (the frames ``meshlap animate`` and the
record buttons draw): the Diffusion view titled every field "diffusion field"."""

from __future__ import annotations

import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.registry import VIEWS  # noqa: E402
from meshlap_app.viewer import Viewer  # noqa: E402

from tests.support.drivers import view_setups  # noqa: E402
from tests.support.legend_ledger import Ledger, title_problem  # noqa: E402
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
        elif problem := title_problem(name):
            out.append(f"{where}: {structure}: {problem}")
        kept = q.owner in KEPT_ON_PURPOSE and active.shows_curvature
        if q.owner != active.name and not kept:
            out.append(f"{where}: {structure} / {name!r} of {q.owner!r} visible in {active.name}")
    return out


def test_every_visible_quantity_has_a_legend_and_belongs_to_the_view(viewer, sphere, monkeypatch):
    from meshlap_core.options import CURVATURE_FIELD_LABELS

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

    ledger = Ledger().install(monkeypatch)
    compute_basis(viewer, 12)
    panel = viewer.panels["spectral"]
    ranges = []
    for _ in panel.frames(viewer, {"k": (1, 8)}):
        q = ledger.quantities["reconstruction"][ERROR_NAME]
        assert q.colorbar
        ranges.append(q.vminmax)
    assert len(ranges) == 8 and len(set(ranges)) == 1, ranges


# ---------------------------------------------------------------- titles: quantity and unit
def test_title_check_refuses_a_bare_or_unitless_title():
    """The check itself, on titles written by hand (the ones the issue found and good ones)."""
    bad = ["diffusion field", "student - reference", "error |x - x_k|", "H [1/length"]
    bad += ["cotangent weight w_ij", "[length]", "displacement (mesh units)"]
    assert all(title_problem(t) for t in bad)
    good = ["geodesic distance [length]", "K [1/length^2] (x 1e-74)"]
    good += ["ratio sigma1/sigma2 [dimensionless]", "uniform - cotan H [mixed: a - b]"]
    assert [t for t in good if title_problem(t)] == []


def _visible_titles(ledger: Ledger, where: str) -> list[str]:
    out = []
    for (structure, name), q in ledger.visible().items():
        if q.kind == "scalar" and (problem := title_problem(name)):
            out.append(f"{where}: {structure}: {problem}")
    return out


@pytest.mark.parametrize("view", VIEWS)
def test_every_colour_bar_in_the_window_names_its_quantity_and_unit(
    view, viewer, sphere, tmp_path, monkeypatch
):
    """Each view made to show its fields (every state its export set-up walks through)."""
    ledger = Ledger().install(monkeypatch)
    assert viewer.open(sphere)
    viewer.set_panel(view)
    frames(viewer, 2)
    problems = _visible_titles(ledger, f"{view}, opened")
    steps = view_setups()[view](viewer, tmp_path)
    for what in steps or [view]:
        frames(viewer, 3)
        problems += _visible_titles(ledger, f"{view}: {what}")
    assert not problems, "\n".join(dict.fromkeys(problems))


def test_every_colour_bar_in_recordings_names_its_quantity_and_unit(viewer, monkeypatch):
    """The frames of ``meshlap animate`` and of the window's record button (the panels'
    ``frames``: the k sweep, the eigenmodes, the normal section turning, the heat flowing)."""
    ledger = Ledger().install(monkeypatch)
    compute_basis(viewer, 8)
    runs = {
        "spectral": [{"k": (1, 3)}, {"modes": (1, 2)}],
        "surfaces": [{"theta": True, "frames": 2, "surface": "saddle", "uv": None}],
        "diffusion": [{"heat_vertex": 3, "heat_t": (-1.0, 1.0), "heat_frames": 2}],
    }
    problems, seen = [], 0
    for name, options in runs.items():
        viewer.set_panel(name)
        frames(viewer)
        for opts in options:
            for caption in viewer.panels[name].frames(viewer, opts):
                titles = _visible_titles(ledger, f"{name} {caption}")
                problems += titles
                seen += 1
    assert seen >= 9 and not problems, "\n".join(dict.fromkeys(problems))
