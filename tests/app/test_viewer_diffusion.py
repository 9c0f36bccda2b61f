"""The Diffusion panel through its widgets (ScriptedUI on polyscope's openGL_mock) and its
polyscope-free state. Its driver, :func:`tests.support.drivers.diffusion.drive_panel_diffusion`,
is also part of the widget tour of ``tests/app/test_viewer_widgets.py`` (every widget driven)."""

from __future__ import annotations

import time

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.state.diffusion import HEAT_TITLES  # noqa: E402

from meshlap_core.diffusion import (  # noqa: E402
    HeatGeodesic,
    mean_edge_length,
)
from tests.support.drivers.diffusion import click, drive_panel_diffusion  # noqa: E402
from tests.support.widgets import compute_basis, drive, frames, settle  # noqa: E402


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


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

    from meshlap_app import session
    from meshlap_app.state.isolines import Isolines

    from tests.support.legend_ledger import Ledger

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
        q = ledger.quantities[copy][HEAT_TITLES[which]]
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
