"""The Flatten panel through its widgets (ScriptedUI on polyscope's openGL_mock) and in pixels
(EGL). ``drive_panel_flatten`` is also part of the widget tour of
``tests/test_viewer_widgets.py`` (every widget driven)."""

from __future__ import annotations

import itertools
import sys
from types import SimpleNamespace

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.state.flatten import (  # noqa: E402
    DISTORTION_LABELS,
    MAX_SEAM_CLICKS,
    SETTINGS,
    boundary_for,
    describe,
)
from test_viewer_widgets import drive, frames  # noqa: E402

from meshlap_core import Flattener  # noqa: E402
from meshlap_core.flatten import UVMap  # noqa: E402
from meshlap_core.io import load_mesh  # noqa: E402
from meshlap_core.options import FLATTEN_METHODS  # noqa: E402

BAD_ITERS = ("", "0", "-1", "nan", "1e309", "abc", 10**9)


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def pick(viewer, structure: str, kind: str, index: int, position=(0.0, 0.0, 0.0), *held) -> None:
    """A scripted click on the scene that polyscope's pick answers with ``structure``'s
    element ``kind`` number ``index`` at ``position`` (display coordinates)."""
    hit = SimpleNamespace(
        is_hit=True,
        structure_name=structure,
        structure_data={"element_type": kind, "index": index},
        position=np.asarray(position, dtype=float),
    )
    real = ps.pick
    ps.pick = lambda screen_coords: hit
    try:
        viewer.ui.script("click", (10.0, 10.0, *held))
        frames(viewer, 1)
    finally:
        ps.pick = real
    frames(viewer, 1)  # the panel draws what the click changed


def lines(viewer) -> str:
    """The panel's wrapped text of the last frames."""
    return " ".join(t for sec, t in viewer.ui.lines if sec == "flatten")  # (wrapped at spaces)


def drive_maps(viewer) -> None:
    """Every map, each equal to the core's on the same disk (the sphere slit open); a map
    not in the list is refused, the last good one stays."""
    st = viewer.panels["flatten"].state
    V, F = viewer.state.mesh.V, viewer.state.mesh.F
    flat = Flattener(V, F)
    for method in FLATTEN_METHODS:
        drive(viewer, "map", method)
        frames(viewer)
        boundary = boundary_for(method, st.boundary)
        assert st.shown.key == (method, boundary)
        if method != "arap":
            np.testing.assert_allclose(st.shown.uvmap.uv, flat.map(method, boundary).uv, atol=1e-9)
    assert st.shown.uvmap.iterations == st.iters  # ARAP's first run
    drive(viewer, "map", "mercator")
    assert st.method == "arap" and "map" in viewer.state.errors["flatten"]
    table = viewer.ui.tables[("flatten", "flatten maps")]
    assert [r[0].split(",")[0] for r in table.rows] == [
        "Tutte", "harmonic", "LSCM", "spectral conformal", "ARAP",
    ]  # fmt: skip
    assert table.highlighted == [4] and not table.flagged()  # the sphere: no face flipped


