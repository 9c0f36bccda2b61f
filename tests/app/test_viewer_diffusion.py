"""The Diffusion panel through its widgets (ScriptedUI on polyscope's openGL_mock) and its
polyscope-free state. ``drive_panel_diffusion`` is also part of the widget tour of
``tests/test_viewer_widgets.py`` (every widget driven)."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from test_viewer_widgets import drive, frames  # noqa: E402

from meshlap_core.diffusion import (  # noqa: E402
    HeatDiffusion,
    HeatGeodesic,
    SpectralFilter,
    exact_distance,
    mean_edge_length,
    transfer,
    unit_heat,
)


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def settle(viewer, owner: str = "diffusion") -> None:
    """Wait for the panel's jobs (worker threads when ``viewer.background``) and let the host
    apply them (an applied job may start the next one)."""
    t0 = time.monotonic()
    while viewer.state.jobs.running(owner) is not None:
        assert time.monotonic() - t0 < 120, "the diffusion job never finished"
        viewer.state.jobs.wait(owner, 1.0)
        frames(viewer, 1)
    frames(viewer, 2)


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


def compute_basis(viewer, k: int = 40) -> None:
    viewer.set_panel("spectral")
    drive(viewer, "modes to compute", k)
    drive(viewer, "compute eigenbasis", True)
    st = viewer.panels["spectral"].state
    t0 = time.monotonic()
    while st.busy:
        assert time.monotonic() - t0 < 300
        time.sleep(0.02)
    frames(viewer, 2)
    assert st.basis is not None


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


def test_diffusion_widgets(viewer):
    drive_panel_diffusion(viewer)
    ui = viewer.ui
    mine = {k for k in ui.seen if k[0] == "diffusion"}
    assert mine and not sorted(mine - ui.driven)


def test_state_headless_without_a_basis(sphere):
    from meshlap_app.state.diffusion import DiffusionState, find_basis

    from meshlap_core.io import load_mesh

    mesh = load_mesh(sphere)
    st = DiffusionState(show="heat")
    assert not st.select(len(mesh.V), len(mesh.V))  # out of range: nothing changes
    assert st.select(len(mesh.V), 3)
    st.compute_heat(mesh.V, mesh.F, mean_edge_length(mesh.V, mesh.F), None)
    assert set(st.heat) == {"euler"} and np.isnan(st.bound)
    assert find_basis([object(), st], mesh.V) is None


# ---------------------------------------------------------------- meshlap animate --heat
def _animate(tmp_path, *args: str):
    import os
    import subprocess
    import sys

    env = dict(os.environ, MESHLAP_CACHE_DIR=str(tmp_path / "cache"))
    cmd = [sys.executable, "-m", "meshlap_core.cli", "animate", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=tmp_path, env=env)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--panel", "diffusion"], "--heat"),
        (["--panel", "diffusion", "--heat", "--heat-t", "2:1"], "--heat-t"),
        (["--panel", "diffusion", "--heat", "--heat-frames", "1"], "--heat-frames"),
        (["--panel", "diffusion", "--heat", "--heat-vertex", "100000"], "--heat-vertex"),
    ],
)
def test_heat_animation_bad_arguments(tmp_path, sphere, args, needle):
    res = _animate(tmp_path, str(sphere), *args, "--out", str(tmp_path / "h.gif"))
    assert res.returncode == 2 and needle in res.stderr
    assert res.stderr.count("meshlap: error:") == 1
    assert not (tmp_path / "h.gif").exists()


@pytest.mark.egl
def test_heat_animation_renders(tmp_path, sphere):
    from PIL import Image

    out = tmp_path / "heat.gif"
    res = _animate(
        tmp_path, str(sphere), "--panel", "diffusion", "--heat", "--heat-frames", "3",
        "--size", "320x180", "--out", str(out),
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    im = Image.open(out)
    assert im.n_frames == 3
    frames = []
    for i in range(3):
        im.seek(i)
        frames.append(np.asarray(im.convert("RGB")).astype(int))
    corner = frames[0][5:100, 5:40]  # the colour bar
    assert ((corner.max(axis=2) - corner.min(axis=2)) > 80).sum() > 50
    assert not np.array_equal(frames[0], frames[2])  # the heat spreads


@pytest.mark.egl
def test_view_screenshot_on_a_clicked_vertex(tmp_path, sphere):
    """``meshlap view --panel diffusion --vertex I --screenshot``: the distance from I with its
    colour bar and isolines, rendered headless."""
    import os
    import subprocess
    import sys

    from PIL import Image

    out = tmp_path / "d.png"
    env = dict(os.environ, MESHLAP_CACHE_DIR=str(tmp_path / "cache"))
    cmd = [sys.executable, "-m", "meshlap_core.cli", "view", str(sphere), "--panel", "diffusion",
           "--vertex", "5", "--screenshot", str(out)]  # fmt: skip
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=tmp_path, env=env)
    assert res.returncode == 0, res.stderr
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    corner = img[20:250, 10:40]  # the colour bar of the distance
    assert ((corner.max(axis=2) - corner.min(axis=2)) > 80).sum() > 100
    h, w, _ = img.shape
    line = img[int(0.25 * h) : int(0.7 * h), int(0.37 * w)].sum(axis=1)  # down the mesh
    jumps = np.count_nonzero(np.abs(np.diff(line)) > 40)  # the isoline bands' edges
    assert jumps >= 4, jumps  # (5 on this view: smooth shading changes by <= 3 a pixel)


def test_play_moves_t_up_its_log_scale_and_stops_at_the_top():
    """The play button's state, headless: whole steps up, a stop at the top, a restart."""
    from meshlap_app.state.diffusion import LOG_T_RANGE, PLAY_STEP, DiffusionState

    st = DiffusionState(log_t=0.0)
    assert not st.play_step()  # not playing: t holds
    st.toggle_play()
    assert st.play_step() and st.play_step()
    assert st.log_t == pytest.approx(2 * PLAY_STEP)
    lo, hi = LOG_T_RANGE
    st.log_t = hi - PLAY_STEP / 4
    assert st.play_step() and st.log_t == hi and not st.playing
    st.toggle_play()  # from the top: starts over at the bottom
    assert st.playing and st.log_t == lo
    st.clear()  # a new mesh stops it
    assert not st.playing


