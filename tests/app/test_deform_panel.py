"""The Deform panel through its widgets (ScriptedUI on polyscope's openGL_mock), a handle
dragged in real pixels (EGL), and ``meshlap view`` / ``meshlap animate`` on it.
``drive_panel_deform`` (:mod:`tests.support.drivers.deform`) is also part of the widget tour of
``tests/app/test_viewer_widgets.py`` (every widget driven)."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_core.deform import make_deformer  # noqa: E402
from tests.support.drivers.deform import click, drive_panel_deform, settle  # noqa: E402
from tests.support.widgets import drive, frames  # noqa: E402


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def test_deform_widgets(viewer):
    drive_panel_deform(viewer)
    ui = viewer.ui
    mine = {k for k in ui.seen if k[0] == "deform"}
    assert mine and not sorted(mine - ui.driven)


def test_the_set_up_is_a_job_with_progress_and_cancel(viewer, monkeypatch):
    """In the window the set-up runs off the UI thread: its progress line and Cancel show in
    the panel; Cancel keeps what was on screen (and is not undone by a rebuild); the next
    change builds again."""
    import meshlap_app.panels.deform as mod

    original = mod.build_set

    def slow(*args, **kwargs):
        time.sleep(0.5)  # long enough for the Cancel button to be pressed meanwhile
        return original(*args, **kwargs)

    monkeypatch.setattr(mod, "build_set", slow)
    viewer.background = True
    st = viewer.panels["deform"].state
    viewer.set_panel("deform")
    frames(viewer)
    click(viewer, 5)
    job = viewer.state.jobs.running("deform")
    assert job is not None and "set-up" in job.title
    drive(viewer, "Cancel##deform", True)
    frames(viewer, 2)
    assert viewer.state.jobs.running("deform") is None and st.built is None
    drive(viewer, "handle radius %", 4.0)  # a new set: built again
    settle(viewer)
    assert st.built is not None and st.handles == [5]


def test_a_session_reopens_the_deformation(viewer, tmp_path):
    from meshlap_app import session

    st = viewer.panels["deform"].state
    viewer.set_panel("deform")
    frames(viewer)
    click(viewer, 9)
    click(viewer, 60, "shift")
    settle(viewer)
    st.set_move(1, {"rotate": [0.0, 1.0, 0.0, 35.0], "move": [0.1, 0.2, 0.0]})
    settle(viewer)
    shape = np.array(st.shown["arap"].positions)
    path = tmp_path / "d.json"
    session.save(viewer, path)
    saved = json.loads(path.read_text())["deform"]
    assert saved["handles"] == [9, 60] and saved["moves"][1]["rotate"][3] == 35.0
    drive(viewer, "clear handles", True)
    session.load(viewer, path)
    settle(viewer)
    assert st.handles == [9, 60] and st.moves[1] == saved["moves"][1]
    np.testing.assert_allclose(st.shown["arap"].positions, shape, atol=1e-8)


PIXEL_SCRIPT = """
import json, sys
import numpy as np
import polyscope as ps
from meshlap_app.camera import project_to_screen
from meshlap_app.state import AppState, MeshState
from meshlap_app.viewer import Viewer, init_polyscope
from tests.support.scripted_ui import ScriptedUI

mesh = MeshState(); mesh.load(None)
init_polyscope("openGL3_egl")
viewer = Viewer(AppState(mesh=mesh, panel="deform"), ui=ScriptedUI())
viewer.sync_mesh()
ps.set_user_callback(viewer.callback)
ps.reset_camera_to_home_view()
for _ in range(3):
    ps.frame_tick()
panel = viewer.panels["deform"]
P = viewer.mesh_points()
high = np.flatnonzero(P[:, 1] > 0.6 * P[:, 1].max())  # near the top, facing the camera
top = int(high[np.argmin(P[high, 2])])
w, h = ps.get_window_size()
def screen(i):  # where vertex i of the deformed copy is on screen now
    params = ps.get_view_camera_parameters()
    Q = panel._positions(viewer, panel.state.methods[0])
    xy, _ = project_to_screen(Q[[i]], params.get_view_mat(), params.get_fov_vertical_deg(), w, h)
    return float(xy[0, 0]), float(xy[0, 1])
at = screen(top)
assert viewer.pick_at(at)  # the press: a click once released in place
for _ in range(500):
    ps.frame_tick()
    if panel.state.built is not None and not panel.state.due():
        break
ps.frame_tick()
rest = ps.screenshot_to_buffer(False)
at = screen(top)
assert viewer.pick_at(at)  # a press on the handle: a drag in the screen plane
assert panel._drag is not None
up = (at[0], at[1] - 0.12 * h)
viewer.ui.script("scene drag", (*at, True), (*up, True), (*up, False))
for _ in range(500):
    ps.frame_tick()
    if not panel.state.due() and not viewer.ui.pending():
        break