def drive_boundary_and_arap(viewer) -> None:
    """The boundary combo where the map takes a shape (Tutte: the square), none for LSCM;
    ARAP's iterations typed (bad values refused), run again (continued), restarted."""
    st = viewer.panels["flatten"].state
    drive(viewer, "map", "tutte")
    drive(viewer, "boundary", "square")
    frames(viewer)
    disk = st.shown.uvmap.disk
    outer = st.shown.uvmap.uv[disk.outer]
    np.testing.assert_allclose(np.abs(outer).max(axis=1), 1.0, atol=1e-12)  # on the square
    drive(viewer, "map", "arap")  # ARAP takes the square too
    frames(viewer)
    assert st.shown.key == ("arap", "square")
    drive(viewer, "boundary", "free")
    frames(viewer)
    assert st.shown.key == ("arap", "free")
    drive(viewer, "ARAP iterations", 4)
    assert st.iters == 4
    for bad in BAD_ITERS:
        drive(viewer, "ARAP iterations", bad)
        assert st.iters == 4 and "ARAP iterations" in viewer.state.errors["flatten"]
    before = st.shown.uvmap.iterations
    e0 = list(st.shown.uvmap.energies)
    drive(viewer, "run ARAP", True)
    frames(viewer)
    m = st.shown.uvmap
    assert m.iterations == before + 4 and m.energies[: len(e0)] == e0  # continued
    assert np.all(np.diff(m.energies) <= 1e-12 * m.energies[0])
    assert viewer.ui.plots[("flatten", "##E")][0] == "line"  # the energy per iteration
    drive(viewer, "restart ARAP", True)
    frames(viewer)
    assert st.shown.uvmap.iterations == 4
    drive(viewer, "map", "lscm")
    frames(viewer)
    assert ("flatten", "boundary") in viewer.ui.seen  # (drawn for the maps that take one)
    assert st.shown.key == ("lscm", "free") and st.boundary == "free"


def drive_display(viewer, tmp_path) -> None:
    """Checker size, the distortion shown, the copy; the histograms and the export."""
    st = viewer.panels["flatten"].state
    F = viewer.state.mesh.F
    mesh = ps.get_surface_mesh("mesh")
    assert mesh.get_quantity_buffer("checkerboard", "coords").size() == 3 * len(F)
    drive(viewer, "checker size", 0.1)
    assert st.checker == 0.1
    drive(viewer, "checker size", 5.0)
    assert st.checker == SETTINGS["checker"].hi  # clamped (Ctrl+click types any value)
    for bad in ("nan", "1e309"):
        drive(viewer, "checker size", bad)
        assert st.checker == SETTINGS["checker"].hi and viewer.state.errors["flatten"]
    drive(viewer, "checker size", 0.05)
    layout = ps.get_surface_mesh("flat layout")
    assert layout.n_faces() == len(F) and layout.n_vertices() == len(st.shown.uvmap.disk.V)
    drive(viewer, "distortion", "area")
    assert layout.get_quantity_buffer(DISTORTION_LABELS["area"], "values").size() == len(F)
    drive(viewer, "distortion", "angle")
    drive(viewer, "distortion", "shear")
    assert st.distortion == "angle" and "distortion" in viewer.state.errors["flatten"]
    drive(viewer, "distortion on the surface", False)
    assert not ps.has_surface_mesh("distortion on the surface")
    drive(viewer, "distortion on the surface", True)
    assert ps.has_surface_mesh("distortion on the surface")
    drawn = [viewer.ui.plots.get(("flatten", f"##{kind} faces")) for kind in ("angle", "area")]
    assert drawn[0] is not None  # (ImPlot skips a plot scrolled out of the window)
    for kind, plot in zip(("angle", "area"), drawn, strict=True):
        assert st.shown.histograms[kind][1].sum() == len(F)
        assert plot is None or (plot[0] == "bars" and plot[2].sum() == len(F))
    caps = viewer.captions()
    assert caps == {
        "mesh": "checkerboard through LSCM",
        "flat layout": "layout (free)",  # no face flipped
        "distortion on the surface": "angle distortion",
    }
    from meshlap_app.panels.export import ExportPanel

    status = ExportPanel.export(viewer, tmp_path)
    assert "sphere_lscm_free_layout.ply" in status, status
    flat = load_mesh(tmp_path / "sphere_lscm_free_layout.ply")
    assert np.allclose(flat.V[:, 2], 0) and flat.V[:, :2].min() >= -1e-6
    values = np.loadtxt(tmp_path / "sphere_lscm_free_angle_distortion.csv", skiprows=1)
    assert values.size == len(F) and values.min() >= 1.0 - 1e-6


