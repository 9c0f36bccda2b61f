"""``meshlap animate`` and the viewer's record button: bad input refused before any rendering,
GIF/MP4 writing (MP4 without the extra is a one-line error), real frames with EGL (frame count,
size, frames that change as the smoothing runs, a caption burned in), and the record / stop
buttons driven through the UI adapter on the openGL_mock backend."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from meshlap_core.cli import main
from meshlap_core.errors import MeshError
from meshlap_core.io.animation import FrameWriter, burn_caption, caption_box, parse_range

Image = pytest.importorskip("PIL.Image")


@pytest.fixture
def no_render(monkeypatch):
    """Fail the test if the renderer is reached (every error must come before it)."""
    import meshlap_app.animate as anim

    def boom(*args, **kwargs):
        raise AssertionError("rendering started before the input was checked")

    monkeypatch.setattr(anim, "render", boom)


def _err(capsys) -> str:
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln]
    assert len(lines) == 1, err  # one line, never a traceback
    assert lines[0].startswith("meshlap: error: ")
    return lines[0]


# ---------------------------------------------------------------- bad input, exit 2
@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--panel", "spectral", "--k", "5:2"], "--k"),
        (["--panel", "spectral", "--k", "0:3"], "--k"),
        (["--panel", "spectral", "--k", "a:b"], "--k"),
        (["--panel", "spectral", "--k", "1:100000"], "--k"),
        (["--panel", "spectral", "--modes", "1:100000"], "--modes"),
        (["--panel", "spectral", "--modes=-1:3"], "--modes"),
        (["--panel", "spectral"], "--k"),
        (["--panel", "smoothing", "--lam", "nan"], "--lam"),
        (["--panel", "smoothing", "--iters", "-1"], "--iters"),
        (["--panel", "surfaces"], "--theta"),
        (["--panel", "surfaces", "--theta", "--surface", "klein"], "klein"),
        (["--panel", "smoothing", "--size", "10x10"], "--size"),
        (["--panel", "smoothing", "--session", "s.json"], "--session"),
    ],
)
def test_bad_arguments_fail_before_rendering(args, needle, sphere, tmp_path, capsys, no_render):
    out = tmp_path / "a.gif"
    code = main(["animate", str(sphere), *args, "--out", str(out)])
    assert code == 2
    assert needle in _err(capsys)
    assert not out.exists()


@pytest.mark.parametrize("name", ["missing/a.gif", "a.avi", "a", "."])
def test_bad_output_paths(name, sphere, tmp_path, capsys, no_render):
    out = tmp_path / name if name != "." else tmp_path
    code = main(["animate", str(sphere), "--panel", "smoothing", "--out", str(out)])
    assert code == 2
    _err(capsys)


def test_unwritable_directory(sphere, tmp_path, capsys, no_render, monkeypatch):
    """A directory this user cannot write in (simulated: the tests may run as root, for whom
    a read-only directory is still writable)."""
    import meshlap_core.io.animation as frames

    real = os.access
    locked = tmp_path / "locked"
    locked.mkdir()
    monkeypatch.setattr(frames.os, "access", lambda p, m: False if p == locked else real(p, m))
    code = main(["animate", str(sphere), "--panel", "smoothing", "--out", str(locked / "a.gif")])
    assert code == 2 and "permission denied" in _err(capsys)
    assert list(locked.iterdir()) == []


def test_input_mesh_is_not_an_output(tmp_path, capsys, no_render):
    gif = tmp_path / "mesh.gif"
    gif.write_bytes(b"not a mesh")
    code = main(["animate", str(gif), "--panel", "smoothing", "--out", str(gif)])
    assert code == 2
    _err(capsys)


def test_mp4_without_imageio_is_one_line(monkeypatch, sphere, tmp_path, capsys, no_render):
    monkeypatch.setitem(sys.modules, "imageio", None)  # import imageio -> ImportError
    monkeypatch.setitem(sys.modules, "imageio.v2", None)
    out = tmp_path / "a.mp4"
    code = main(["animate", str(sphere), "--panel", "smoothing", "--out", str(out)])
    assert code == 2
    line = _err(capsys)
    assert "meshlap[video]" in line and "imageio" in line
    with pytest.raises(MeshError, match="video"):
        FrameWriter(out, 10)


def test_parse_range():
    assert parse_range("1:300", "--k") == (1, 300)
    assert parse_range("12", "--modes", lo=1) == (1, 12)
    assert parse_range("0:0", "--modes", lo=0) == (0, 0)
    for bad in ("5:2", "0:3", "1:2:3", "x", ""):
        with pytest.raises(MeshError, match="--k"):
            parse_range(bad, "--k")
    with pytest.raises(MeshError, match="10 or less"):
        parse_range("1:11", "--k", hi=10)


# ---------------------------------------------------------------- writing frames
def _frames(n: int, h: int = 60, w: int = 80) -> list[np.ndarray]:
    out = []
    for i in range(n):
        f = np.full((h, w, 4), 255, dtype=np.uint8)
        f[10:30, 5 + 5 * i : 25 + 5 * i, :3] = (200, 40, 40)
        out.append(f)
    return out


def test_gif_writer_frames_size_and_duration(tmp_path):
    path = tmp_path / "x.gif"
    w = FrameWriter(path, fps=4)
    for f in _frames(5):
        w.add(f)
    assert not path.exists()  # nothing appears before close
    assert w.close() == path
    im = Image.open(path)
    assert im.n_frames == 5 and im.size == (80, 60)
    assert im.info["duration"] == 250
    seen = []
    for i in range(im.n_frames):
        im.seek(i)
        seen.append(np.asarray(im.convert("RGB")))
    assert not np.array_equal(seen[0], seen[4])
    assert seen[2][20, 5 + 10 + 2].tolist() == [200, 40, 40]
    assert [p.name for p in tmp_path.iterdir()] == ["x.gif"]  # no temporary file left


def test_writer_refuses_mixed_sizes_and_abort_leaves_nothing(tmp_path):
    path = tmp_path / "x.gif"
    w = FrameWriter(path, fps=10)
    w.add(_frames(1)[0])
    with pytest.raises(MeshError, match="frame 1"):
        w.add(np.zeros((10, 10, 3), dtype=np.uint8))
    w.abort()
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(MeshError, match="no frames"):
        FrameWriter(path, fps=10).close()
    with pytest.raises(MeshError, match="--fps"):
        FrameWriter(path, fps=0)


def test_mp4_writer_when_the_video_extra_is_installed(tmp_path):
    pytest.importorskip("imageio_ffmpeg", reason="the optional extra meshlap[video]")
    iio = pytest.importorskip("imageio.v2")
    path = tmp_path / "x.mp4"
    w = FrameWriter(path, fps=5)
    for f in _frames(6, h=61, w=81):  # odd sizes are cropped to even ones for H.264
        w.add(f)
    assert not path.exists()
    w.close()
    reader = iio.get_reader(path)
    assert reader.count_frames() == 6 and reader.get_data(0).shape == (60, 80, 3)
    assert [p.name for p in tmp_path.iterdir()] == ["x.mp4"]


def test_caption_is_burned_into_the_bottom_band():
    frame = np.full((180, 320, 4), 255, dtype=np.uint8)
    frame[:, :, :3] = 90  # a grey scene
    plain = burn_caption(frame, "")
    shot = burn_caption(frame, "iteration 3/30   λ = 1   RMSE 0.0123")
    assert plain.shape == shot.shape == (180, 320, 3)
    _, y0, _, y1 = caption_box(180, 320)
    assert np.array_equal(plain[:y0], shot[:y0])  # the scene above is untouched
    band = shot[y0:y1].astype(int)
    dark = (band.sum(axis=2) < 200).sum()  # text pixels on the light band
    assert dark > 50
    assert (plain[y0:y1] == 90).all()  # the blank frame has no band
    other = burn_caption(frame, "iteration 4/30   λ = 1   RMSE 0.0101")
    assert not np.array_equal(shot[y0:y1], other[y0:y1])
    assert (frame[..., :3] == 90).all()  # the input is not modified


# ---------------------------------------------------------------- real frames (EGL)
def _run_cli(tmp_path, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, MESHLAP_CACHE_DIR=str(tmp_path / "cache"))
    cmd = [sys.executable, "-m", "meshlap_core.cli", "animate", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=tmp_path, env=env)


def _read_gif(path) -> list[np.ndarray]:
    im = Image.open(path)
    out = []
    for i in range(im.n_frames):
        im.seek(i)
        out.append(np.asarray(im.convert("RGB")).astype(int))
    return out


@pytest.mark.egl
def test_smoothing_gif_of_an_icosphere(tmp_path, sphere):
    out = tmp_path / "smooth.gif"
    res = _run_cli(
        tmp_path,
        str(sphere),
        "--panel",
        "smoothing",
        "--noise",
        "0.02",
        "--iters",
        "4",
        "--size",
        "320x180",
        "--out",
        str(out),
    )
    assert res.returncode == 0, res.stderr
    assert "5/5 frames" in res.stderr  # the progress bar
    frames = _read_gif(out)
    assert len(frames) == 5 and frames[0].shape == (180, 320, 3)
    _, y0, _, _ = caption_box(180, 320)
    scene0, scene4 = frames[0][:y0], frames[4][:y0]
    assert np.abs(scene0 - scene4).sum(axis=2).astype(bool).mean() > 0.01  # the mesh smooths
    # the input copy stays put: the left half changes far less than the right (smoothed) half
    left = np.abs(scene0[:, :160] - scene4[:, :160]).sum()
    right = np.abs(scene0[:, 160:] - scene4[:, 160:]).sum()
    assert right > 3 * left
    for f in frames:  # a caption: dark text on the light band at the bottom
        assert ((f[y0:].sum(axis=2) < 200).sum()) > 30
    assert not np.array_equal(frames[0][y0:], frames[4][y0:])  # "iteration 0/4" -> "4/4"


@pytest.mark.egl
def test_modes_k_sweep_and_theta_render(tmp_path, sphere):
    cases = {
        "modes.gif": ["--panel", "spectral", "--modes", "1:3"],
        "k.gif": ["--panel", "spectral", "--k", "2:4"],
        "theta.gif": ["--panel", "surfaces", "--theta", "--frames", "3"],
    }
    for name, args in cases.items():
        out = tmp_path / name
        res = _run_cli(tmp_path, str(sphere), *args, "--size", "320x180", "--out", str(out))
        assert res.returncode == 0, res.stderr
        frames = _read_gif(out)
        assert len(frames) == 3, name
        # polyscope's colour bar at the top left: saturated (coloured) pixels there
        corner = frames[0][5:100, 5:40]
        saturated = (corner.max(axis=2) - corner.min(axis=2)) > 80
        assert saturated.sum() > 50, name
        assert not np.array_equal(frames[0], frames[2]), name


# ---------------------------------------------------------------- the record button (mock)
@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def _drive(viewer, label, *values) -> None:
    """One value per frame for widget ``label`` inside the (collapsed) record header."""
    import polyscope as ps
    from meshlap_app.record import RECORD_HEADER

    for value in values:
        viewer.ui.script(label, value)
        viewer.ui.script(RECORD_HEADER, True)
        ps.frame_tick()
        assert not viewer.ui.pending(), f"widget {label!r} was not drawn"
    internal = {k: m for k, m in viewer.state.errors.items() if "internal error" in m}
    assert not internal, internal


def test_record_button_smoothing_play(viewer, tmp_path):
    import polyscope as ps

    viewer.set_panel("smoothing")
    ps.frame_tick()
    st = viewer.panels["smoothing"].state
    _drive(viewer, "record file", "nowhere/x.gif")
    _drive(viewer, "record", True)  # a missing folder: said in red, nothing recorded
    assert "does not exist" in viewer.state.errors["smoothing"]
    assert not viewer.panels["smoothing"].recorder.recording
    _drive(viewer, "record file", "play.avi")
    _drive(viewer, "record", True)
    assert ".avi" in viewer.state.errors["smoothing"]
    _drive(viewer, "record file", "play.gif")
    _drive(viewer, "record", True)
    assert viewer.panels["smoothing"].recorder.recording
    viewer.ui.script("play", True)
    for _ in range(4):
        ps.frame_tick()
    st.playing = False
    _drive(viewer, "stop", True)
    rec = viewer.panels["smoothing"].recorder
    assert not rec.recording and str(tmp_path / "play.gif") in rec.status
    im = Image.open(tmp_path / "play.gif")
    # the frame at record time, then one per smoothing step while playing
    assert im.n_frames == st.smoother.iteration + 1 >= 4
    assert ("smoothing", "record") in viewer.ui.driven and ("smoothing", "stop") in viewer.ui.driven


def test_record_button_spectral_k_drag(viewer, tmp_path):
    import polyscope as ps

    viewer.set_panel("spectral")
    st = viewer.panels["spectral"].state
    st.k_request = 12
    st.start(viewer.state.mesh.V, viewer.state.mesh.F, background=False)
    ps.frame_tick()
    _drive(viewer, "record file", "k.gif")
    _drive(viewer, "record", True)
    for k in (2, 3, 3, 5):  # an unchanged k adds no frame
        viewer.ui.script("k (reconstruct)", k)
        ps.frame_tick()
    _drive(viewer, "stop", True)
    assert "4 frames" in viewer.panels["spectral"].recorder.status
    assert Image.open(tmp_path / "k.gif").n_frames == 4
    assert ("spectral", "record file") in viewer.ui.driven


# ---------------------------------------------------------------- --session (issue 15)
def _session_file(tmp_path, mesh, panel="smoothing", name="s.json", **changes):
    """A session on ``mesh`` saved on ``panel`` with a 1200x700 window (``changes``:
    ``section=dict`` updates, or top-level fields such as ``ui_scale``)."""
    from meshlap_app.state.session import Session, write_session

    s = Session(mesh=mesh, panel=panel)
    s.camera = {"fov": 45.0, "windowWidth": 1200, "windowHeight": 700, "viewMat": [0.0] * 16}
    s.settings["smoothing"].update(method="explicit", lam=0.25, noise_alpha=0.01, seed=4)
    s.settings["smoothing"]["iterations"] = 3
    s.settings["spectral"].update(k=6, mode=4)
    s.settings["surfaces"].update(surface="torus", res=30, u=1.0, v=2.0)
    for key, value in changes.items():
        if key in s.settings:
            s.settings[key].update(value)
        else:
            setattr(s, key, value)
    if changes.get("camera") or changes.get("smoothing", {}).get("iterations", 0) > 5000:
        # values the reader refuses (write_session checks them): written as it would write them
        path = tmp_path / name
        path.write_text(json.dumps(s.to_dict(tmp_path.resolve()), indent=2) + "\n")
        return path
    path = write_session(tmp_path / f"{name}.json", s)
    return path.rename(tmp_path / name)  # write_session wants .json; a session may be named .gif


@pytest.fixture
def spec_of(monkeypatch):
    """Run ``meshlap animate`` with the renderer replaced: returns the spec it was given."""
    import meshlap_app.animate as anim

    seen = []

    def fake(spec, mesh, progress=True):
        seen.append(spec)
        return spec.out

    monkeypatch.setattr(anim, "render", fake)

    def run(*args: str):
        seen.clear()
        assert main(["animate", *args]) == 0
        return seen[0]

    return run


def test_session_values_fill_what_was_not_typed(spec_of, sphere, tmp_path):
    path = _session_file(tmp_path, sphere)
    out = str(tmp_path / "a.gif")
    spec = spec_of("--session", str(path), "--out", out)
    assert spec.panel == "smoothing" and spec.mesh == sphere.resolve()
    assert (spec.options["method"], spec.options["laplacian"], spec.options["lam"]) == (
        "explicit",
        "uniform",
        0.25,
    )
    assert (spec.options["noise"], spec.options["seed"], spec.options["iters"]) == (
        0.01,
        4,
        3,
    )  # iters: the saved iteration
    assert spec.size == (680, 700)  # the 1200x700 window left of the 520-pixel panel
    assert spec.session.panel == "smoothing" and spec.session_file == path
    # typed options win over the session
    spec = spec_of("--session", str(path), "--out", out, "--lam", "2", "--iters", "7")
    assert (
        spec.options["lam"],
        spec.options["iters"],
        spec.options["method"],
        spec.options["seed"],
    ) == (2.0, 7, "explicit", 4)
    spec = spec_of("--session", str(path), "--out", out, "--size", "320x200")
    assert spec.size == (320, 200)
    # a session at iteration 0: the built-in 30 iterations; a larger UI scale: a wider panel
    zero = _session_file(tmp_path, sphere, name="z.json", smoothing={"iterations": 0})
    assert spec_of("--session", str(zero), "--out", out).options["iters"] == 30
    big = _session_file(tmp_path, sphere, name="big.json", ui_scale=1.5)
    assert spec_of("--session", str(big), "--out", out).size == (420, 700)  # 1200 - 1.5*520
    # no camera in the file: the built-in size
    nocam = _session_file(tmp_path, sphere, name="nocam.json", camera=None)
    assert spec_of("--session", str(nocam), "--out", out).size == (960, 540)


def test_session_spectral_and_surfaces_rules(spec_of, sphere, tmp_path):
    out = str(tmp_path / "a.gif")
    sp = _session_file(tmp_path, sphere, panel="spectral", name="sp.json")
    spec = spec_of("--session", str(sp), "--out", out)
    assert spec.what == "k" and spec.options["k"] == (1, 6)  # the k sweep up to the session's k
    spec = spec_of("--session", str(sp), "--out", out, "--modes", "2:5")
    assert spec.what == "modes" and spec.options["modes"] == (2, 5) and spec.options["k"] is None
    assert spec_of("--session", str(sp), "--out", out, "--k", "3:4").options["k"] == (3, 4)
    sf = _session_file(tmp_path, sphere, panel="surfaces", name="sf.json")
    spec = spec_of("--session", str(sf), "--out", out)
    assert (
        spec.options["theta"]
        and spec.options["surface"] == "torus"
        and spec.options["uv"] == (1.0, 2.0)
    )
    assert spec.options["frames"] == 72
    spec = spec_of("--session", str(sf), "--out", out, "--uv", "0.5,0.25")
    assert spec.options["uv"] == (0.5, 0.25) and spec.options["surface"] == "torus"
    spec = spec_of("--session", str(sf), "--out", out, "--surface", "saddle")
    assert (
        spec.options["surface"] == "saddle" and spec.options["uv"] is None
    )  # the torus's point is not the saddle's
    # a session saved on the curvature panel is animated with --panel
    cv = _session_file(tmp_path, sphere, panel="curvature", name="cv.json")
    spec = spec_of("--session", str(cv), "--out", out, "--panel", "smoothing")
    assert spec.panel == "smoothing" and spec.options["iters"] == 3 and spec.options["lam"] == 0.25


def test_without_a_session_the_defaults_are_unchanged(spec_of, sphere, tmp_path):
    from meshlap_app.animate import AnimationSpec

    out = tmp_path / "a.gif"
    spec = spec_of(str(sphere), "--panel", "smoothing", "--out", str(out))
    smoothing = {"method": "implicit", "laplacian": "uniform", "lam": 1.0, "iters": 30}
    smoothing |= {"noise": 0.0, "seed": 0}
    assert spec == AnimationSpec(panel="smoothing", out=out, mesh=sphere, options=smoothing)
    spec = spec_of(str(sphere), "--panel", "spectral", "--out", str(out), "--k", "1:5")
    spectral = {"k": (1, 5), "modes": None}
    assert spec == AnimationSpec(panel="spectral", out=out, mesh=sphere, options=spectral)
    spec = spec_of("--panel", "surfaces", "--theta", "--out", str(out))
    surfaces = {"theta": True, "surface": "saddle", "uv": None, "frames": 72}
    assert spec == AnimationSpec(panel="surfaces", out=out, options=surfaces)


def test_session_window_keeps_the_view_left_of_the_panel():
    from meshlap_app.animate import panel_strip, session_window
    from meshlap_app.scene import PANEL_PX
    from meshlap_app.state.session import Session

    s = Session(camera={"windowWidth": 1600, "windowHeight": 900})
    assert panel_strip(1600, 1.0) == PANEL_PX
    assert session_window(s) == ((1600, 900), 1600 - PANEL_PX)
    # another size: same vertical extent, the strip scaled with the height, centred the same
    assert session_window(s, (540, 450)) == ((540 + PANEL_PX // 2, 450), 540)
    s.ui_scale = 2.0
    assert session_window(s) == ((1600, 900), 1600 - 2 * PANEL_PX)
    s.camera = {"windowWidth": 600, "windowHeight": 400}  # the panel at most 70 % of the window
    assert session_window(s) == ((600, 400), 180)
    s.camera = None
    assert session_window(s) is None


def _bad_sessions(tmp_path, sphere) -> dict[str, str]:
    (tmp_path / "notjson.json").write_text("{ not json")
    (tmp_path / "newer.json").write_text('{"format": "meshlap-session", "version": 9}')
    (tmp_path / "nomesh.json").write_text(
        '{"format": "meshlap-session", "version": 1, "mesh": "gone.obj"}'
    )
    _session_file(tmp_path, sphere, name="vertex.json", onering={"vertex": 10**6})
    _session_file(tmp_path, sphere, panel="curvature", name="curv.json")
    _session_file(tmp_path, sphere, panel="onering", name="ring.json")
    _session_file(tmp_path, sphere, panel="spectral", name="sp.json")
    _session_file(tmp_path, sphere, name="ok.json")
    _session_file(tmp_path, sphere, name="long.json", smoothing={"iterations": 6000})
    _session_file(tmp_path, sphere, name="cam.json", camera={"windowWidth": "wide"})
    _session_file(tmp_path, sphere, name="lecture.gif")  # a session file with a .gif name
    gifmesh = tmp_path / "mesh.gif"  # a mesh whose name ends in .gif
    gifmesh.write_bytes(sphere.read_bytes())
    _session_file(tmp_path, gifmesh, name="gifmesh.json")
    return {"dir": str(tmp_path), "sphere": str(sphere)}


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--session", "{dir}/notjson.json"], "not JSON"),
        (["--session", "{dir}/newer.json"], "newer meshlap"),
        (["--session", "{dir}/missing.json"], "cannot read the session"),
        (["--session", "{dir}/nomesh.json"], "does not exist"),
        (["--session", "{dir}/vertex.json"], '"onering.vertex" 1000000 is out of range'),
        (["--session", "{dir}/curv.json"], "curvature panel, which has no animation"),
        (["--session", "{dir}/ring.json"], "--panel spectral|smoothing|surfaces"),
        (["--session", "{dir}/sp.json", "--k", "1:3", "--modes", "1:3"], "exactly one"),
        (["--session", "{dir}/sp.json", "--k", "5:2"], "--k"),
        (["--session", "{dir}/ok.json", "--lam", "-1"], "--lam"),
        (["{sphere}", "--session", "{dir}/ok.json"], "MESH cannot be combined"),
        (["--session", "{dir}/cam.json"], '"camera.windowWidth"'),
        (["--session", "{dir}/cam.json", "--size", "300x200"], '"camera.windowWidth"'),
        (["--session", "{dir}/ok.json", "--size", "10x10"], "--size"),
        (["{sphere}"], "--panel"),
        (["--session", "{dir}/long.json"], "ran 6000 iterations; an animation has at most 5000"),
    ],
)
def test_bad_sessions_fail_before_rendering(args, needle, sphere, tmp_path, capsys, no_render):
    names = _bad_sessions(tmp_path, sphere)
    before = sorted(p.name for p in tmp_path.iterdir())
    out = tmp_path / "a.gif"
    code = main(["animate", *(a.format(**names) for a in args), "--out", str(out)])
    assert code == 2
    assert needle in _err(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written


@pytest.mark.parametrize(
    ("session", "out", "needle"),
    [
        ("ok.json", "missing/a.gif", "does not exist"),
        ("ok.json", "a.png", "unsupported output type"),
        ("lecture.gif", "lecture.gif", "overwrite an input"),  # the session file itself
        ("gifmesh.json", "mesh.gif", "overwrite an input"),  # the session's mesh
    ],
)
def test_session_outputs_never_overwrite_an_input(
    session, out, needle, sphere, tmp_path, capsys, no_render
):
    _bad_sessions(tmp_path, sphere)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    code = main(["animate", "--session", str(tmp_path / session), "--out", str(tmp_path / out)])
    assert code == 2 and needle in _err(capsys)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before


def test_session_unwritable_out(sphere, tmp_path, capsys, no_render, monkeypatch):
    import meshlap_core.io.animation as frames

    path = _session_file(tmp_path, sphere)
    real = os.access
    locked = tmp_path / "locked"
    locked.mkdir()
    monkeypatch.setattr(frames.os, "access", lambda p, m: False if p == locked else real(p, m))
    code = main(["animate", "--session", str(path), "--out", str(locked / "a.gif")])
    assert code == 2 and "permission denied" in _err(capsys)
    assert list(locked.iterdir()) == []


def _teacher_session(viewer, tmp_path, panel: str):
    """Prepare ``viewer`` as a teacher would (noise, λ, 3 steps; a basis with k = 6, mode 4;
    the torus at (u, v) = (1, 2)), turn the camera and save on ``panel``."""
    import polyscope as ps
    from meshlap_app import session

    mesh = viewer.state.mesh
    sm = viewer.panels["smoothing"].state
    sm.configure(mesh.V, mesh.F, noise_alpha=0.02, seed=5)
    sm.set_lam(2.0)
    for _ in range(3):
        assert sm.step()
    viewer.panels["smoothing"].push(viewer, force=True)
    spec = viewer.panels["spectral"].state
    spec.k_request = 12
    spec.start(mesh.V, mesh.F, background=False)
    spec.set_mode(4)
    spec.set_k(6)
    viewer.panels["surfaces"].state.set_surface("torus", 30)
    viewer.panels["surfaces"].state.set_uv(1.0, 2.0)
    viewer.panels["surfaces"].state.set_section(30.0)
    viewer.set_panel(panel)
    ps.set_window_size(1200, 700)
    ps.frame_tick()
    ps.look_at((0.9, 1.1, 2.6), (0.3, 0.0, 0.0))
    ps.frame_tick()
    return session.save(viewer, tmp_path / f"{panel}.json")


@pytest.mark.parametrize("panel", ["smoothing", "spectral", "surfaces"])
def test_session_frames_start_from_the_restored_viewer(panel, viewer, spec_of, tmp_path, mock):
    """openGL_mock: the generators run on the viewer restored from the session, keep its
    camera (no re-framing) and caption what the session set."""
    import json

    import meshlap_app.animate as anim
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    path = _teacher_session(viewer, tmp_path, panel)
    saved = json.loads(path.read_text())["camera"]
    frames = ["--frames", "4"] if panel == "surfaces" else []  # (another panel refuses it)
    spec = spec_of("--session", str(path), "--out", str(tmp_path / "a.gif"), *frames)
    mock.clear_user_callback()
    mock.remove_all_structures()
    mesh = MeshState()
    assert mesh.load(spec.mesh)
    fresh = Viewer(AppState(mesh=mesh, panel=spec.panel))
    fresh.sync_mesh()
    assert anim.restore_session(fresh, spec, mesh) == 680  # the window left of the panel
    assert tuple(mock.get_window_size()) == (1200, 700)
    captions = list(fresh.panels[panel].frames(fresh, spec.options))
    assert len(captions) == spec.animation.frame_count(spec.options)
    camera = json.loads(mock.get_view_as_json())
    np.testing.assert_allclose(camera["viewMat"], saved["viewMat"], atol=1e-6)
    if panel == "smoothing":
        assert len(captions) == 4  # iterations 0..3: the last is the saved view
        assert captions[0].startswith("implicit (uniform L), λ = 2, noise α = 0.02")
        assert "iteration 0/3" in captions[0] and "iteration 3/3" in captions[-1]
        np.testing.assert_array_equal(
            fresh.panels["smoothing"].state.V, viewer.panels["smoothing"].state.V
        )
    elif panel == "spectral":
        assert [c.split("   ")[0] for c in captions] == [f"k = {k} modes" for k in range(1, 7)]
        assert fresh.panels["spectral"].state.basis.info.from_cache  # the session's basis
    else:
        assert all(c.startswith("torus at (u, v) = (1, 2)   θ = ") for c in captions)
        thetas = [float(c.split("θ = ")[1].split("°")[0]) for c in captions]
        assert thetas == [30.0, 120.0, 210.0, 300.0]  # one turn from the saved θ
        assert (
            fresh.panels["surfaces"].state.u,
            fresh.panels["surfaces"].state.v,
            fresh.panels["surfaces"].state.res,
        ) == (1.0, 2.0, 30)


def test_session_animation_replays_the_lam_of_every_step(viewer, spec_of, tmp_path, mock):
    """A run whose λ was changed mid-way (0.5 ×2, then 2 ×2): the frames step with the saved
    λ of each step and end on the saved vertices bit for bit; a typed --lam replaces them."""
    import meshlap_app.animate as anim
    from meshlap_app import session
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    mesh = viewer.state.mesh
    sm = viewer.panels["smoothing"].state
    sm.configure(mesh.V, mesh.F, noise_alpha=0.02, seed=5)
    sm.set_lam(0.5)
    for lam in (0.5, 0.5, 2.0, 2.0):
        sm.set_lam(lam)
        assert sm.step()
    viewer.set_panel("smoothing")
    path = session.save(viewer, tmp_path / "lams.json")
    out = str(tmp_path / "a.gif")

    def frames(*typed: str) -> tuple[list[str], np.ndarray]:
        spec = spec_of("--session", str(path), "--out", out, *typed)
        mock.remove_all_structures()
        m = MeshState()
        assert m.load(spec.mesh)
        fresh = Viewer(AppState(mesh=m, panel=spec.panel))
        fresh.sync_mesh()
        anim.restore_session(fresh, spec, m)
        captions = list(fresh.panels["smoothing"].frames(fresh, spec.options))
        return captions, fresh.panels["smoothing"].state.V.copy()

    captions, V = frames()
    assert [c.split("λ = ")[1].split(",")[0] for c in captions[1:]] == ["0.5", "0.5", "2", "2"]
    np.testing.assert_array_equal(V, sm.V)
    captions, V = frames("--lam", "2")  # every step at the typed λ: another result
    assert all("λ = 2," in c for c in captions)
    assert np.abs(V - sm.V).max() > 1e-6


EGL_SAVE = """
import sys
from pathlib import Path
import polyscope as ps
from meshlap_app import session
from meshlap_app.state import AppState, CurvatureState, MeshState
from meshlap_app.viewer import Viewer, init_polyscope

