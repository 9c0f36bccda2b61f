"""The window records all three animation kinds (issue 15): the Spectral panel plays the k sweep
and the eigenmodes, the Surfaces panel draws and turns the normal section, and each panel's
*record* header writes what it plays (one frame per change, the CLI's captions, the kind's frame
rate) atomically. Widgets are driven through the UI adapter on the openGL_mock backend; real
pixels come from an EGL subprocess (``test_recordings_with_real_pixels``)."""

from __future__ import annotations

import itertools
import textwrap

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")
Image = pytest.importorskip("PIL.Image")

from meshlap_app.record import RECORD_HEADER  # noqa: E402
from meshlap_app.registry import animated  # noqa: E402
from meshlap_app.scene import NORMAL_SECTION  # noqa: E402

DEFAULT_FPS = {k: fps for s in animated().values() for k, fps in s.animation.fps.items()}
from meshlap_app.state.surfaces import TURN_STEP_DEG, section_arc  # noqa: E402

from meshlap_core import primitives  # noqa: E402
from meshlap_core.errors import MeshError  # noqa: E402
from meshlap_core.io import save_mesh  # noqa: E402
from meshlap_core.io.animation import caption_box  # noqa: E402
from meshlap_core.surfaces import normal_curvature  # noqa: E402
from tests.support.drivers.record import (  # noqa: E402
    RECORD_WIDGETS,
    Clock,
    basis,
    drive_record_widgets,
    tick,
)


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def read_gif(path) -> tuple[list[np.ndarray], int]:
    im = Image.open(path)
    out = []
    for i in range(im.n_frames):
        im.seek(i)
        out.append(np.asarray(im.convert("RGB")).astype(int))
    return out, int(im.info["duration"])


def assert_captioned_and_distinct(frames: list[np.ndarray]) -> None:
    """Each frame has dark caption text on its light band; consecutive frames differ."""
    h, w = frames[0].shape[:2]
    _, y0, _, y1 = caption_box(h, w)
    for f in frames:
        assert (f[y0:y1].sum(axis=2) < 200).sum() > 30  # text on the band
    for a, b in itertools.pairwise(frames):
        assert not np.array_equal(a, b)


# ---------------------------------------------------------------- Spectral: play and record
def test_modes_play_at_a_readable_pace_and_record_at_1_5_fps(viewer, tmp_path):
    viewer.set_panel("spectral")
    basis(viewer, 6)  # modes 0..5: the play shows 1..5
    st = viewer.panels["spectral"].state
    clock = Clock()
    st.clock = clock
    tick(viewer, "play what", "modes")
    tick(viewer, "record file", "modes.gif")
    tick(viewer, "record", True)
    tick(viewer, "play", True)
    assert st.playing and st.mode == 1
    for _ in range(5):  # no time passes: the mode stays
        tick(viewer)
    assert st.mode == 1
    clock.now += 0.6  # < 1/1.5 s
    tick(viewer)
    assert st.mode == 1
    clock.now += 0.1
    tick(viewer)
    assert st.mode == 2
    for _ in range(10):
        clock.now += 0.7
        tick(viewer)
    assert not st.playing and st.mode == 5  # stopped at the last mode
    assert ("spectral", "pause") in viewer.ui.seen  # the button said pause while playing
    tick(viewer, "stop", True)
    rec = viewer.panels["spectral"].recorder
    assert str(tmp_path / "modes.gif") in rec.status and "1.5 fps" in rec.status
    frames, duration = read_gif(tmp_path / "modes.gif")
    assert len(frames) == 5  # modes 1..5, one frame each
    assert abs(duration - 1000 / DEFAULT_FPS["modes"]) <= 10  # 1.5 fps
    assert_captioned_and_distinct(frames)
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix != ".obj") == [
        "cache",
        "modes.gif",
    ]


