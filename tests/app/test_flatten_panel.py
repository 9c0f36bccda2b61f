"""The Flatten panel through its widgets (ScriptedUI on polyscope's openGL_mock) and in pixels
(EGL). ``drive_panel_flatten`` is also part of the widget tour of
``tests/app/test_viewer_widgets.py`` (every widget driven)."""

from __future__ import annotations

import itertools
import sys

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from tests.support.drivers.flatten import drive_panel_flatten, lines, pick  # noqa: E402
from tests.support.widgets import drive, frames  # noqa: E402


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def test_flatten_widgets(mock, viewer, tmp_path):
    drive_panel_flatten(viewer, tmp_path)
    assert not viewer.ui.pending()


def test_leaving_the_view_hides_its_structures_and_the_checkerboard(mock, viewer):
    viewer.set_panel("flatten")
    frames(viewer, 2)
    assert ps.get_surface_mesh("flat layout").is_enabled()
    viewer.set_panel("curvature")
    frames(viewer, 2)
    assert not ps.get_surface_mesh("flat layout").is_enabled()
    with pytest.raises(Exception, match="checkerboard"):
        ps.get_surface_mesh("mesh").get_quantity_buffer("checkerboard", "coords")
    viewer.set_panel("flatten")
    frames(viewer, 2)
    assert ps.get_surface_mesh("mesh").get_quantity_buffer("checkerboard", "coords").size()


def test_a_session_brings_back_the_map_and_the_seam(mock, viewer, tmp_path):
    from meshlap_app import session

    viewer.set_panel("flatten")
    st = viewer.panels["flatten"].state
    drive(viewer, "map", "harmonic")
    drive(viewer, "boundary", "square")
    drive(viewer, "checker size", 0.08)
    P = viewer.mesh_points()
    for v in (0, 30):
        pick(viewer, "mesh", "vertex", v, P[v], "shift")
    frames(viewer)
    path = tmp_path / "s.json"
    session.save(viewer, path)
    drive(viewer, "clear seam", True)
    drive(viewer, "map", "tutte")
    session.load(viewer, path)
    frames(viewer, 3)
    assert (st.method, st.boundary, st.checker, st.seam) == ("harmonic", "square", 0.08, [0, 30])
    assert st.shown.key == ("harmonic", "square") and st.shown.uvmap.disk.how.startswith("seam")


def test_several_boundary_loops_the_longest_is_the_outer_one(mock, viewer, tmp_path):
    """A grid with a square hole: the panel says the longest loop is the outer boundary (the
    hole stays free) and draws that loop; Tutte's map puts it on the circle."""
    from meshlap_core import grid
    from meshlap_core.io import save_mesh

    V, F = grid(9, 9)
    centre = V[F].mean(axis=1)
    keep = np.abs(centre[:, :2] - 0.5).max(axis=1) > 0.2  # a hole in the middle
    path = tmp_path / "holed.obj"
    save_mesh(path, V, F[keep])
    assert viewer.open(path)
    viewer.set_panel("flatten")
    frames(viewer, 3)
    st = viewer.panels["flatten"].state
    disk = st.shown.uvmap.disk
    assert len(disk.holes) == 1 and "is the outer boundary" in lines(viewer)
    assert ps.get_curve_network("outer boundary").n_nodes() == len(disk.outer)
    np.testing.assert_allclose(np.linalg.norm(st.shown.uvmap.uv[disk.outer], axis=1), 1.0)


# ---------------------------------------------------------------- pixels (EGL)
EGL_SCRIPT = r"""
import sys
import numpy as np
import polyscope as ps
from meshlap_app.state import AppState, MeshState
from meshlap_app.state.flatten import describe
from meshlap_app.viewer import Viewer, init_polyscope
from meshlap_core.flatten import UVMap

mesh = MeshState()
assert mesh.load(None)
init_polyscope("openGL3_egl")
ps.set_build_default_gui_panels(False)
viewer = Viewer(AppState(mesh=mesh, panel="flatten"))
viewer.sync_mesh()
ps.set_window_size(1600, 600)
ps.set_ground_plane_mode("none")
ps.set_user_callback(viewer.callback)
ps.frame_tick()  # the map is computed at the view's first frame
viewer.frame()
np.save(sys.argv[1], ps.screenshot_to_buffer(transparent_bg=False, include_UI=False))
st = viewer.panels["flatten"].state
m = st.shown.uvmap
inner = np.setdiff1d(np.arange(len(m.uv)), m.disk.boundary)
uv = m.uv.copy()
uv[inner[:: max(len(inner) // 40, 1)]] *= -0.5  # 40 interior vertices thrown across
view = describe(UVMap(m.method, m.boundary, uv, m.disk, 0.0))
st.adopt((None, None, view, 0.0), st.disk_key)
viewer.panels["flatten"].push(viewer)
np.save(sys.argv[2], ps.screenshot_to_buffer(transparent_bg=False, include_UI=False))
print(len(view.flipped))
"""


