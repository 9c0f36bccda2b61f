"""Hostile round 3, the viewer's causes (issue 22): one test per cause.

- ``./imgui.ini`` rewritten by ``view --screenshot``, ``view --session`` and ``animate``;
- one camera check for ``view --session`` and ``animate --session``;
- session values that passed the check and broke later (a seed ≥ 2³¹, a noise α of 1e308),
  and the panel's own seed and noise fields;
- session files through the one reader (size, special files, deep JSON, long integers) and
  the session's mesh through ``check_input``;
- one replay limit for ``smoothing.iterations``.

Every refusal is one line ``meshlap: error: <file>: <problem>`` and exit 2, before a window
or renderer starts.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from meshlap_core import primitives, save_mesh
from meshlap_core.cli import main
from meshlap_core.errors import MeshError, MeshWarning
from tests.support import hostile

V, F = primitives.icosphere(1)


@pytest.fixture
def sphere(tmp_path: Path) -> Path:
    path = tmp_path / "sphere.obj"
    save_mesh(path, V, F)
    return path


@pytest.fixture
def no_window(monkeypatch):
    """Fail the test if a window or a renderer is started (every refusal comes before)."""
    import meshlap_app.animate as anim
    import meshlap_app.viewer as viewer

    def boom(*args, **kwargs):
        raise AssertionError("polyscope started before the session was checked")

    monkeypatch.setattr(viewer, "init_polyscope", boom)
    monkeypatch.setattr(anim, "render", boom)


def _session(folder: Path, mesh: Path | None, name: str = "s.json", **changes) -> Path:
    """A session file written as the viewer writes one, with ``changes`` applied to its JSON
    (``"camera"`` replaces the camera; ``section={key: value}`` updates a section), unchecked."""
    from meshlap_app.state.session import Session

    s = Session(mesh=mesh, panel="smoothing")
    s.camera = {
        "farClip": 20.0,
        "fov": 45.0,
        "frontDir": "NegZ Forward",
        "navigateStyle": "Turntable",
        "nearClip": 0.005,
        "projectionMode": "Perspective",
        "upDir": "Y Up",
        "viewCenter": [0.0, 0.0, 0.0],
        "viewMat": [1.0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, -3, 0, 0, 0, 1],
        "viewRelativeMode": "Center Relative",
        "windowHeight": 700,
        "windowWidth": 1200,
    }
    data = s.to_dict(folder)
    for key, value in changes.items():
        if isinstance(data.get(key), dict) and isinstance(value, dict) and key != "camera":
            data[key].update(value)
        else:
            data[key] = value
    path = folder / name
    path.write_text(json.dumps(data))
    return path


def _refused(capsys, argv: list[str]) -> str:
    """Run ``meshlap ARGV``: exit 2 and exactly one error line, returned."""
    code = main(argv)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln]
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith("meshlap: error: "), err
    assert "Traceback" not in err and "internal error" not in err
    return lines[0]


def _view_and_animate(tmp_path: Path, session: Path) -> list[list[str]]:
    return [
        ["view", "--session", str(session)],
        ["view", "--session", str(session), "--screenshot", str(tmp_path / "v.png")],
        ["animate", "--session", str(session), "--out", str(tmp_path / "a.gif")],
    ]


# ---------------------------------------------------------------- ./imgui.ini
def test_the_config_folder_follows_xdg_and_home(tmp_path, monkeypatch):
    from meshlap_app import config

    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "xdg"))
    assert config.layout_file() == tmp_path / "xdg" / "meshlap" / "imgui.ini"
    monkeypatch.setenv("XDG_CONFIG_HOME", "relative/xdg")  # the XDG spec: ignored
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert config.config_dir() == tmp_path / "home" / ".config" / "meshlap"
    monkeypatch.delenv("XDG_CONFIG_HOME")
    assert config.config_dir() == tmp_path / "home" / ".config" / "meshlap"


def test_the_layout_round_trips_and_a_read_only_home_only_warns(tmp_path, monkeypatch):
    from meshlap_app import config

    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))
    assert config.read_layout() is None  # nothing saved yet, nothing created
    assert not (tmp_path / "cfg").exists()
    text = "[Window][meshlap]\nPos=10,20\nSize=300,400\n"
    assert config.write_layout(text) == tmp_path / "cfg" / "meshlap" / "imgui.ini"
    assert config.read_layout() == text
    assert [p.name for p in (tmp_path / "cfg" / "meshlap").iterdir()] == ["imgui.ini"]
    (tmp_path / "cfg" / "meshlap" / "imgui.ini").write_bytes(b"\xff\xfe bad")
    assert config.read_layout() is None  # a broken layout: the default one
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    monkeypatch.setenv("XDG_CONFIG_HOME", str(blocked))
    with pytest.warns(MeshWarning, match="window layout was not kept"):
        assert config.write_layout(text) is None


def test_the_window_keeps_its_layout_in_the_config_folder(
    polyscope_mock, sphere, tmp_path, monkeypatch
):
    """``run`` without ``--screenshot`` (the frame loop replaced: one frame): the layout is read
    from and written to the config folder; the current directory stays empty."""
    from meshlap_app import viewer as viewer_module
    from meshlap_app.state import AppState, MeshState

    cwd = tmp_path / "cwd"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))
    mesh = MeshState()
    assert mesh.load(sphere)
    viewer = viewer_module.Viewer(AppState(mesh=mesh, folder=tmp_path))
    loaded: list[str] = []
    monkeypatch.setattr(viewer.ui, "load_layout", loaded.append)
    monkeypatch.setattr(viewer_module, "run_frames", polyscope_mock.frame_tick)
    viewer_module.show_window(viewer)
    saved = tmp_path / "cfg" / "meshlap" / "imgui.ini"
    assert saved.is_file() and loaded == []
    first = saved.read_text()
    assert "[Window]" in first
    viewer_module.show_window(viewer)  # the second window opens with the saved layout
    assert loaded == [first]
    assert os.listdir(cwd) == []


@pytest.mark.egl
@pytest.mark.parametrize("command", ["view-screenshot", "view-session", "animate"])
def test_a_users_imgui_ini_is_never_touched(command, sphere, tmp_path):
    """The user's own ``./imgui.ini`` (with comments, read-only content polyscope would drop)
    is byte for byte the same after each rendering command, and nothing else appears."""
    cwd = tmp_path / "work"
    cwd.mkdir()
    mine = "; my own layout, keep these comments\n[Window][Debug##Default]\nPos=1,2\n"
    (cwd / "imgui.ini").write_text(mine)
    (cwd / ".polyscope.ini").write_text('{"windowWidth": 77}\n')
    session = _session(tmp_path, sphere)
    out = tmp_path / "out"
    out.mkdir()
    argv = {
        "view-screenshot": ["view", str(sphere), "--screenshot", str(out / "v.png")],
        "view-session": ["view", "--session", str(session), "--screenshot", str(out / "v.png")],
        "animate": [
            *("animate", str(sphere), "--panel", "smoothing", "--iters", "2"),
            *("--size", "128x96", "--out", str(out / "a.gif")),
        ],
    }[command]
    env = {
        **os.environ,
        "XDG_CONFIG_HOME": str(tmp_path / "cfg"),
        "HOME": str(tmp_path),
        "MPLCONFIGDIR": str(tmp_path / "mpl"),
    }
    res = subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", *argv],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert res.returncode == 0, res.stderr
    assert sorted(os.listdir(cwd)) == [".polyscope.ini", "imgui.ini"]
    assert (cwd / "imgui.ini").read_text() == mine
    assert (cwd / ".polyscope.ini").read_text() == '{"windowWidth": 77}\n'
    assert not (tmp_path / "cfg" / "meshlap").exists()  # headless renders keep no layout


# ---------------------------------------------------------------- one camera check
BAD_CAMERAS = [
    ("windowWidth", 100000),
    ("windowWidth", -5),
    ("windowWidth", 2**63),
    ("windowWidth", "wide"),
    ("windowWidth", 1200.0),
    ("windowWidth", True),
    ("windowHeight", 10),
    ("windowHeight", None),
    ("projectionMode", "Fisheye"),
    ("projectionMode", "perspective"),
    ("fov", "nan"),
    ("fov", 1e308),
    ("fov", 0),
    ("fov", 180),
    ("fov", -45.0),
    ("viewMat", [1.0] * 15),
    ("viewMat", [1.0] * 17),
    ("viewMat", [1.0] * 15 + [None]),
    ("viewMat", [1.0] * 15 + ["1"]),
    ("viewMat", "identity"),
    ("viewCenter", [0.0, 0.0]),
    ("upDir", "Sideways"),
    ("frontDir", 3),
    ("navigateStyle", "Orbit"),
    ("viewRelativeMode", "Camera Relative"),
    ("nearClip", 0.0),
    ("farClip", -1.0),
]


@pytest.mark.parametrize(("key", "value"), BAD_CAMERAS, ids=lambda x: repr(x)[:20])
def test_view_and_animate_refuse_the_same_bad_camera(
    key, value, sphere, tmp_path, capsys, no_window
):
    camera = json.loads(_session(tmp_path, sphere).read_text())["camera"]
    camera[key] = value
    path = _session(tmp_path, sphere, name="cam.json", camera=camera)
    lines = {_refused(capsys, argv) for argv in _view_and_animate(tmp_path, path)}
    assert len(lines) == 1, lines  # the same line from both commands
    line = lines.pop()
    assert line.startswith(f"meshlap: error: {path}: ") and f'"camera.{key}"' in line
    assert len(line) < 300  # a huge value is not echoed


def test_unknown_keys_in_the_camera_are_refused_without_echoing_them(
    sphere, tmp_path, capsys, no_window
):
    camera = json.loads(_session(tmp_path, sphere).read_text())["camera"]
    camera["padding" * 100] = list(range(10_000))
    path = _session(tmp_path, sphere, name="cam.json", camera=camera)
    for argv in _view_and_animate(tmp_path, path):
        line = _refused(capsys, argv)
        assert "unknown key(s) in 'camera'" in line and len(line) < 300


def test_what_polyscope_writes_is_accepted(polyscope_mock):
    """Every camera polyscope 2.6 writes (each up and front direction, navigation style and
    projection) reads back: the check refuses nothing the viewer saves."""
    from meshlap_app.session import camera_json
    from meshlap_app.state.camera import CAMERA_KEYS, check_camera

    ps = polyscope_mock
    ps.look_at((2.0, 1.0, 2.0), (0.0, 0.0, 0.0))
    ps.frame_tick()
    seen = set()
    for up, front, style, mode in zip(
        ["x_up", "neg_x_up", "y_up", "neg_y_up", "z_up", "neg_z_up"],
        ["y_front", "neg_y_front", "z_front", "neg_z_front", "x_front", "neg_x_front"],
        ["turntable", "free", "planar", "arcball", "none", "first_person"],
        ["orthographic", "perspective"] * 3,
        strict=True,
    ):
        ps.set_up_dir(up)
        ps.set_front_dir(front)
        ps.set_navigation_style(style)
        ps.set_view_projection_mode(mode)
        raw = json.loads(ps.get_view_as_json())
        seen |= set(raw)
        camera = camera_json()
        assert camera is not None and check_camera(camera, "s.json") == camera
    assert seen == set(CAMERA_KEYS)  # no key polyscope writes is unknown to the check
    ps.set_up_dir("y_up")
    ps.set_front_dir("neg_z_front")
    ps.set_navigation_style("turntable")
    ps.set_view_projection_mode("perspective")


def test_a_window_wider_than_the_limit_is_saved_within_it():
    from meshlap_app.state.camera import captured, check_camera

    camera = captured({"windowWidth": 11520, "windowHeight": 40, "fov": 45.0, "future": 1})
    assert camera == {"windowWidth": 8192, "windowHeight": 64, "fov": 45.0}
    assert check_camera(camera, "s.json") == camera


def test_animate_has_no_camera_check_of_its_own():
    """One validator: ``app/animate.py`` reads the window size through
    :mod:`meshlap_app.state.camera` and holds no limit of its own."""
    import meshlap_app.animate as anim

    text = Path(anim.__file__).read_text()
    assert "8192" not in text and "isinstance(x, int)" not in text


# ---------------------------------------------------------------- values that broke later
@pytest.mark.parametrize(
    ("changes", "needle"),
    [
        ({"smoothing": {"seed": 2**31}}, '"smoothing.seed" must be an integer 0 to 2147483647'),
        ({"smoothing": {"seed": 2**63}}, '"smoothing.seed" must be an integer 0 to 2147483647'),
        ({"smoothing": {"seed": 10**4000}}, "got a number of about 4001 digits"),
        ({"smoothing": {"seed": 1.0}}, '"smoothing.seed" must be an integer'),
        ({"smoothing": {"noise_alpha": 1e308}}, '"smoothing.noise_alpha": noise alpha 1e+308'),
        ({"smoothing": {"noise_alpha": 1e75}}, "use alpha <="),
    ],
)
def test_session_seed_and_noise_are_refused_when_read(
    changes, needle, sphere, tmp_path, capsys, no_window
):
    path = _session(tmp_path, sphere, name="s.json", **changes)
    for argv in _view_and_animate(tmp_path, path):
        line = _refused(capsys, argv)
        assert line.startswith(f"meshlap: error: {path}: ") and needle in line
        assert "NaN or infinite" not in line  # not blamed on the mesh
        assert len(line) < 400


def test_the_panels_seed_and_noise_fields_use_the_same_checks():
    from meshlap_app.state.smoothing import SmoothingState

    st = SmoothingState()
    st.configure(V, F, noise_alpha=0.01, seed=3)
    before = st.V.copy()
    with pytest.raises(MeshError, match=r"^noise seed: must be an integer 0 to 2147483647"):
        st.configure(V, F, seed=2**31)
    with pytest.raises(MeshError, match=r"^noise alpha: noise alpha 1e\+308 would move"):
        st.configure(V, F, noise_alpha=1e308)
    with pytest.raises(MeshError, match=r"^noise alpha: must be a finite number"):
        st.configure(V, F, noise_alpha=float("nan"))
    assert (st.noise_alpha, st.seed) == (0.01, 3)  # the last good state stays
    np.testing.assert_array_equal(st.V, before)


# ---------------------------------------------------------------- the one reader
def _fifo(folder: Path) -> Path:
    path = folder / "pipe.json"
    os.mkfifo(path)
    return path


def _device(folder: Path) -> Path:
    path = folder / "zero.json"
    path.symlink_to("/dev/zero")
    return path


def _directory(folder: Path) -> Path:
    path = folder / "folder.json"
    path.mkdir()
    return path


READER_CASES = {
    "fifo": (_fifo, "not a regular file (a named pipe (FIFO))"),
    "/dev/zero": (_device, "not a regular file (a device)"),
    "directory": (_directory, "is a directory"),
    "oversize": (lambda d: hostile.sparse_file(d, "big.json", 16 * 2**20 + 1), "at most 16 MiB"),
    "deep": (hostile.deep_json, "nested too deeply"),
    "5000 digits": (hostile.long_int_json, "more than 4300 digits"),
}


@pytest.mark.parametrize("case", sorted(READER_CASES))
def test_session_files_go_through_the_one_reader(case, tmp_path, capsys, no_window):
    make, words = READER_CASES[case]
    path = make(tmp_path)
    for argv in _view_and_animate(tmp_path, path):
        line = _refused(capsys, argv)
        assert line.startswith(f"meshlap: error: {path}: ") and words in line
        assert "out of memory" not in line and "does not exist" not in line


@pytest.mark.parametrize(
    ("kind", "words"), [("directory", "is a directory"), ("device", "not a regular file")]
)
def test_a_session_mesh_that_is_not_a_file_is_named_as_such(
    kind, words, tmp_path, capsys, no_window
):
    mesh = tmp_path / "mesh.obj"
    if kind == "directory":
        mesh.mkdir()
    else:
        mesh.symlink_to("/dev/null")
    path = _session(tmp_path, None, name="s.json")
    data = json.loads(path.read_text())
    data["mesh"] = "mesh.obj"  # relative: beside the session
    path.write_text(json.dumps(data))
    for argv in _view_and_animate(tmp_path, path):
        line = _refused(capsys, argv)
        assert line.startswith(f"meshlap: error: {path}: the mesh 'mesh.obj'")
        assert words in line and "does not exist" not in line


# ---------------------------------------------------------------- one replay limit
def test_view_and_animate_share_one_replay_limit(sphere, tmp_path, capsys, no_window):
    from meshlap_app.state import smoothing
    from meshlap_app.state.session import read_session

    limit = smoothing.MAX_FRAMES_ITERS
    ok = _session(tmp_path, sphere, name="ok.json", smoothing={"iterations": limit})
    assert read_session(ok).settings["smoothing"]["iterations"] == limit
    for n in (limit + 1, 100_000):
        path = _session(tmp_path, sphere, name=f"n{n}.json", smoothing={"iterations": n})
        lines = {_refused(capsys, argv) for argv in _view_and_animate(tmp_path, path)}
        assert len(lines) == 1, lines
        line = lines.pop()
        assert f'"smoothing.iterations" must be 0 to {limit}' in line
        assert f"ran {n} iterations" in line


def test_no_session_reader_opens_a_file_outside_the_reader():
    """``app/state/session.py`` reads through ``meshlap_core.io.reader`` only."""
    import meshlap_app.state.session as session_module

    text = Path(session_module.__file__).read_text()
    assert "read_text(" not in text and "open(" not in text and "read_json(" in text