mesh = MeshState(); assert mesh.load(None)  # the bundled mesh
init_polyscope("openGL3_egl")
viewer = Viewer(AppState(mesh=mesh))
ps.set_build_default_gui_panels(False)
viewer.sync_mesh()
ps.set_window_size(1200, 700)
sm = viewer.panels["smoothing"].state
sm.configure(mesh.V, mesh.F, noise_alpha=0.02, seed=5)
sm.set_lam(2.0)
for _ in range(3):
    sm.step()
viewer.panels["smoothing"].push(viewer, force=True)
spec = viewer.panels["spectral"]
spec.state.k_request = 12
spec.state.start(mesh.V, mesh.F, background=False)
spec.state.set_mode(4)
spec.state.set_k(5)
viewer.panels["surfaces"].state.set_surface("torus", 30)
viewer.panels["surfaces"].state.set_uv(1.0, 2.0)
ps.set_user_callback(viewer.callback)
for panel in ("smoothing", "spectral", "surfaces"):
    viewer.set_panel(panel)
    ps.frame_tick()
    ps.frame_tick()
    if panel != "surfaces":  # the teacher turns the camera (the torus keeps the framing)
        ps.look_at((0.9, 1.1, 2.6), (0.3, 0.0, 0.0))
        ps.frame_tick()
    session.save(viewer, Path(sys.argv[1]) / f"{panel}.json")
