"""Saved sessions: the state <-> JSON mapping (headless), bad files, the window's *save session* /
*load session* widgets on polyscope's openGL_mock backend, ``meshlap view --session`` errors, and
(EGL) the render of a reloaded session against the render taken when it was saved."""

from __future__ import annotations

import json
import subprocess
import sys
import threading

import numpy as np
import pytest
from meshlap_app.registry import VIEWS
from meshlap_app.state.session import (
    VERSION,
    Session,
    added_keys,
    default_settings,
    from_dict,
    read_session,
    schema,
    write_session,
)

from meshlap_core import __version__, primitives
from meshlap_core.cli import main
from meshlap_core.errors import MeshError
from meshlap_core.io import save_mesh


@pytest.fixture
def sphere(tmp_path):
    path = tmp_path / "sphere.obj"
    save_mesh(path, *primitives.icosphere(2))
    return path


def non_default_session(mesh) -> Session:
    """A session whose every field differs from the default: each registered panel's every
    declared setting at its sample value (derived from the specs, no table here)."""
    s = Session(mesh=mesh.resolve(), panel=VIEWS[-1], ui_scale=1.75)
    s.camera = {"fov": 40.0, "viewMat": [float(i) for i in range(16)], "upDir": "Y Up"}
    s.settings = {sec: settings.samples() for sec, settings in schema().items()}
    return s


# ---------------------------------------------------------------- the mapping, headless
def test_every_field_differs_from_its_default_and_round_trips(tmp_path, sphere):
    s = non_default_session(sphere)
    defaults = default_settings()
    for sec, settings in schema().items():
        assert set(s.settings[sec]) == set(settings.keys())  # the test covers every field
        for key in settings.keys():
            assert s.settings[sec][key] != defaults[sec][key], f"{sec}.{key}"
    out = write_session(tmp_path / "lecture.json", s)
    data = json.loads(out.read_text())
    assert data["format"] == "meshlap-session" and data["version"] == VERSION == 1
    assert data["meshlap"] == __version__
    assert data["mesh"] == "sphere.obj"  # inside the session's folder: written relative
    back = read_session(out)
    assert back == s
    assert from_dict(s.to_dict(), "x") == s  # absolute path without a folder


def test_relative_mesh_resolves_against_the_session_folder(tmp_path, sphere, monkeypatch):
    sub = tmp_path / "slides"
    sub.mkdir()
    out = write_session(sub / "s.json", Session(mesh=sphere))
    assert json.loads(out.read_text())["mesh"] == str(sphere.resolve())  # outside: absolute
    data = Session().to_dict()
    data["mesh"] = "../sphere.obj"
    (sub / "rel.json").write_text(json.dumps(data))
    monkeypatch.chdir(tmp_path.parent)  # the working directory does not matter
    assert read_session(sub / "rel.json").mesh == sphere.resolve()


def test_missing_keys_take_the_defaults(tmp_path):
    path = tmp_path / "min.json"
    path.write_text('{"format": "meshlap-session", "version": 1, "smoothing": {"seed": 3}}')
    s = read_session(path)
    assert s.mesh is None and s.panel == "curvature" and s.camera is None
    expected = default_settings()
    expected["smoothing"]["seed"] = 3
    assert s.settings == expected