def test_k_sweep_records_one_frame_per_k_at_15_fps(viewer, tmp_path):
    viewer.set_panel("spectral")
    basis(viewer, 8)
    st = viewer.panels["spectral"].state
    assert st.k == 8  # the k on screen when record is pressed is not part of the sweep
    tick(viewer, "record file", "k.gif")
    tick(viewer, "record", True)
    tick(viewer, "play", True)
    assert st.k == 1
    for _ in range(20):
        tick(viewer)
    assert not st.playing and st.k == 8
    tick(viewer, "stop", True)
    frames, duration = read_gif(tmp_path / "k.gif")
    assert len(frames) == 8  # k = 1..8
    assert abs(duration - 1000 / DEFAULT_FPS["k"]) <= 10
    assert_captioned_and_distinct(frames)


def test_pause_resumes_and_the_kind_choice_is_checked(viewer):
    viewer.set_panel("spectral")
    st = viewer.panels["spectral"].state
    with pytest.raises(MeshError, match="eigenbasis"):
        st.toggle_play()
    basis(viewer, 10)
    tick(viewer, "play", True)
    tick(viewer)
    tick(viewer)
    tick(viewer, "pause", True)
    k = st.k
    assert not st.playing and 1 < k < 10
    tick(viewer)
    assert st.k == k
    tick(viewer, "play", True)  # goes on from k, not from 1
    tick(viewer)
    assert st.k == k + 1
    tick(viewer, "play what", "nonsense")
    assert "nonsense" in viewer.state.errors["spectral"] and st.play_what == "k sweep"
    tick(viewer, "play what", "modes")  # a new choice stops the sweep
    assert st.play_what == "modes" and not st.playing and "spectral" not in viewer.state.errors


def test_spectral_copy_offset_is_cached_per_mesh(viewer, tmp_path, monkeypatch):
    import meshlap_app.panels.spectral as spectral_panel

    calls = []
    real = spectral_panel.side_offset

    def counting(V, *front):  # front: the mesh's front view (item 5 of issue 23)
        calls.append(len(V))
        return real(V, *front)

    monkeypatch.setattr(spectral_panel, "side_offset", counting)
    viewer.set_panel("spectral")
    basis(viewer, 12)
    for k in (2, 3, 4, 5, 6):
        tick(viewer, "k (reconstruct)", k)
    assert len(calls) == 1  # computed once, reused on every k move
    panel = viewer.panels["spectral"]
    before = panel._offset(viewer).copy()
    big = tmp_path / "big.obj"
    V, F = primitives.icosphere(1)
    save_mesh(big, V * np.array([3.0, 1.0, 1.0]), F)  # a different shape and vertex count
    assert viewer.open(big)
    basis(viewer, 6)
    tick(viewer, "k (reconstruct)", 3)
    assert len(calls) == 2 and calls[-1] == len(V)  # a new mesh: recomputed
    after = panel._offset(viewer)
    np.testing.assert_allclose(after, real(viewer.state.display.points(viewer.state.mesh.V)))
    assert not np.allclose(after, before)


# ---------------------------------------------------------------- Surfaces: θ and record
def test_theta_slider_draws_the_section(viewer):
    viewer.set_panel("surfaces")
    tick(viewer)
    s = viewer.panels["surfaces"].state
    assert ps.has_curve_network(NORMAL_SECTION)
    tick(viewer, "section theta", 45.0)
    assert s.section_deg == 45.0
    t, kn = s.section()
    p = s.point
    assert kn == pytest.approx(normal_curvature(s.name, s.u, s.v, np.radians(45.0)))
    assert abs(np.dot(t, p.n)) < 1e-12 and np.linalg.norm(t) == pytest.approx(1.0)
    tick(viewer, "section theta", 400.0)  # Ctrl+click may type any angle: modulo 360
    assert s.section_deg == pytest.approx(40.0)
    for bad in ("nan", "1e309"):
        tick(viewer, "section theta", bad)
        assert s.section_deg == pytest.approx(40.0) and "theta" in viewer.state.errors["surfaces"]
    assert "θ =  40.0°" in s.section_caption()
    viewer.set_panel("curvature")  # the section is the Surfaces panel's only
    assert not ps.get_curve_network(NORMAL_SECTION).is_enabled()


