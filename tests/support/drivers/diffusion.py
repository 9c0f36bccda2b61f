"""The Diffusion view's widgets: sources by click, the heat method's settings, the heat and its
play, the spectral filters and the drawn transfer curve, the heat kernel signature."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import polyscope as ps
import pytest

from meshlap_core.diffusion import (
    HeatDiffusion,
    HeatGeodesic,
    SpectralFilter,
    exact_distance,
    mean_edge_length,
    transfer,
    unit_heat,
)
from tests.support.widgets import compute_basis, drive, frames, settle, settle_jobs


def click(viewer, vertex: int, *held: str) -> None:
    """A scripted click on the scene (with the modifier keys ``held``) that polyscope's pick
    answers with the mesh's ``vertex``."""
    hit = SimpleNamespace(
        is_hit=True,
        structure_name="mesh",
        structure_data={"element_type": "vertex", "index": vertex},
        position=np.zeros(3),
    )
    real = ps.pick
    ps.pick = lambda screen_coords: hit
    try:
        viewer.ui.script("click", (10.0, 10.0, *held))
        frames(viewer, 1)
    finally:
        ps.pick = real


def drive_heat_play(viewer, hd: HeatDiffusion) -> None:
    """Play t: one step of ``PLAY_STEP`` (log10 of t/h^2) each time the last heat field
    arrived; pause holds t; at the top of the range play stops, and plays again from the
    bottom. Leaves t at 10 h^2."""
    from meshlap_app.state.diffusion import LOG_T_RANGE, PLAY_STEP

    st = viewer.panels["diffusion"].state
    h2 = mean_edge_length(viewer.state.mesh.V, viewer.state.mesh.F) ** 2
    drive(viewer, "play t", True)
    assert st.playing
    for _ in range(3):
        settle(viewer)
    drive(viewer, "pause t", True)
    assert not st.playing
    settle(viewer)
    x = st.log_t
    steps = (x - 1.0) / PLAY_STEP
    assert steps >= 2 and steps == pytest.approx(round(steps), abs=1e-9)  # whole steps up
    frames(viewer, 3)
    assert st.log_t == x  # paused: t holds
    u = hd.euler(unit_heat(np.array(st.sources), hd.mass), 10.0**x * h2, st.steps)
    np.testing.assert_allclose(st.heat["euler"], u, atol=1e-12)  # the field of the t shown
    lo, hi = LOG_T_RANGE
    drive(viewer, "log10 t/h^2", hi - PLAY_STEP / 2)
    drive(viewer, "play t", True)
    settle(viewer)
    frames(viewer, 2)
    assert not st.playing and st.log_t == hi  # stopped at the top
    drive(viewer, "play t", True)  # again: from the bottom
    assert lo <= st.log_t <= lo + 2 * PLAY_STEP
    drive(viewer, "pause t", True)
    settle(viewer)
    drive(viewer, "log10 t/h^2", 1.0)
    settle(viewer)


def drive_drawn_curve(viewer, basis) -> None:
    """The drawn transfer function: every control point dragged in the plot (its gain; its λ
    stays), the filtered copy ``U h(Λ) Uᵀ M X`` following each move; gains clamped to the
    band gain's range; a non-finite drag is refused."""
    from meshlap_app.state.diffusion import DEFAULT_KNOTS

    st = viewer.panels["diffusion"].state
    V = viewer.state.mesh.V
    drive(viewer, "filter", "drawn")
    lam = basis.eigenvalues
    top = float(lam[-1])
    xs = [x for x, _ in DEFAULT_KNOTS]
    for i in range(len(st.knots)):
        drive(viewer, f"curve point {i}", (0.5 * top, 1.0))  # dragged sideways too: λ stays
    assert [x for x, _ in st.knots] == xs and [y for _, y in st.knots] == [1.0] * len(xs)
    np.testing.assert_allclose(st.gains, 1.0)
    np.testing.assert_allclose(st.filtered, V, atol=1e-9)  # h ≡ 1 on the full basis: X
    drive(viewer, "curve point 3", (xs[3] * top, 0.0))  # a notch at λ_3, by hand:
    s = lam / top
    h = 1.0 - np.clip(
        1.0 - np.abs(s - xs[3]) / np.where(s < xs[3], xs[3] - xs[2], xs[4] - xs[3]), 0, 1
    )
    np.testing.assert_allclose(st.gains, h, atol=1e-12)
    U, M = basis.vectors, basis.mass
    np.testing.assert_allclose(st.filtered, U @ (h[:, None] * (U.T @ (M[:, None] * V))), atol=1e-9)
    drive(viewer, "curve point 1", (0.1 * top, 99.0))  # the gain clamped to the slider's range
    assert st.knots[1] == (xs[1], 5.0)
    before = list(st.knots)
    drive(viewer, "curve point 2", (0.2, float("nan")))
    assert st.knots == before and "drawn curve" in viewer.state.errors["diffusion"]
    drive(viewer, "keep residual", True)  # with the residual: X − U Uᵀ M X added back
    ref = SpectralFilter(basis).apply(st.gains, residual=True)
    np.testing.assert_allclose(st.filtered, ref, atol=1e-9)
    drive(viewer, "keep residual", False)