BAD = [
    ("{not json", "not JSON"),
    ("[1, 2]", "must be a JSON object"),
    ('"text"', "must be a JSON object"),
    ('{"format": "other", "version": 1}', "not a meshlap session"),
    ('{"format": "meshlap-session"}', '"version" must be an integer'),
    ('{"format": "meshlap-session", "version": "1"}', '"version" must be an integer'),
    ('{"format": "meshlap-session", "version": 2, "meshlap": "9.0"}', "newer meshlap (9.0"),
    ('{"format": "meshlap-session", "version": 1, "colour": 1}', "unknown key(s) 'colour'"),
    ('{"format": "meshlap-session", "version": 1, "mesh": "gone.obj"}', "does not exist"),
    ('{"format": "meshlap-session", "version": 1, "mesh": 5}', '"mesh" must be a file name'),
    ('{"format": "meshlap-session", "version": 1, "panel": "nope"}', '"panel" must be one of'),
    ('{"format": "meshlap-session", "version": 1, "ui_scale": 9}', '"ui_scale" must be between'),
    ('{"format": "meshlap-session", "version": 1, "camera": [1]}', '"camera" must be an object'),
    ('{"format": "meshlap-session", "version": 1, "spectral": 3}', '"spectral" must be an object'),
    ('{"format": "meshlap-session", "version": 1, "onering": {"x": 1}}', "unknown key(s) in"),
]
WRONG_VALUES = [
    ("curvature", "field", "mean"),
    ("curvature", "area", 3),
    ("curvature", "clip", "5"),
    ("curvature", "clip", 60.0),
    ("curvature", "side_by_side", 1),
    ("onering", "vertex", -2),
    ("onering", "vertex", 1.5),
    ("spectral", "computed", "yes"),
    ("spectral", "k_request", 1),
    ("spectral", "k", True),
    ("smoothing", "lam", 0),
    ("smoothing", "lam", -1.0),
    ("smoothing", "lam", None),
    ("smoothing", "noise_alpha", -0.1),
    ("smoothing", "seed", -1),
    ("smoothing", "iterations", 10**9),
    ("surfaces", "surface", "klein"),
    ("surfaces", "res", 0),
    ("surfaces", "u", "nan"),
    ("surfaces", "theta", "30"),
    ("spectral", "play", "k"),
    ("curvature_lab", "estimator", "magic"),
    ("curvature_lab", "res", 2),
    ("curvature_lab", "noise", 0.5),
    ("curvature_lab", "jitter", -0.1),
    ("curvature_lab", "flips", "0.1"),
    ("curvature_lab", "crosses", 0),
    ("curvature_lab", "vertex", -2),
]


@pytest.mark.parametrize("text, message", BAD)
def test_bad_files_are_a_clear_mesh_error(tmp_path, text, message):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(MeshError) as exc:
        read_session(path)
    assert str(exc.value).startswith(str(path)) and message in str(exc.value)


@pytest.mark.parametrize("section, key, value", WRONG_VALUES)
def test_wrong_types_and_values_name_the_field(tmp_path, section, key, value):
    data = Session().to_dict()
    data[section][key] = value
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(MeshError, match=rf'bad.json: "{section}.{key}" must'):
        read_session(path)


def test_unreadable_files_and_bad_output_paths(tmp_path, sphere):
    with pytest.raises(MeshError, match="cannot read the session"):
        read_session(tmp_path / "missing.json")
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(MeshError, match="not UTF-8"):
        read_session(tmp_path / "bin.json")
    with pytest.raises(MeshError, match="does not exist"):
        write_session(tmp_path / "no" / "s.json", Session())
    with pytest.raises(MeshError, match="unsupported output type"):
        write_session(tmp_path / "s.txt", Session())
    with pytest.raises(MeshError, match="overwrite an input"):
        write_session(sphere, Session(mesh=sphere))
    with pytest.raises(MeshError):
        write_session(tmp_path / "sphere.json", Session(mesh=sphere, ui_scale=float("nan")))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bin.json", "sphere.obj"]