"""


def _differing(a: np.ndarray, b: np.ndarray, tol: int = 40) -> float:
    """Fraction of pixels whose RGB differ by more than ``tol`` in some channel."""
    return float((np.abs(a - b).max(axis=2) > tol).mean())


@pytest.mark.egl
def test_session_animations_show_the_saved_view(tmp_path, python_ok):
    """EGL: a smoothing session (noise, λ = 2, 3 iterations) animates to iterations 0..3 whose
    LAST frame is the saved view (`meshlap view --session --screenshot`, cropped left of the
    panel; frame 0 is the noisy start, not the saved view); a spectral session gives the k
    sweep 1..5, a surfaces session the θ frames; an explicit --size keeps the picture's centre
    and vertical extent."""
    python_ok("-c", EGL_SAVE, tmp_path)
    view_png = tmp_path / "view.png"
    cli = ("-m", "meshlap_core.cli", "view", "--session")
    python_ok(*cli, tmp_path / "smoothing.json", "--screenshot", view_png)
    out = tmp_path / "smoothing.gif"
    res = _run_cli(tmp_path, "--session", "smoothing.json", "--shadow", "--out", str(out))
    assert res.returncode == 0, res.stderr
    frames = _read_gif(out)
    assert len(frames) == 4 and frames[0].shape == (700, 680, 3)  # 1200 - 520 panel pixels
    view = np.asarray(Image.open(view_png).convert("RGB")).astype(int)
    assert view.shape == (700, 1200, 3)
    _, y0, _, _ = caption_box(700, 680)
    saved = view[:y0, :680]  # the window left of meshlap's panel
    # the viewer writes its own small captions under the two meshes: < 1 % of the pixels
    assert _differing(frames[-1][:y0], saved) < 0.01
    assert _differing(frames[0][:y0], saved) > 0.015  # iteration 0: the noisy copy
    assert np.abs(frames[-1][:y0] - saved).mean() < 6  # GIF palette round-off only

    # an explicit size: same vertical extent, centred on the saved view's centre
    for size in ("340x350", "480x350"):
        res = _run_cli(
            tmp_path, "--session", "smoothing.json", "--iters", "0", "--size", size,
            "--out", str(tmp_path / f"{size}.gif"),
        )  # fmt: skip
        assert res.returncode == 0, res.stderr
    narrow, wide = (_read_gif(tmp_path / f"{s}.gif")[0] for s in ("340x350", "480x350"))
    assert narrow.shape == (350, 340, 3) and wide.shape == (350, 480, 3)
    _, y1, _, _ = caption_box(350, 480)
    assert _differing(narrow[:y1], wide[:y1, 70:410]) < 0.01  # the middle 340 columns
    half = frames[0][::2, ::2][:y1]  # the default size at half scale: the same picture
    assert _differing(narrow[:y1], half) < 0.05

    res = _run_cli(tmp_path, "--session", "spectral.json", "--out", str(tmp_path / "k.gif"))
    assert res.returncode == 0, res.stderr
    k = _read_gif(tmp_path / "k.gif")
    assert len(k) == 5 and k[0].shape == (700, 680, 3)  # k = 1..5, the session's k
    assert not np.array_equal(k[1], k[4])
    res = _run_cli(
        tmp_path, "--session", "surfaces.json", "--frames", "4", "--out", str(tmp_path / "t.gif")
    )
    assert res.returncode == 0, res.stderr
    theta = _read_gif(tmp_path / "t.gif")
    assert len(theta) == 4 and theta[0].shape == (700, 680, 3)
    assert not np.array_equal(theta[0], theta[1])  # the section turns


def test_session_on_another_panel_is_framed_as_without_a_session(viewer, spec_of, tmp_path, mock):
    """--panel other than the session's: its camera framed other structures, so the view is
    framed as without --session, at the requested (default: the saved view's) size."""
    import json

    import meshlap_app.animate as anim
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    path = _teacher_session(viewer, tmp_path, "curvature")
    saved = json.loads(path.read_text())["camera"]
    spec = spec_of("--session", str(path), "--panel", "smoothing", "--out", str(tmp_path / "a.gif"))
    assert spec.size == (680, 700) and spec.options["iters"] == 3
    mock.clear_user_callback()
    mock.remove_all_structures()
    mesh = MeshState()
    assert mesh.load(spec.mesh)
    fresh = Viewer(AppState(mesh=mesh, panel=spec.panel))
    fresh.sync_mesh()
    assert anim.restore_session(fresh, spec, mesh) is None  # nothing cropped
    assert fresh.state.panel == "smoothing" and tuple(mock.get_window_size()) == (680, 700)
    captions = list(fresh.panels["smoothing"].frames(fresh, spec.options))
    assert len(captions) == 4 and "iteration 3/3" in captions[-1]
    camera = json.loads(mock.get_view_as_json())
    assert not np.allclose(camera["viewMat"], saved["viewMat"], atol=1e-3)  # re-framed