def drive_panel_diffusion(viewer, tmp_path=None) -> None:
    """Every widget of the Diffusion panel, with good and bad values."""
    mesh = viewer.state.mesh
    V, F = mesh.V, mesh.F
    panel = viewer.panels["diffusion"]
    st = panel.state
    viewer.set_panel("diffusion")
    frames(viewer)
    drive(viewer, "show", "distance")
    assert panel.select(viewer, 7)
    settle(viewer)
    np.testing.assert_allclose(st.distance, HeatGeodesic(V, F).distance([7]), atol=1e-12)
    assert ps.get_surface_mesh("mesh").get_quantity_buffer  # the field is on the mesh
    click(viewer, 40, "shift")  # a shift-click adds a source
    settle(viewer)
    assert st.sources == [7, 40]
    np.testing.assert_allclose(st.distance, HeatGeodesic(V, F).distance([7, 40]), atol=1e-12)
    click(viewer, 3)  # a plain click replaces them
    assert st.sources == [3]
    click(viewer, 7)
    click(viewer, 40, "shift")
    click(viewer, 40, "shift")  # twice the same: once
    assert st.sources == [7, 40]
    drive(viewer, "m (t = m h^2)", "4")
    settle(viewer)
    np.testing.assert_allclose(st.distance, HeatGeodesic(V, F, m=4).distance([7, 40]), atol=1e-12)
    for bad in ("0", "-1", "nan", "abc"):
        drive(viewer, "m (t = m h^2)", bad)
        assert st.m == 4.0 and "m (t = m h^2)" in viewer.state.errors["diffusion"]
    drive(viewer, "boundary condition", "neumann")
    settle(viewer)
    assert st.boundary == "neumann"
    drive(viewer, "exact distance", True)
    settle(viewer)
    ex = exact_distance(V, F, [7, 40])
    np.testing.assert_allclose(st.exact, ex)
    assert 0 < st.exact_stats["mean"] < st.exact_stats["max"] < 1
    drive(viewer, "show error map", True)
    assert st.heat_field == "difference"
    drive(viewer, "isolines", True)  # the error map's own setting (off at first)
    assert panel.isolines.of("distance error").on and panel.isolines.of("distance").on
    drive(viewer, "show error map", False)
    drive(viewer, "isolines", False)
    assert not panel.isolines.of("distance").on
    drive(viewer, "isolines", True)
    drive(viewer, "isoline count", 5, 0, 10**6)
    assert panel.isolines.of("distance").count == 200  # clamped

    # heat: Euler alone, then with the Spectral view's basis the two ways and their difference
    drive(viewer, "show", "heat")
    drive(viewer, "log10 t/h^2", 1.0)
    drive(viewer, "Euler steps", 3, 0)
    assert st.steps == 1  # clamped to >= 1
    drive(viewer, "Euler steps", 2)
    settle(viewer)
    hd = HeatDiffusion(V, F)
    t = 10.0 * mean_edge_length(V, F) ** 2
    u = hd.euler(unit_heat(np.array(st.sources), hd.mass), t, 2)
    np.testing.assert_allclose(st.heat["euler"], u, atol=1e-12)
    drive(viewer, "log10 t/h^2", float("nan"))
    assert st.log_t == 1.0
    drive_heat_play(viewer, hd)
    compute_basis(viewer, k=len(V))  # the full basis: the two ways agree up to Euler's error
    viewer.set_panel("diffusion")
    drive(viewer, "Euler steps", 200)
    settle(viewer)
    assert st.k_used == len(V) and st.bound < 1e-6
    diff = np.abs(st.heat["difference"]).max()
    assert diff < 0.05 * np.abs(st.heat["euler"]).max()
    # the two other fields on copies beside the mesh, on the same colour range
    assert ps.has_surface_mesh("heat (second way)") and ps.has_surface_mesh("heat (third field)")
    caps = panel.captions(viewer)
    assert caps["mesh"] == "backward Euler" and "eigen-expansion" in caps["heat (second way)"]
    drive(viewer, "heat field", "difference")
    _, (lo, hi) = st.heat_shown()
    assert lo == -hi  # one colour range for the three fields
    assert hi == pytest.approx(
        max(np.abs(st.heat["euler"]).max(), np.abs(st.heat["spectral"]).max())
    )
    drive(viewer, "heat field", "euler")

    # filter over the basis
    drive(viewer, "show", "filter")
    basis = viewer.panels["spectral"].state.basis
    drive(viewer, "filter", "low-pass")
    drive(viewer, "modes kept", 10)
    ref = SpectralFilter(basis).apply(transfer("low-pass", basis.eigenvalues, keep=10))
    np.testing.assert_allclose(st.filtered, ref, atol=1e-12)
    assert ps.has_surface_mesh("filtered")
    drive(viewer, "filter", "band")
    drive(viewer, "band gain", 1.0)
    np.testing.assert_allclose(st.filtered, V, atol=1e-9)  # h ≡ 1 on the full basis
    drive(viewer, "filter", "explicit")
    drive(viewer, "smoother steps", 4)
    drive(viewer, "measure by smoothing", True)
    settle(viewer)
    ok = np.isfinite(st.measured)  # the modes the round sphere's coordinates contain
    assert ok.sum() >= 3
    np.testing.assert_allclose(st.measured[ok], st.gains[ok], atol=1e-8)  # frozen operator
    drive(viewer, "filter", "implicit")
    drive(viewer, "smoother steps", 3, -5)
    assert st.iters == 0
    np.testing.assert_allclose(st.gains, 1.0)  # no step: identity
    drive(viewer, "keep residual", True)
    drive(viewer, "keep residual", False)
    drive_drawn_curve(viewer, basis)

    # heat kernel signature
    drive(viewer, "show", "hks")
    drive(viewer, "HKS time", 3, 99)
    assert st.hks_scale == 15 and st.hks is not None and st.hks_dist is not None
    assert st.hks_dist[st.sources[0]] == 0.0
    drive(viewer, "clear sources", True)
    assert st.sources == []


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path: Path) -> Any:
    """The distance from a clicked vertex, then (an eigenbasis computed) the heat two ways
    with the third field on copies, a drawn filter and the heat kernel signature."""
    assert viewer.panels["diffusion"].select(viewer, 7)
    settle_jobs(viewer)
    yield "distance"
    viewer.set_panel("spectral")
    from tests.support.drivers.spectral import show_for_export as show_spectral

    show_spectral(viewer, tmp_path)
    viewer.set_panel("diffusion")
    drive(viewer, "show", "heat")
    settle_jobs(viewer)
    assert len(viewer.panels["diffusion"].state.heat) == 3
    yield "heat"
    drive(viewer, "heat field", "difference")
    yield "heat difference"
    drive(viewer, "show", "filter")
    drive(viewer, "filter", "drawn")
    drive(viewer, "curve point 2", (0.0, 0.3))
    yield "drawn filter"
    drive(viewer, "show", "hks")
    settle_jobs(viewer)
    yield "hks"
