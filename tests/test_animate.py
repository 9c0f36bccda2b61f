"""``meshlap animate`` and the viewer's record button: bad input refused before any rendering,
GIF/MP4 writing (MP4 without the extra is a one-line error), real frames with EGL (frame count,
size, frames that change as the smoothing runs, a caption burned in), and the record / stop
buttons driven through the UI adapter on the openGL_mock backend."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.cli import main
from meshlap_core.errors import MeshError
from meshlap_core.frames import FrameWriter, burn_caption, caption_box, parse_range
from meshlap_core.io import save_mesh

Image = pytest.importorskip("PIL.Image")


@pytest.fixture
def sphere(tmp_path):
    path = tmp_path / "ico.obj"
    save_mesh(path, *primitives.icosphere(2))
    return path


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
    import meshlap_core.frames as frames

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


def _egl_or_skip() -> None:
    code = "import polyscope as ps; ps.set_allow_headless_backends(True); ps.init('openGL3_egl')"
    try:
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.skip("polyscope's EGL backend does not start")
    if res.returncode != 0:
        pytest.skip("polyscope's EGL backend cannot start on this machine (no EGL/Mesa)")


@pytest.mark.egl
def test_smoothing_gif_of_an_icosphere(tmp_path, sphere):
    _egl_or_skip()
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
    _egl_or_skip()
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


@pytest.fixture
def viewer(mock, sphere, tmp_path, monkeypatch):
    from meshlap_app.state import CurvatureState, MeshState
    from meshlap_app.ui import UI
    from meshlap_app.viewer import Viewer

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    mock.remove_all_structures()
    mesh = MeshState()
    assert mesh.load(sphere)
    v = Viewer(mesh, CurvatureState(), ui=UI(), export_dir=tmp_path)
    v.sync_mesh()
    mock.set_user_callback(v.callback)
    yield v
    mock.clear_user_callback()


def _drive(viewer, label, *values) -> None:
    """One value per frame for widget ``label`` inside the (collapsed) record header."""
    import polyscope as ps
    from meshlap_app.animate import RECORD_HEADER

    for value in values:
        viewer.ui.script(label, value)
        viewer.ui.script(RECORD_HEADER, True)
        ps.frame_tick()
        assert not viewer.ui.pending(), f"widget {label!r} was not drawn"
    internal = {k: m for k, m in viewer.errors.items() if "internal error" in m}
    assert not internal, internal


def test_record_button_smoothing_play(viewer, tmp_path):
    import polyscope as ps

    viewer.set_panel("smoothing")
    ps.frame_tick()
    st = viewer.panels["smoothing"].state
    _drive(viewer, "record file", "nowhere/x.gif")
    _drive(viewer, "record", True)  # a missing folder: said in red, nothing recorded
    assert "does not exist" in viewer.errors["smoothing"]
    assert not viewer.panels["smoothing"].recorder.recording
    _drive(viewer, "record file", "play.avi")
    _drive(viewer, "record", True)
    assert ".avi" in viewer.errors["smoothing"]
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
    st.start(viewer.mesh.V, viewer.mesh.F, background=False)
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