ps.frame_tick()
moved = ps.screenshot_to_buffer(False)
np.save(sys.argv[1], np.stack([rest, moved]))
print(json.dumps({"at": at, "after": screen(top), "top": top, "handles": panel.state.handles,
                  "move": panel.state.moves[0]["move"]}))
"""


@pytest.mark.egl
def test_a_dragged_handle_moves_the_mesh_in_the_picture(tmp_path, python_ok):
    """Real pixels (EGL): the top vertex clicked (a handle), then dragged up in the screen
    plane: the mesh's silhouette reaches higher by about the drag, and the rest of it stays
    (ARAP, the farthest region held)."""
    out = tmp_path / "shots.npy"
    res = python_ok("-c", PIXEL_SCRIPT, out, timeout=300)
    info = json.loads(res.stdout.strip().splitlines()[-1])
    rest, moved = np.load(out)[..., :3].astype(int)
    h, w, _ = rest.shape
    scene = slice(0, int(0.55 * w))  # left of meshlap's panel

    def top_row(img):
        fg = np.abs(img[:, scene] - img[h - 2, 2]).sum(axis=2) > 40  # not the background
        fg[:40] = False  # (the colour bar's title)
        rows = np.flatnonzero(fg.any(axis=1))
        return int(rows[0])

    assert info["handles"] == [info["top"]]
    drag = 0.12 * h
    rise = top_row(rest) - top_row(moved)
    # the handle followed the mouse up the screen plane; the silhouette's top rose with it
    assert info["at"][1] - info["after"][1] > 0.7 * drag, info
    assert rise > 0.25 * drag, (rise, drag)
    bottom = slice(int(0.8 * h), h)  # the held bottom part barely changes
    changed = np.abs(rest[bottom, scene] - moved[bottom, scene]).sum(axis=2) > 60
    assert changed.mean() < 0.02


@pytest.mark.egl
def test_view_screenshot_and_animate_a_drag(tmp_path, python_ok, sphere):
    """``meshlap view --panel deform --screenshot``: a lifted, turned handle with its colour
    bar; ``meshlap animate --panel deform``: frames of the drag, the shape changing."""
    from PIL import Image

    shot = tmp_path / "d.png"
    python_ok("-m", "meshlap_core.cli", "view", sphere, "--panel", "deform",
              "--screenshot", shot, timeout=300)  # fmt: skip
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    corner = img[20:250, 10:40]  # the colour bar of the displacement
    assert ((corner.max(axis=2) - corner.min(axis=2)) > 80).sum() > 100
    gif = tmp_path / "drag.gif"
    res = python_ok("-m", "meshlap_core.cli", "animate", sphere, "--panel", "deform",
                    "--drag-frames", "4", "--deform-method", "biharmonic", "--size", "320x180",
                    "--out", gif, timeout=300)  # fmt: skip
    assert "4/4 frames" in res.stderr
    im = Image.open(gif)
    assert im.n_frames == 4
    first = np.asarray(im.convert("RGB")).astype(int)
    im.seek(3)
    last = np.asarray(im.convert("RGB")).astype(int)
    assert np.abs(first[:150] - last[:150]).sum(axis=2).astype(bool).mean() > 0.01


def test_a_big_mesh_keeps_its_deformers_in_a_child_process(viewer, monkeypatch):
    """Above the inline size (patched to 0 here) the window builds the handle set in a child
    process and each move is a job solved there (CHOLMOD holds the GIL: a thread would freeze
    the window); the shape, energy and rotation-error map are those of a deformer built here,
    and a new set ends the old child."""
    import meshlap_app.panels.deform as mod

    monkeypatch.setattr(mod, "INLINE_SOLVE_MAX", 0)
    viewer.background = True
    viewer.state.jobs.processes = True
    V, F = viewer.state.mesh.V, viewer.state.mesh.F
    st = viewer.panels["deform"].state
    viewer.set_panel("deform")
    drive(viewer, "method", "biharmonic")
    frames(viewer)
    click(viewer, 12)
    settle(viewer)
    b = st.built
    assert getattr(b, "remote", False) and b.child.alive
    st.set_move(0, {"rotate": [0.0, 0.0, 1.0, 20.0], "move": [0.0, 0.3, 0.0]})
    drive(viewer, "colour", "rotation error")
    settle(viewer)
    ref = make_deformer("biharmonic", V, F, b.regions.vertices, b.fixed)
    U = ref.update(st.targets("biharmonic"))
    np.testing.assert_allclose(st.shown["biharmonic"].positions, U, atol=1e-10)
    assert st.figures("biharmonic")["energy"] == pytest.approx(ref.energy(), rel=1e-9)
    np.testing.assert_allclose(st.field("biharmonic"), ref.rotation_error(), atol=1e-10)
    drive(viewer, "handle radius %", 7.0)  # a new set: the old child ends
    settle(viewer)
    assert st.built is not b and not b.child.alive
    drive(viewer, "colour", "displacement")
    drive(viewer, "method", "arap")
    settle(viewer)