def test_section_arc_is_the_osculating_circle():
    class P:
        p = np.array([1.0, 2.0, 3.0])
        n = np.array([0.0, 0.0, 1.0])
        signs = "outward"  # meshlap's: kn > 0 bends away from n (a sphere, n outward)

    t = np.array([1.0, 0.0, 0.0])
    arc = section_arc(P, t, 2.0, 10.0, n=41)  # radius 1/2: clipped to one full turn
    centre = P.p - P.n / 2.0
    np.testing.assert_allclose(np.linalg.norm(arc - centre, axis=1), 0.5)
    np.testing.assert_allclose(arc[20], P.p)  # through p, tangent t there
    P.signs = "do-carmo"  # the same circle bends towards n with do Carmo's sign of kn
    arc = section_arc(P, t, 2.0, 10.0, n=41)
    np.testing.assert_allclose(np.linalg.norm(arc - (P.p + P.n / 2.0), axis=1), 0.5)
    flat = section_arc(P, t, 0.0, 1.0, n=5)
    np.testing.assert_allclose(flat[:, 0], [0.0, 0.5, 1.0, 1.5, 2.0])


@pytest.mark.parametrize("signs", ["outward", "do-carmo"])
def test_section_arc_lies_on_the_sphere_under_either_sign(signs):
    """On the unit sphere every normal section is a great circle: the osculating arc drawn
    lies on the sphere (it bent off it, outwards, with meshlap's sign)."""
    from meshlap_core import surfaces

    p = surfaces.point_geometry("sphere", 0.5, 0.7, signs=signs)
    for theta in (0.0, 0.6, 2.0):
        d = p.p_u * np.cos(theta) + p.p_v * np.sin(theta)
        t = d / np.linalg.norm(d)
        kn = surfaces.normal_curvature_from_forms(p, theta)
        arc = section_arc(p, t, kn, 1.5)
        np.testing.assert_allclose(np.linalg.norm(arc, axis=1), 1.0, atol=1e-12)


def test_theta_turn_records_one_frame_per_step(viewer, tmp_path):
    viewer.set_panel("surfaces")
    tick(viewer, "surface", "saddle")
    s = viewer.panels["surfaces"].state
    rec = viewer.panels["surfaces"].recorder
    for bad, needle in (("", "empty"), ("x.avi", ".avi"), ("nowhere/x.gif", "does not exist")):
        tick(viewer, "record file", bad)
        tick(viewer, "record", True)
        assert needle in viewer.state.errors["surfaces"] and not rec.recording  # said in red
    tick(viewer, "record file", "turn.gif")
    tick(viewer, "record", True)
    assert rec.recording and "surfaces" not in viewer.state.errors
    viewer.ui.script("record", True)  # a second recording: the button is "stop" now
    viewer.ui.script(RECORD_HEADER, True)
    ps.frame_tick()
    assert viewer.ui.pending() == {"record": [True]} and rec.recording
    viewer.ui._script.clear()
    with pytest.raises(MeshError, match="already recording"):
        rec.start(viewer)
    tick(viewer, "turn", True)
    seen = [s.section_deg]
    while s.turning:
        tick(viewer)
        seen.append(s.section_deg)
    steps = round(360 / TURN_STEP_DEG)
    assert len(seen) == steps and np.allclose(np.diff(seen), TURN_STEP_DEG)
    tick(viewer, "stop", True)
    assert f"wrote {steps} frames (15 fps) to {tmp_path / 'turn.gif'}" == rec.status
    frames, duration = read_gif(tmp_path / "turn.gif")
    assert len(frames) == steps  # one per θ step, 0..355°: a full turn as the CLI's 72 frames
    assert abs(duration - 1000 / DEFAULT_FPS["theta"]) <= 10
    assert_captioned_and_distinct(frames)
    assert not [p for p in tmp_path.iterdir() if "tmp" in p.name]  # written atomically