def _objects(img: np.ndarray) -> list[tuple[int, int]]:
    """Column extents of the objects on the white background, left to right."""
    rgb = img[..., :3].astype(int)
    ink = (np.abs(rgb - rgb[2, 2]).sum(axis=2) > 30).sum(axis=0) > 10
    runs, start = [], None
    for x, on in enumerate(np.append(ink, False)):
        if on and start is None:
            start = x
        elif not on and start is not None:
            if x - start > 20:
                runs.append((start, x))
            start = None
    return runs


def _magenta(img: np.ndarray) -> np.ndarray:
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return (r > 170) & (b > 140) & (g < 90)


@pytest.mark.egl
def test_egl_checkerboard_layout_and_flipped_faces(tmp_path, python_ok):
    a, b = tmp_path / "a.npy", tmp_path / "b.npy"
    out = python_ok("-c", EGL_SCRIPT, a, b, timeout=300)
    flips = int(out.stdout.split()[-1])
    img, flipped = np.load(a), np.load(b)
    objects = _objects(img)
    assert len(objects) == 3, objects  # the mesh, the layout, the copy
    (m0, m1), (l0, l1), _ = objects
    mesh = img[:, m0:m1, :3].astype(int)
    r, g, b_ = mesh[..., 0], mesh[..., 1], mesh[..., 2]
    blue = (b_ > r + 60) & (b_ > g + 20)  # the checker's blue squares, shaded
    light = (r > 190) & (g > 190) & (b_ > 190) & (np.abs(r - b_) < 30)  # its light squares
    assert blue.sum() > 2000 and light.sum() > 2000, (blue.sum(), light.sum())
    row = blue[img.shape[0] // 2]
    assert np.count_nonzero(np.diff(row.astype(int))) >= 8  # squares alternate across
    assert not _magenta(img).any()  # no flip: no magenta
    assert flips > 0
    assert _magenta(flipped[:, m0:m1]).sum() > 30  # over the mesh
    assert _magenta(flipped[:, l0:l1]).sum() > 30  # over the layout
    assert sys.platform  # (the script ran in its own process: EGL and the mock never meet)


@pytest.mark.egl
def test_meshlap_view_and_animate_of_the_flatten_panel(tmp_path, python_ok):
    """``meshlap view --panel flatten --map lscm --checker 0.1 --screenshot``: the panel's
    flags apply; ``meshlap animate --panel flatten --arap-iters 3``: four frames, the map
    changing from one to the next (ARAP's iterations)."""
    from PIL import Image

    shot = tmp_path / "v.png"
    cli = ("-m", "meshlap_core.cli")
    python_ok(*cli, "view", "--panel", "flatten", "--map", "lscm", "--checker", "0.1",
              "--distortion", "area", "--screenshot", shot, timeout=300)  # fmt: skip
    img = np.asarray(Image.open(shot).convert("RGB"))
    scene = img[:, 180 : int(0.6 * img.shape[1])]  # right of the colour bars, left of the panel
    assert len(_objects(scene)) == 3  # the mesh, the layout, the copy
    gif = tmp_path / "a.gif"
    python_ok(*cli, "animate", "--panel", "flatten", "--arap-iters", "3", "--size", "480x270",
              "--out", gif, timeout=300)  # fmt: skip
    frames = []
    with Image.open(gif) as im:
        for i in range(im.n_frames):
            im.seek(i)
            frames.append(np.asarray(im.convert("RGB"), dtype=int))
    assert len(frames) == 4
    assert all(np.abs(a - b).sum() > 0 for a, b in itertools.pairwise(frames))
