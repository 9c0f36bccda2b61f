"""The Flatten view's widgets: the maps and their settings, the boundary and ARAP, the display
(checkerboard, layout, distortion copy), a clicked face and the seam, flipped faces; and the
real-window tour's step (:func:`checkerboard_step`)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import polyscope as ps
from meshlap_app.state.flatten import (
    DISTORTION_LABELS,
    MAX_SEAM_CLICKS,
    SETTINGS,
    boundary_for,
    describe,
)

from meshlap_core import Flattener
from meshlap_core.flatten import UVMap
from meshlap_core.io import load_mesh
from meshlap_core.options import FLATTEN_METHODS
from tests.support.imgui_screen import changed_fraction, parse, subjects
from tests.support.widgets import drive, frames, settle_jobs
from tests.support.window_session import Session

BAD_ITERS = ("", "0", "-1", "nan", "1e309", "abc", 10**9)


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
    size = ps.get_window_size()
    ps.set_window_size(size[0], 4000)  # ImPlot skips a plot scrolled out of the window: a
    try:  # window tall enough for the panel, whatever the tests before left open
        frames(viewer, 2)
        drawn = [viewer.ui.plots.get(("flatten", f"##{kind} faces")) for kind in ("angle", "area")]
    finally:
        ps.set_window_size(*size)
    assert drawn[0] is not None
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


# ------------------------------------------------------------------ the real window's step
def checkerboard(img: np.ndarray, box: tuple[int, int]) -> bool:
    """The Flatten view's checkerboard on the object between the columns ``box``: its blue
    and its light squares (each at least 400 pixels, shaded by the lighting), alternating
    along the object's middle row."""
    x0, x1 = box
    c = img[:, x0:x1].astype(np.int16)
    r, g, b = c[..., 0], c[..., 1], c[..., 2]
    blue = (b > r + 60) & (b > g + 20)
    light = (r > 190) & (g > 190) & (b > 190) & (np.abs(r - b) < 30)
    ys = np.flatnonzero(blue.any(axis=1))
    if blue.sum() < 400 or light.sum() < 400 or len(ys) == 0:
        return False
    row = blue[(ys[0] + ys[-1]) // 2]
    return int(np.count_nonzero(np.diff(row.astype(np.int8)))) >= 6


def checkerboard_step(s: Session) -> None:
    """The Flatten view (its number key; the view combo when it has none): the checkerboard
    through Tutte's map on the mesh, the flat layout and the copy coloured by the distortion
    beside it (three objects, none behind the panel); the map combo (the view's first) to
    LSCM (its third entry): the layout changes and the checkerboard stays."""
    from meshlap_app.registry import VIEWS

    number = VIEWS.index("flatten") + 1  # its number key (0 for the tenth view)
    layout = s.goto(number, "Flatten")

    def shown(img: np.ndarray) -> bool:
        try:
            objects = subjects(img, parse(img))
        except LookupError:
            return False
        return len(objects) >= 3 and checkerboard(img, objects[0])

    s.until(shown, 60, "the checkerboard on the mesh, the layout and the copy beside it")
    layout = parse(s.settled((0, 0, *s.size)))
    s.subject_ok(layout, 3, "the mesh, its layout and the distortion copy")
    before = s.img
    flat = subjects(before, layout)[1]
    s.choose(1, 0, 2)  # map → lscm

    def remapped(img: np.ndarray) -> bool:
        box = (flat[0], 0, flat[1], s.size[1])
        return changed_fraction(before, img, box) > 0.02 and shown(img)

    s.until(remapped, 60, "a new layout after choosing LSCM, the checkerboard still on the mesh")
    s.subject_ok(parse(s.settled((0, 0, *s.size))), 3, "after LSCM")


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path) -> None:
    """The default map: the checkerboard on the mesh, the layout and the distortion copy."""
    settle_jobs(viewer)