def test_the_mapping_module_imports_no_polyscope():
    code = (
        "import sys, meshlap_app.state.session\n"
        "assert 'polyscope' not in sys.modules, 'polyscope imported'\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr


# ---------------------------------------------------------------- the CLI
@pytest.mark.parametrize(
    "args, message",
    [
        (["--session", "{dir}/missing.json"], "cannot read the session"),
        (["--session", "{dir}/bad.json"], "not JSON"),
        (["--session", "{dir}/newer.json"], "newer meshlap"),
        (["--session", "{dir}/nomesh.json"], "does not exist"),
        (["--session", "{dir}/vertex.json"], '"onering.vertex" 100000 is out of range'),
        (["{dir}/sphere.obj", "--session", "{dir}/ok.json"], "MESH cannot be combined"),
        (["--session", "{dir}/ok.json", "--panel", "spectral"], "--panel cannot be combined"),
    ],
)
def test_cli_refuses_bad_sessions_in_one_line(tmp_path, sphere, capsys, args, message):
    (tmp_path / "bad.json").write_text("{")
    (tmp_path / "newer.json").write_text('{"format": "meshlap-session", "version": 7}')
    (tmp_path / "nomesh.json").write_text(
        '{"format": "meshlap-session", "version": 1, "mesh": "gone.ply"}'
    )
    vertex = Session(mesh=sphere)
    vertex.settings["onering"]["vertex"] = 100_000
    write_session(tmp_path / "vertex.json", vertex)
    write_session(tmp_path / "ok.json", Session(mesh=sphere))
    code = main(["view", *(a.format(dir=tmp_path) for a in args)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("meshlap: error: ") and message in err


# ---------------------------------------------------------------- the window (openGL_mock)
ps = pytest.importorskip("polyscope")

from tests.support.drivers.help import drive_session_widgets, tick  # noqa: E402


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def new_viewer(path):
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    from tests.support.scripted_ui import ScriptedUI

    ps.remove_all_structures()
    mesh = MeshState()
    assert mesh.load(path)
    v = Viewer(AppState(mesh=mesh, folder=path.parent), ui=ScriptedUI())
    v.sync_mesh()
    ps.set_user_callback(v.callback)
    ps.frame_tick()
    return v


def test_session_widgets_save_and_load(mock, tmp_path, sphere, monkeypatch):
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    drive_session_widgets(viewer, tmp_path)
    ui = viewer.ui
    mine = {("help", "session file"), ("help", "save session"), ("help", "load session")}
    assert mine <= set(ui.seen) and mine <= ui.driven and mine <= set(ui.tooltips)


def set_up_everything(viewer) -> None:
    """Change every panel's settings away from the defaults, as a teacher would."""
    from meshlap_app.panels.help import HelpPanel

    assert isinstance(viewer.panels["help"], HelpPanel)
    viewer.set_ui_scale(1.25)
    c = viewer.state.curv
    c.field_name, c.area, c.boundary = "k2", "barycentric", "2pi"  # default: voronoi
    c.set_percentile(4.5)
    viewer.state.curv.side_by_side = True
    viewer.state.curv.second_field = "gaussian"
    viewer.panels["curvature"].sync(viewer)
    viewer.panels["onering"].state.reverse = True
    viewer.panels["onering"].select(viewer, 11)
    viewer.panels["surfaces"].state.set_surface("torus", 20)
    viewer.panels["surfaces"].state.set_uv(0.7, 1.1)
    viewer.panels["surfaces"].state.set_section(400.0)  # the normal section at θ = 40°
    spec = viewer.panels["spectral"]
    spec.state.set_play_what("modes")
    spec.state.k_request = 16
    spec.state.start(viewer.state.mesh.V, viewer.state.mesh.F, background=False)
    spec.state.set_mode(5)
    spec.state.set_k(7)
    sm = viewer.panels["smoothing"]
    sm.state.configure(
        viewer.state.mesh.V, viewer.state.mesh.F, method="explicit", laplacian="cotan"
    )
    sm.state.configure(viewer.state.mesh.V, viewer.state.mesh.F, noise_alpha=0.02, seed=4)
    sm.state.set_lam(0.001)
    for _ in range(6):
        assert sm.state.step()
    viewer.set_panel("smoothing")
    tick(viewer)
    ps.look_at((1.0, 2.0, 3.0), (0.0, 0.0, 0.0))
    tick(viewer)


def test_load_restores_every_setting_the_run_and_the_camera(mock, tmp_path, sphere, monkeypatch):
    from meshlap_app import session

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    set_up_everything(viewer)
    saved = session.capture(viewer)
    assert saved.camera is not None and saved.settings["smoothing"]["iterations"] == 6
    V_run = viewer.panels["smoothing"].state.V.copy()
    path = session.save(viewer, tmp_path / "lecture.json")

    other = tmp_path / "other.obj"
    save_mesh(other, *primitives.icosphere(1))
    fresh = new_viewer(other)  # a new window on another mesh, every setting at its default
    assert session.capture(fresh) != saved
    session.load(fresh, path)
    tick(fresh)
    tick(fresh)
    back = session.capture(fresh)
    assert back.mesh == saved.mesh and back.panel == saved.panel == "smoothing"
    assert back.settings == saved.settings and back.ui_scale == 1.25
    np.testing.assert_allclose(back.camera["viewMat"], saved.camera["viewMat"], atol=1e-6)
    # the run is replayed: same seed, same noise, same six steps, same positions
    np.testing.assert_array_equal(fresh.panels["smoothing"].state.V, V_run)
    spec = fresh.panels["spectral"].state
    assert spec.basis.info.from_cache and (spec.k, spec.mode, spec.basis.k_max) == (7, 5, 16)
    assert fresh.panels["onering"].state.vertex == 11 and fresh.panels["onering"].state.reverse
    assert fresh.panels["surfaces"].state.section_deg == 40.0 and spec.play_what == "modes"
    assert ps.has_surface_mesh("mesh (second estimator)")
    assert not fresh.reframe  # the saved camera is kept, not re-framed


def test_window_size_of_the_camera_and_a_busy_worker(mock, tmp_path, sphere, monkeypatch):
    from meshlap_app import session

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    ps.look_at((2.0, 1.0, 2.0), (0.0, 0.0, 0.0))
    tick(viewer)
    saved = session.capture(viewer)
    saved.camera["windowWidth"], saved.camera["windowHeight"] = 800, 600
    path = write_session(tmp_path / "s.json", saved)
    ps.set_window_size(1280, 720)
    ps.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0))
    tick(viewer)
    session.load(viewer, path)  # the window's load button: the window keeps its size
    tick(viewer)
    assert tuple(ps.get_window_size()) == (1280, 720)
    view = session.capture(viewer).camera["viewMat"]
    np.testing.assert_allclose(view, saved.camera["viewMat"], atol=1e-6)
    session.load(viewer, path, resize=True)  # `meshlap view --session`: the saved size
    tick(viewer)
    assert tuple(ps.get_window_size()) == (800, 600)
    np.testing.assert_allclose(view, saved.camera["viewMat"], atol=1e-6)
    ps.set_window_size(1280, 720)
    # while the eigen worker runs, a session is refused and nothing changes
    spec = viewer.panels["spectral"].state
    done = threading.Event()
    spec._jobs = viewer.state.jobs
    spec._job = viewer.state.jobs.start(
        "spectral", "eigenbasis", lambda r: done.wait(60), lambda r: None, background=True
    )
    tick(viewer)  # the re-frame for the new window size happens first
    before = session.capture(viewer)
    tick(viewer, "session file", str(path))
    tick(viewer, "load session", True)
    assert "still being computed" in viewer.state.errors["help"]
    assert session.capture(viewer) == before
    done.set()
    assert viewer.state.jobs.wait(timeout=60)


def test_dropping_a_session_file_loads_it(mock, tmp_path, sphere, monkeypatch):
    from meshlap_app import session

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    s = Session(mesh=sphere, panel="surfaces")
    s.settings["surfaces"].update(surface="torus", u=0.5)
    write_session(tmp_path / "drop.json", s)
    (tmp_path / "bad.json").write_text("{")
    viewer.files_dropped([str(tmp_path / "bad.json")])
    assert "bad.json: not JSON" in viewer.state.errors["mesh_info"]
    assert viewer.state.panel == "curvature"
    viewer.files_dropped([str(tmp_path / "drop.json")])
    tick(viewer)
    assert (
        viewer.state.panel == "surfaces"
        and viewer.panels["surfaces"].state.name == "torus"
        and viewer.panels["surfaces"].state.u == 0.5
    )
    assert session.capture(viewer).settings == s.settings and "mesh" not in viewer.state.errors


# ---------------------------------------------------------------- real pixels (EGL)
SAVE_SCRIPT = """
import sys
from pathlib import Path
import polyscope as ps
from meshlap_app import scene, session
from meshlap_app.state import AppState, CurvatureState, MeshState
from meshlap_app.viewer import Viewer, init_polyscope

mesh = MeshState(); assert mesh.load(Path(sys.argv[1]))
init_polyscope("openGL3_egl")
viewer = Viewer(AppState(mesh=mesh, curv=CurvatureState(field_name="gaussian"), panel=sys.argv[2]))
ps.set_build_default_gui_panels(False)
viewer.sync_mesh()
ps.set_window_size(1600, 900)
viewer.state.curv.set_percentile(6.0)
viewer.state.curv.side_by_side = sys.argv[2] == "curvature"
sm = viewer.panels["smoothing"].state
sm.configure(mesh.V, mesh.F, noise_alpha=0.01, seed=3)
for _ in range(4):
    sm.step()
viewer.panels["smoothing"].push(viewer, force=True)
if sys.argv[2] == "spectral":
    spec = viewer.panels["spectral"]
    spec.state.k_request = 40
    spec.state.start(mesh.V, mesh.F, background=False)
    spec.state.set_mode(6)
    spec.state.set_k(12)
    spec.push_mode(viewer, force=True)
    spec.push_k(viewer, force=True)
if sys.argv[2] == "onering":
    viewer.panels["onering"].state.reverse = True
    viewer.panels["onering"].select(viewer, 123)
if sys.argv[2] == "surfaces":
    viewer.panels["surfaces"].state.set_surface("torus", 40)
    viewer.panels["surfaces"].state.set_uv(1.0, 2.0)
viewer.panels["curvature"].sync(viewer)
viewer.set_panel(sys.argv[2])
ps.set_user_callback(viewer.callback)
ps.frame_tick()
far = 3.0 if sys.argv[2] == "surfaces" else 1.0  # the torus is larger than the mesh
ps.look_at((0.6 * far, 1.6 * far, 3.2 * far), (0.2, 0.0, 0.0))
ps.frame_tick()
ps.frame_tick()
scene.save_screenshot(Path(sys.argv[3]))
session.save(viewer, Path(sys.argv[4]))
"""


@pytest.mark.egl
@pytest.mark.parametrize("panel", ["curvature", "onering", "spectral", "smoothing", "surfaces"])
def test_render_of_a_loaded_session_equals_the_render_when_saved(tmp_path, panel, python_ok):
    import matplotlib.image as mpimg
    from meshlap_app.state.mesh import default_mesh_path

    saved_png, session_json, loaded_png = (
        tmp_path / "saved.png",
        tmp_path / "s.json",
        tmp_path / "loaded.png",
    )
    args = [str(default_mesh_path()), panel, str(saved_png), str(session_json)]
    python_ok("-c", SAVE_SCRIPT, *args, timeout=300)
    cli = ("-m", "meshlap_core.cli", "view", "--session", session_json)
    python_ok(*cli, "--screenshot", loaded_png, timeout=300)
    a = mpimg.imread(saved_png)[..., :3]
    b = mpimg.imread(loaded_png)[..., :3]
    assert a.shape == b.shape
    scene_part = np.abs(a - a[0, 0]).sum(axis=2) > 0.05
    assert scene_part.mean() > 0.05  # something is drawn
    differs = np.abs(a - b).max(axis=2) > 2 / 255  # pixel tolerance: 2 levels of 255
    assert differs.mean() < 0.002, f"{differs.mean():.4%} of the pixels differ"


# ---------------------------------------------------------------- λ changed during a run
def drive_smoothing(viewer, label, *values) -> None:
    """Give the Smoothing panel's widget ``label`` one value per frame."""
    viewer.set_panel("smoothing")
    for value in values:
        viewer.ui.script(label, value)
        tick(viewer)


def test_lam_changed_mid_run_is_replayed_bit_for_bit(mock, tmp_path, sphere, monkeypatch):
    from meshlap_app import session

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    st = viewer.panels["smoothing"].state
    drive_smoothing(viewer, "method", "explicit")
    drive_smoothing(viewer, "noise alpha", 0.02)
    drive_smoothing(viewer, "step", *[True] * 4)  # 4 steps at the default 0.5
    drive_smoothing(viewer, "lambda", "0.9")  # typed in the window: the mesh is kept
    drive_smoothing(viewer, "step", *[True] * 3)
    drive_smoothing(viewer, "lambda", "0.1")
    drive_smoothing(viewer, "step", True, True)
    drive_smoothing(viewer, "lambda", "0.3")  # set, not used yet: the next step's λ
    assert st.smoother.iteration == 9 and st.lam == 0.3
    assert st.lam_steps == [[0.5, 4], [0.9, 3], [0.1, 2]]
    V_run = np.array(st.V)
    path = session.save(viewer, tmp_path / "run.json")
    saved = json.loads(path.read_text())["smoothing"]
    assert saved["lam_steps"] == [[0.5, 4], [0.9, 3], [0.1, 2]] and saved["lam"] == 0.3
    assert saved["iterations"] == 9

    fresh = new_viewer(sphere)
    session.load(fresh, path)
    tick(fresh)
    st2 = fresh.panels["smoothing"].state
    assert np.array_equal(st2.V, V_run)  # bit for bit
    assert st2.smoother.iteration == 9 and st2.lam == st2.smoother.lam == 0.3
    assert (
        session.capture(fresh).settings["smoothing"]
        == session.capture(viewer).settings["smoothing"]
    )
    assert st.step() and st2.step()  # the next step uses the λ set last, in both
    assert np.array_equal(st2.V, st.V) and st2.lam_steps[-1] == [0.3, 1]

    # the same file without lam_steps (version 1 before it): 9 steps at 0.3, another mesh
    old = dict(saved)
    del old["lam_steps"]
    data = json.loads(path.read_text())
    data["smoothing"] = old
    (tmp_path / "old.json").write_text(json.dumps(data))
    other = new_viewer(sphere)
    session.load(other, tmp_path / "old.json")
    st3 = other.panels["smoothing"].state
    assert st3.smoother.iteration == 9 and st3.lam_steps == [[0.3, 9]]
    assert not np.array_equal(st3.V, V_run)  # so the test above proves the replay
    assert float(np.abs(st3.V - V_run).max()) > 1e-4


def test_lam_steps_written_only_when_lam_changed(mock, tmp_path, sphere, monkeypatch):
    """A run at one λ is saved as before (no ``lam_steps``: older meshlaps still read it);
    reset and a rebuild start a new record."""
    from meshlap_app import session

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    st = viewer.panels["smoothing"].state
    drive_smoothing(viewer, "step", True, True)
    assert st.lam_steps == [[0.5, 2]]
    assert session.capture(viewer).settings["smoothing"]["lam_steps"] is None
    drive_smoothing(viewer, "lambda", "0.7")  # changed after the last step: must be saved
    assert session.capture(viewer).settings["smoothing"]["lam_steps"] == [[0.5, 2]]
    drive_smoothing(viewer, "reset", True)
    assert st.lam_steps == [] and session.capture(viewer).settings["smoothing"]["lam_steps"] is None
    drive_smoothing(viewer, "step", True)
    drive_smoothing(viewer, "Laplacian", "cotan")  # a rebuild: iteration 0, a new record
    assert st.lam_steps == [] and st.smoother.iteration == 0
    path = session.save(viewer, tmp_path / "plain.json")
    assert "lam_steps" not in json.loads(path.read_text())["smoothing"]


def test_added_keys_are_written_only_when_they_say_something(tmp_path, sphere):
    """A session at the defaults has none of the keys added after the first files (an older
    meshlap, which refuses unknown keys, still opens it); set, each is written and read back."""
    ADDED_KEYS = added_keys()

    plain = json.loads(write_session(tmp_path / "plain.json", Session(mesh=sphere)).read_text())
    for sec, key in ADDED_KEYS:
        assert key not in plain[sec], f"{sec}.{key}"
    assert ADDED_KEYS  # the spectral play choice, the λ of each step, ...
    s = non_default_session(sphere)
    data = json.loads(write_session(tmp_path / "all.json", s).read_text())
    for sec, key in ADDED_KEYS:
        assert data[sec][key] == s.settings[sec][key] != schema()[sec].default(key)
    assert read_session(tmp_path / "all.json") == s


def test_old_format_file_replays_iterations_at_lam(tmp_path, sphere):
    from meshlap_app.state.smoothing import replay_steps

    path = tmp_path / "v1.json"
    path.write_text(
        json.dumps(
            {
                "format": "meshlap-session",
                "version": 1,
                "mesh": "sphere.obj",
                "smoothing": {"method": "explicit", "lam": 0.25, "iterations": 7},
            }
        )
    )
    s = read_session(path)
    assert s.settings["smoothing"]["lam_steps"] is None
    assert replay_steps(s.settings["smoothing"]) == [[0.25, 7]]
    s.settings["smoothing"]["iterations"] = 0
    assert replay_steps(s.settings["smoothing"]) == []
    path.write_text(
        json.dumps(
            {
                "format": "meshlap-session",
                "version": 1,
                "smoothing": {"lam": 2, "iterations": 3, "lam_steps": [[1, 1], [0.5, 2]]},
            }
        )
    )
    sm = read_session(path).settings["smoothing"]
    assert sm["lam_steps"] == [[1.0, 1], [0.5, 2]] and isinstance(sm["lam_steps"][0][0], float)
    assert replay_steps(sm) == [[1.0, 1], [0.5, 2]]


BAD_LAM_STEPS = [
    ('"0.5"', "must be a list of [lam, steps] pairs"),
    ("{}", "must be a list of [lam, steps] pairs"),
    ("[0.5, 3]", "entry 0 must be a [lam, steps] pair"),
    ("[[0.5, 3, 1]]", "entry 0 must be a [lam, steps] pair"),
    ("[[0, 3]]", "entry 0: lam must be > 0"),
    ("[[0.5, 1], [-1, 2]]", "entry 1: lam must be > 0"),
    ("[[NaN, 3]]", "entry 0: lam must be a finite number"),
    ("[[Infinity, 3]]", "entry 0: lam must be a finite number"),
    ('[["0.5", 3]]', "entry 0: lam must be a finite number"),
    ("[[true, 3]]", "entry 0: lam must be a finite number"),
    ("[[0.5, 0], [1.0, 3]]", "entry 0: steps must be >= 1"),
    ("[[0.5, 1.5]]", "entry 0: steps must be an integer"),
    ("[[0.5, 2], [1.0, 2]]", 'counts 4 steps but "smoothing.iterations" is 3'),
    ("[]", '"smoothing.lam_steps" counts 0 steps but "smoothing.iterations" is 3'),
]


@pytest.mark.parametrize("value, message", BAD_LAM_STEPS)
def test_bad_lam_steps_are_one_clear_error(tmp_path, value, message):
    path = tmp_path / "bad.json"
    path.write_text(
        '{"format": "meshlap-session", "version": 1, '
        f'"smoothing": {{"iterations": 3, "lam_steps": {value}}}}}'
    )
    with pytest.raises(MeshError) as err:
        read_session(path)
    text = str(err.value)
    assert text.startswith(str(path)) and message in text and "\n" not in text
    if "counts" not in message:
        assert '"smoothing.lam_steps"' in text


def test_cli_refuses_bad_lam_steps_in_one_line(tmp_path, sphere, capsys):
    path = tmp_path / "bad.json"
    path.write_text(
        json.dumps(
            {
                "format": "meshlap-session",
                "version": 1,
                "mesh": str(sphere),
                "smoothing": {"iterations": 2, "lam_steps": [[-0.5, 2]]},
            }
        )
    )
    code = main(["view", "--session", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("meshlap: error: ") and '"smoothing.lam_steps" entry 0: lam' in err


@pytest.mark.parametrize("method, laplacian", [("implicit", "cotan"), ("taubin", "uniform")])
def test_every_method_replays_lam_changes_exactly(
    mock, tmp_path, sphere, monkeypatch, method, laplacian
):
    """The implicit system is refactorized per λ and Taubin's ν follows λ: both replay bit for
    bit, including a λ set before the first step and one set after the last."""
    from meshlap_app import session

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    st = viewer.panels["smoothing"].state
    V, F = viewer.state.mesh.V, viewer.state.mesh.F
    st.configure(V, F, method=method, laplacian=laplacian, noise_alpha=0.03, seed=2)
    lams = (0.02, 0.05, 0.02) if laplacian == "cotan" else (0.3, 0.6, 0.3)
    st.set_lam(lams[0])  # before any step: the run starts at lams[0], not the built 0.5
    for lam, steps in zip(lams, (2, 3, 1), strict=True):
        st.set_lam(lam)
        for _ in range(steps):
            assert st.step()
    st.set_lam(lams[1])
    assert st.lam_steps == [[lams[0], 2], [lams[1], 3], [lams[2], 1]]
    viewer.set_panel("smoothing")
    path = session.save(viewer, tmp_path / f"{method}.json")
    fresh = new_viewer(sphere)
    session.load(fresh, path)
    st2 = fresh.panels["smoothing"].state
    assert st2.smoother.method == method and st2.lam == lams[1]
    assert np.array_equal(st2.V, st.V)
    assert st2.lam_steps == st.lam_steps


def test_curvature_lab_vertex_must_exist_on_the_labs_mesh(tmp_path, sphere):
    from meshlap_app.state.mesh import MeshState
    from meshlap_app.state.session import check_session_mesh

    mesh = MeshState()
    assert mesh.load(sphere)
    s = Session(mesh=sphere.resolve())
    lab = s.settings["curvature_lab"]
    lab.update(surface="saddle", res=8, vertex=80)  # a 9 x 9 grid: vertices 0..80
    check_session_mesh(s, mesh, "x")
    lab["vertex"] = 81
    with pytest.raises(MeshError, match=r"curvature_lab.vertex.*0\.\.80"):
        check_session_mesh(s, mesh, "x")
    lab.update(source="mesh", vertex=161)  # the icosphere(2): 162 vertices
    check_session_mesh(s, mesh, "x")
    lab["vertex"] = 162
    with pytest.raises(MeshError, match=r"0\.\.161"):
        check_session_mesh(s, mesh, "x")


def test_a_saved_session_reopens_the_curvature_lab(mock, tmp_path, sphere, monkeypatch):
    from meshlap_app import session

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    panel = viewer.panels["curvature_lab"]
    lab = panel.state
    lab.set_choice("estimator", "rusinkiewicz")
    lab.set_choice("quantity", "K")
    lab.set_choice("surface", "catenoid")
    lab.set_number("res", 10)
    lab.set_number("noise", 0.002)
    lab.set_number("jitter", 0.1)
    lab.crosses = False
    viewer.set_panel("curvature_lab")
    tick(viewer)
    assert lab.result is not None and lab.convergence(), viewer.state.errors
    lab.pick(23)
    tick(viewer)
    values, conv = lab.result.values.copy(), lab.convergence()
    path = session.save(viewer, tmp_path / "lab.json")
    assert json.loads(path.read_text())["curvature_lab"]["vertex"] == 23

    fresh = new_viewer(sphere)
    session.load(fresh, path)
    tick(fresh)
    tick(fresh)
    back = fresh.panels["curvature_lab"].state
    assert fresh.state.panel == "curvature_lab"
    assert back.settings() == lab.settings()
    assert back.vertex == 23 and back.shape_operator()["k1"] == lab.shape_operator()["k1"]
    np.testing.assert_array_equal(back.result.values, values)  # the same error map
    assert back.convergence() == conv  # and the same study


# ---------------------------------------------------------------- work a session kept badly
def drive_diffusion(viewer, label, *values) -> None:
    for value in values:
        viewer.ui.script(label, value)
        tick(viewer)


def test_a_dragged_curve_of_the_drawn_filter_is_saved_and_reopened(
    mock, tmp_path, sphere, monkeypatch
):
    """The drawn filter's control points, dragged in the plot, came back at the default curve
    from a saved session: the gains are a declared setting now, and the filtered copy of the
    reopened session is the one on screen when it was saved."""
    from meshlap_app import session
    from meshlap_app.state.diffusion import DEFAULT_KNOTS

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    spec = viewer.panels["spectral"].state
    spec.k_request = 30
    spec.start(viewer.state.mesh.V, viewer.state.mesh.F, background=False)
    viewer.set_panel("diffusion")
    drive_diffusion(viewer, "show", "filter")
    drive_diffusion(viewer, "filter", "drawn")
    drive_diffusion(viewer, "curve point 2", (0.1, 0.3))
    drive_diffusion(viewer, "curve point 5", (0.6, 1.5))
    drive_diffusion(viewer, "smoother steps", 7)
    drive_diffusion(viewer, "keep residual", True)
    st = viewer.panels["diffusion"].state
    gains = [y for _, y in st.knots]
    assert gains[2] == 0.3 and gains[5] == 1.5 and gains != [y for _, y in DEFAULT_KNOTS]
    shown = st.filtered.copy()
    path = session.save(viewer, tmp_path / "drawn.json")
    assert json.loads(path.read_text())["diffusion"]["curve"] == gains

    other = tmp_path / "other.obj"
    save_mesh(other, *primitives.icosphere(1))
    fresh = new_viewer(other)
    session.load(fresh, path)
    for _ in range(3):
        tick(fresh)
    back = fresh.panels["diffusion"].state
    assert [y for _, y in back.knots] == gains and [x for x, _ in back.knots] == [
        x for x, _ in DEFAULT_KNOTS
    ]
    assert (back.iters, back.residual, back.filter) == (7, True, "drawn")
    np.testing.assert_allclose(back.filtered, shown, atol=1e-12)
    assert (
        session.capture(fresh).settings["diffusion"]
        == session.capture(viewer).settings["diffusion"]
    )


def test_a_session_saved_in_the_hks_view_reopens_coloured(mock, tmp_path, sphere, monkeypatch):
    """Saved in the HKS view, a session reopened with "t = nan" and the mesh uncoloured: the
    signature waited for a click that restoring does not make, and a basis arriving later
    (read from the cache) was never used. Reopened through the panels, the mesh shows the
    signature at the saved time, with its colour bar, and the panel's t is that time."""
    from meshlap_app import session
    from meshlap_app.scene import MESH

    from meshlap_core.diffusion import heat_kernel_signature, hks_times
    from tests.support.legend_ledger import Ledger

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    viewer = new_viewer(sphere)
    spec = viewer.panels["spectral"].state
    spec.k_request = 20
    spec.start(viewer.state.mesh.V, viewer.state.mesh.F, background=False)
    viewer.set_panel("diffusion")
    drive_diffusion(viewer, "show", "hks")
    drive_diffusion(viewer, "HKS time", 5)
    st = viewer.panels["diffusion"].state
    assert st.hks is not None and np.isfinite(st.hks_time())
    t_saved = st.hks_time()
    path = session.save(viewer, tmp_path / "hks.json")

    ledger = Ledger().install(monkeypatch)
    fresh = new_viewer(sphere)
    session.load(fresh, path)
    for _ in range(3):
        tick(fresh)
    back = fresh.panels["diffusion"].state
    assert back.show == "hks" and back.hks_scale == 5
    assert np.isfinite(back.hks_time()) and back.hks_time() == pytest.approx(t_saved)
    basis = fresh.panels["spectral"].state.basis
    H = heat_kernel_signature(basis, hks_times(basis.eigenvalues, 16), scaled=True)
    shown = {n: q for (s, n), q in ledger.visible().items() if s == MESH}
    assert len(shown) == 1, shown
    (q,) = shown.values()
    assert q.colorbar and q.owner == "diffusion"
    np.testing.assert_allclose(q.values, H[:, 5], rtol=1e-10)