def test_distance_view_factorizes_before_the_first_click_which_only_solves(viewer, monkeypatch):
    """As on a scan (solves as jobs, the window's worker threads): showing the distance view
    starts the heat method's factorizations; a click while they run waits for them (the job is
    not restarted) and is answered when they end; later clicks reuse them (no factorization)."""
    import meshlap_app.panels.diffusion as mod

    monkeypatch.setattr(mod, "INLINE_DISTANCE_MAX", 0)
    viewer.background = True
    panel, jobs = viewer.panels["diffusion"], viewer.state.jobs
    st = panel.state
    built: list[float] = []

    class Counted(HeatGeodesic):
        def __init__(self, *args, **kwargs):
            time.sleep(0.3)  # long enough for a click to arrive meanwhile
            super().__init__(*args, **kwargs)
            built.append(self.m)

    monkeypatch.setattr(mod, "HeatGeodesic", Counted)
    viewer.set_panel("diffusion")
    drive(viewer, "show", "distance")
    job = jobs.running("diffusion")
    assert job is not None and job.title == mod.FACTORING and st.sources == []
    assert panel.select(viewer, 11)  # a click during the factorization
    assert jobs.running("diffusion") is job  # waited for, not restarted
    settle(viewer)
    V, F = viewer.state.mesh.V, viewer.state.mesh.F
    np.testing.assert_allclose(st.distance, HeatGeodesic(V, F).distance([11]), atol=1e-12)
    assert built == [1.0]
    assert panel.select(viewer, 30)
    job = jobs.running("diffusion")
    assert job is None or job.title == mod.SOLVING
    settle(viewer)
    np.testing.assert_allclose(st.distance, HeatGeodesic(V, F).distance([30]), atol=1e-12)
    assert built == [1.0]  # the click only back-substituted
    drive(viewer, "m (t = m h^2)", "2")  # a new m: factorized again, once
    settle(viewer)
    assert built == [1.0, 2.0]
    np.testing.assert_allclose(st.distance, HeatGeodesic(V, F, m=2).distance([30]), atol=1e-12)


def test_a_session_keeps_the_isolines_of_every_field_and_the_heat_copies_show_them(
    viewer, tmp_path, monkeypatch
):
    """The distance's toggle and count (``isolines`` / ``isoline_count``) and every other
    field's that differs from a new field's (``isoline_fields``) are saved and restored; the
    two heat copies beside the mesh carry the isolines of the field they show."""
    import json

    from legend_ledger import Ledger
    from meshlap_app import session
    from meshlap_app.state.isolines import Isolines

    ledger = Ledger().install(monkeypatch)
    panel = viewer.panels["diffusion"]
    compute_basis(viewer, k=30)
    viewer.set_panel("diffusion")
    drive(viewer, "show", "distance")
    click(viewer, 5)
    settle(viewer)
    drive(viewer, "isoline count", 30)
    drive(viewer, "show", "heat")
    settle(viewer)
    drive(viewer, "isolines", True)  # the heat's: off by default
    drive(viewer, "isoline count", 4)
    drive(viewer, "heat field", "difference")
    drive(viewer, "isoline count", 9)  # the difference's own setting (still off)
    drive(viewer, "heat field", "euler")
    frames(viewer, 2)
    st = panel.state
    for copy, which in (("heat (second way)", "spectral"), ("heat (third field)", "difference")):
        q = ledger.quantities[copy][which]
        if which == "spectral":  # the heat's setting: on, 4 curves over its own range
            v = st.heat[which]
            assert q.isolines and q.isoline_period == pytest.approx((v.max() - v.min()) / 4)
        else:  # the difference's: off
            assert not q.isolines
    path = session.save(viewer, tmp_path / "iso.json")
    saved = json.loads(path.read_text())["diffusion"]
    assert saved["isolines"] is True and saved["isoline_count"] == 30
    assert saved["isoline_fields"] == {
        "heat": {"on": True, "count": 4},
        "heat error": {"on": False, "count": 9},
    }
    panel.isolines = Isolines()  # forgotten
    session.load(viewer, path)
    frames(viewer, 2)
    assert (panel.isolines.of("distance").on, panel.isolines.of("distance").count) == (True, 30)
    assert (panel.isolines.of("heat").on, panel.isolines.of("heat").count) == (True, 4)
    assert panel.isolines.of("heat error").count == 9 and not panel.isolines.of("heat error").on
    assert not panel.isolines.of("distance error").on and panel.isolines.of("hks").on