def drive_face_and_seam(viewer) -> None:
    """A clicked face (on the mesh, the layout, the copy): its Jacobian and the ellipse drawn
    on both; shift-clicks make a seam (the disk is cut along it), undo and clear it; a seam
    that cuts the sphere in two is refused and the last good map stays."""
    panel = viewer.panels["flatten"]
    st = panel.state
    pick(viewer, "mesh", "face", 7)
    assert st.face == 7 and "face 7: sigma1 = " in lines(viewer)
    assert ps.has_curve_network("circle on the face")
    assert ps.has_curve_network("its ellipse in the layout")
    disk = st.shown.uvmap.disk
    v = int(disk.F[11, 0])
    at = panel._layout[disk.F[11]].mean(axis=0)  # near face 11 in the layout
    pick(viewer, "flat layout", "vertex", v, at)
    assert st.face == 11
    pick(viewer, "distortion on the surface", "face", 5)
    assert st.face == 5
    drive(viewer, "clear face", True)
    assert st.face == -1 and not ps.has_curve_network("circle on the face")
    P = viewer.mesh_points()
    for v in (0, 30):
        pick(viewer, "mesh", "vertex", v, P[v], "shift")
    frames(viewer)
    assert st.seam == [0, 30] and st.shown.uvmap.disk.how.startswith("seam")
    assert ps.has_point_cloud("seam vertices") and ps.has_curve_network("cut")
    drive(viewer, "undo seam vertex", True)
    frames(viewer)
    assert st.seam == [0] and st.shown.uvmap.disk.how == "slit"
    for v in (30, 60):
        pick(viewer, "mesh", "vertex", v, P[v], "shift")
    good = st.shown
    assert good.uvmap.disk.how.startswith("seam")
    pick(viewer, "mesh", "vertex", 0, P[0], "shift")  # back to the first: a closed loop
    frames(viewer)
    assert "2 pieces" in viewer.state.errors["flatten"] and st.shown is good
    drive(viewer, "clear seam", True)
    frames(viewer)
    assert st.seam == [] and st.shown.uvmap.disk.how == "slit"
    assert len(st.seam) <= MAX_SEAM_CLICKS


def drive_flipped(viewer) -> None:
    """A map with flipped faces (one interior vertex thrown out): they are drawn in their
    own colour over the mesh and the layout, counted, and the table's row is flagged."""
    panel = viewer.panels["flatten"]
    st = panel.state
    m = st.shown.uvmap
    inner = np.setdiff1d(np.arange(len(m.uv)), m.disk.boundary)[0]
    uv = m.uv.copy()
    uv[inner] += 10.0 * np.ptp(uv, axis=0)
    view = describe(UVMap(m.method, m.boundary, uv, m.disk, 0.0))
    assert len(view.flipped) > 0
    st.adopt((None, None, view, 0.0), st.disk_key)
    frames(viewer, 2)
    for name in ("flipped faces", "flipped faces (layout)"):
        sm = ps.get_surface_mesh(name)
        assert sm.n_faces() == len(view.flipped) and sm.n_vertices() == 3 * len(view.flipped)
    table = viewer.ui.tables[("flatten", "flatten maps")]
    assert table.flagged()[0][1] == str(len(view.flipped))
    assert f"{len(view.flipped)} flipped" in viewer.captions()["flat layout"]


def drive_panel_flatten(viewer, tmp_path) -> None:
    """Every widget of the Flatten panel, with good and bad values."""
    st = viewer.panels["flatten"].state
    viewer.set_panel("flatten")
    frames(viewer, 2)
    assert st.shown is not None and st.shown.key == ("tutte", "circle")
    assert "slit along the shortest path" in lines(viewer)  # the closed sphere, said
    assert ps.has_curve_network("cut")
    drive_maps(viewer)
    drive_boundary_and_arap(viewer)
    drive_display(viewer, tmp_path)
    drive_face_and_seam(viewer)
    drive_flipped(viewer)


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