def test_a_resized_window_ends_the_recording_without_a_file(viewer, tmp_path, monkeypatch):
    import meshlap_app.record as record

    viewer.set_panel("surfaces")
    tick(viewer, "record file", "resized.gif")
    tick(viewer, "record", True)
    tick(viewer, "section theta", 10.0)
    rec = viewer.panels["surfaces"].recorder
    assert rec.count == 2
    real = record.ps.screenshot_to_buffer
    monkeypatch.setattr(record.ps, "screenshot_to_buffer", lambda **kw: real(**kw)[:-10, :-10])
    tick(viewer, "section theta", 20.0)
    assert not rec.recording and "recording stopped" in viewer.state.errors["surfaces"]
    assert not (tmp_path / "resized.gif").exists()
    assert not [p for p in tmp_path.iterdir() if "tmp" in p.name]
    monkeypatch.undo()
    tick(viewer, "section theta", 30.0)  # the session goes on, the θ applied
    assert (
        viewer.panels["surfaces"].state.section_deg == 30.0
        and "surfaces" not in viewer.state.errors
    )


def test_cli_theta_frames_draw_with_the_panel(viewer):
    options = {"theta": True, "frames": 4, "surface": "saddle", "uv": None}
    viewer.set_panel("surfaces")
    for i, caption in enumerate(viewer.panels["surfaces"].frames(viewer, options)):
        assert viewer.panels["surfaces"].state.section_deg == pytest.approx(90.0 * i)
        assert caption == viewer.panels["surfaces"].state.section_caption()
        assert ps.has_curve_network(NORMAL_SECTION)


# ---------------------------------------------------------------- the every-widget tour


def test_record_widgets_have_tooltips(viewer, tmp_path):
    drive_record_widgets(viewer, tmp_path)
    ui = viewer.ui
    new = (
        "play what",
        "play",
        "pause",
        "section theta",
        "turn",
        "pause turn",
        *RECORD_WIDGETS,
    )
    mine = [k for k in ui.seen if k[1] in new and k != ("smoothing", "play")]
    assert {label for _, label in mine} == set(new)
    # the record header in each of the three panels that play
    assert {p for p, label in mine if label in RECORD_WIDGETS} == {
        "spectral",
        "smoothing",
        "surfaces",
    }
    assert not sorted(set(mine) - ui.driven)
    assert not sorted(set(mine) - set(ui.tooltips))


# ---------------------------------------------------------------- real pixels (EGL)
EGL_SCRIPT = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    import polyscope as ps
    from meshlap_app.record import crop_scene
    from meshlap_app.record import RECORD_HEADER
    from meshlap_app.scene import save_screenshot
    from meshlap_app.state import AppState, CurvatureState, MeshState
    from meshlap_app.viewer import Viewer, init_polyscope
    from tests.support.scripted_ui import ScriptedUI

    mesh_path, out = Path(sys.argv[1]), Path(sys.argv[2])
    init_polyscope("openGL3_egl")
    ps.set_build_default_gui_panels(False)
    ps.set_window_size(1280, 720)
    mesh = MeshState()
    assert mesh.load(mesh_path)
    v = Viewer(AppState(mesh=mesh, folder=out), ui=ScriptedUI())
    v.sync_mesh()
    ps.set_user_callback(v.callback)

    def tick(label=None, value=None):
        if label is not None:
            v.ui.script(label, value)
            if label in ("record file", "record", "stop"):
                v.ui.script(RECORD_HEADER, True)
        ps.frame_tick()
        assert not v.ui.pending(), label
        assert not v.state.errors, v.state.errors

    v.set_panel("surfaces")
    tick(); tick()
    tick("section theta", 30.0)
    tick(); tick()
    save_screenshot(out / "surfaces_panel.png")
    tick("record file", "theta.gif")
    tick("record", True)
    tick("turn", True)
    for _ in range(11):
        tick()
    tick("pause turn", True)
    tick("stop", True)
    v.set_panel("spectral")
    st = v.panels["spectral"].state
    st.k_request = 12
    st.start(mesh.V, mesh.F, background=False)
    tick(); tick()
    tick("record file", "k.gif")
    tick("record", True)
    tick("play", True)
    while st.playing:
        tick()
    tick("stop", True)

    class Clock:  # one second per frame: a new mode each frame (the pace is tested on mock)
        now = 0.0

        def __call__(self):
            self.now += 1.0
            return self.now

    st.clock = Clock()
    tick("play what", "modes")
    tick("record file", "modes.gif")
    tick("record", True)
    tick("play", True)
    while st.playing:
        tick()
    tick("stop", True)
    """
)


@pytest.mark.egl
def test_recordings_with_real_pixels(tmp_path, sphere, python_ok):
    """EGL: the θ turn and the k sweep recorded through the widgets change the picture from
    frame to frame (the section turns, the copy grows into the sphere)."""
    pytest.importorskip("polyscope")
    python_ok("-c", EGL_SCRIPT, sphere, tmp_path)
    theta, _ = read_gif(tmp_path / "theta.gif")
    k, _ = read_gif(tmp_path / "k.gif")
    modes, _ = read_gif(tmp_path / "modes.gif")
    assert len(theta) == 12 and len(k) == 12 and len(modes) == 11
    for frames in (theta, k, modes):
        h, w = frames[0].shape[:2]
        _, y0, _, _ = caption_box(h, w)
        moved = np.abs(frames[0][:y0] - frames[-1][:y0]).sum(axis=2) > 30
        assert moved.mean() > 0.001  # the scene itself changed, not only the caption
        assert_captioned_and_distinct(frames)
    assert (tmp_path / "surfaces_panel.png").is_file()


# ---------------------------------------------------------------- pacing: play runs at full rate
@pytest.mark.parametrize(
    ("panel", "play"),
    [("smoothing", "play"), ("spectral", "play"), ("diffusion", "play t"), ("surfaces", "turn")],
)
def test_a_view_that_plays_keeps_the_full_frame_rate_without_input(viewer, panel, play):
    """The window's pacer drops to the busy or idle rate a second after the last input; a
    view that plays (smoothing, the k sweep, heat's t, the section's turn) keeps it at full
    rate while it plays, and idle comes back when it stops. Before, only polyscope's redraw
    request kept the rate up: a frame that changed nothing (the k sweep or the modes between
    two steps, a smoothing step not back yet) fell to 4 frames/s, so the next step could come
    up to 0.25 s late."""
    from meshlap_app.pacing import FULL_FPS, Pacer

    clock = Clock()
    viewer.pace, viewer.pacer = True, Pacer(clock=clock, sleep=lambda s: None)
    viewer.set_panel(panel)
    if panel == "spectral":
        basis(viewer, 6)
    if panel == "diffusion":
        tick(viewer, "show", "heat")
    tick(viewer)
    clock.now += 60.0  # a minute without input: idle
    tick(viewer)
    assert viewer.pacer.mode in ("idle", "busy")
    tick(viewer, play, True)
    assert viewer.panels[panel].animating()
    clock.now += 60.0  # playing, still no input
    tick(viewer)
    assert viewer.pacer.mode == "active" and viewer.pacer.rate(False, True) == FULL_FPS
    viewer.panels[panel].state.__dict__.update(playing=False, turning=False)  # it stopped
    clock.now += 60.0
    tick(viewer)
    assert not viewer.panels[panel].animating() and viewer.pacer.mode in ("idle", "busy")
