"""Issue 23, the remaining items: the window fitted inside the screen and its title (pure
parts; the real window in ``tests/window/test_open.py`` and the tour), the mesh's up axis
(through the viewer on ``openGL_mock``), legends placed off the data."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from meshlap_app.state.app import AppState
from meshlap_app.state.display import UP_BY_MESH, Display, up_rotation
from meshlap_app.state.session import Session, from_dict, write_session
from meshlap_app.window import PRODUCT, fit_window, window_title

from meshlap_core.errors import MeshError
from meshlap_core.io import save_mesh
from meshlap_core.options import DEFAULT_UP, UP_AXES
from meshlap_core.primitives import icosphere


# ---------------------------------------------------------------- item 10: window placement
@pytest.mark.parametrize(
    ("area", "wanted", "frame", "expected"),
    [
        # polyscope's 1280×720 on a 1280×720 screen without a window manager: the whole screen
        ((0, 0, 1280, 720), (1280, 720), (0, 0, 0, 0), (0, 0, 1280, 720)),
        # on 1920×1080: kept, centred ((1920-1280)/2, (1080-720)/2)
        ((0, 0, 1920, 1080), (1280, 720), (0, 0, 0, 0), (320, 180, 1280, 720)),
        # a 30-pixel title bar and 2-pixel borders on 1280×720: the content shrinks so the
        # frame fits too (1276 = 1280-2-2, 688 = 720-30-2), its corner inside the frame
        ((0, 0, 1280, 720), (1280, 720), (2, 30, 2, 2), (2, 30, 1276, 688)),
        # a work area less a 40-pixel top panel, on a second monitor at x = 1920
        ((1920, 40, 1024, 728), (1280, 720), (0, 0, 0, 0), (1920, 44, 1024, 720)),
    ],
)
def test_the_window_and_its_frame_fit_inside_the_work_area(area, wanted, frame, expected):
    x, y, w, h = fit_window(area, wanted, frame)
    assert (x, y, w, h) == expected
    ax, ay, aw, ah = area
    left, top, right, bottom = frame
    assert ax <= x - left and x + w + right <= ax + aw
    assert ay <= y - top and y + h + bottom <= ay + ah


def test_a_window_smaller_than_the_screen_keeps_its_size_and_is_centred():
    for wanted in ((800, 600), (1, 1), (1919, 1079)):
        x, y, w, h = fit_window((0, 0, 1920, 1080), wanted)
        assert (w, h) == wanted
        assert abs(x - (1920 - x - w)) <= 1 and abs(y - (1080 - y - h)) <= 1


def test_the_title_names_the_mesh_only_when_it_can_follow_it():
    assert window_title("bumpy.obj", True) == f"{PRODUCT} — bumpy.obj"
    # set once at the window's creation, a mesh name would go on naming the first mesh
    assert window_title("bumpy.obj", False) == PRODUCT
    assert window_title(None, True) == PRODUCT


# ---------------------------------------------------------------- item 10: the mesh's up axis
NEFERTITI = Path(__file__).resolve().parents[3] / "shared" / "meshes" / "nefertiti.obj"


@pytest.mark.parametrize("up", UP_AXES)
def test_the_up_rotation_is_a_rotation_taking_the_axis_to_display_y(up):
    R = up_rotation(up)
    assert np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) == pytest.approx(1.0)
    e = np.zeros(3)
    e["xyz".index(up[-1])] = -1.0 if up.startswith("-") else 1.0
    assert np.allclose(R @ e, [0.0, 1.0, 0.0])


def test_z_up_by_hand_and_the_display_of_a_tall_box():
    # a quarter turn about x: (x, y, z) -> (x, z, -y)
    assert np.allclose(up_rotation("z") @ [1.0, 2.0, 3.0], [1.0, 3.0, -2.0])
    assert np.allclose(up_rotation("y"), np.eye(3))
    d = Display()
    box = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 5)], dtype=float)
    d.fit(box, "z")
    P = d.points(box)
    assert np.argmax(np.ptp(P, axis=0)) == 1  # the box's tall z side stands up on screen
    assert np.allclose(d.vectors(np.array([[0.0, 0.0, 1.0]])), [[0.0, d.scale, 0.0]])
    with pytest.raises(MeshError, match="unknown up axis 'w'"):
        d.fit(box, "w")


def test_the_up_rule_given_then_known_meshes_then_y():
    state = AppState()
    assert state.up_for("bumpy.obj") == DEFAULT_UP == "y"
    assert state.up_for("nefertiti.obj") == UP_BY_MESH["nefertiti.obj"] == "z"
    state.up_given["bumpy.obj"] = "-x"
    assert state.up_for("bumpy.obj") == "-x"


def test_view_up_is_refused_unknown_and_with_a_session(tmp_path, capsys):
    from meshlap_core.cli import main

    with pytest.raises(SystemExit) as exit_:
        main(["view", "--up", "w"])
    assert exit_.value.code == 2 and "invalid choice: 'w'" in capsys.readouterr().err
    write_session(tmp_path / "s.json", Session())
    assert main(["view", "--session", str(tmp_path / "s.json"), "--up", "z"]) == 2
    assert "--up cannot be combined with --session" in capsys.readouterr().err


def test_the_session_keeps_a_given_up_and_refuses_a_bad_one(tmp_path):
    s = Session(up="z")
    data = s.to_dict()
    assert data["up"] == "z" and from_dict(data).up == "z"
    assert "up" not in Session().to_dict()  # the rule's: not written (older readers)
    assert from_dict(Session().to_dict()).up is None
    with pytest.raises(MeshError, match='"up" must be one of'):
        from_dict({**data, "up": "w"})


ps = pytest.importorskip("polyscope")


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def eye_direction_in_mesh_axes(viewer) -> np.ndarray:
    """The unit direction from the mesh's centre to the camera, in the mesh's own axes."""
    d = viewer.state.display
    eye = np.asarray(ps.get_view_camera_parameters().get_position(), dtype=float)
    centre = d.points(viewer.state.mesh.V).mean(axis=0)
    v = d.rotation.T @ (eye - centre)
    return v / np.linalg.norm(v)


def test_a_z_up_mesh_is_seen_from_the_side_saved_and_restored(mock, viewer, tmp_path):
    from meshlap_app.session import capture

    tall = tmp_path / "tall.obj"
    V, F = icosphere(2)
    save_mesh(tall, V * [1.0, 1.0, 3.0], F)
    viewer.state.up_given["tall.obj"] = "z"
    assert viewer.open(tall)
    ps.frame_tick()
    assert viewer.state.display.up == "z"
    v = eye_direction_in_mesh_axes(viewer)
    assert abs(v[2]) < 0.3  # looked at from the side (y-up, the eye was on its z axis)
    P = viewer.state.display.points(viewer.state.mesh.V)
    assert np.argmax(np.ptp(P, axis=0)) == 1  # standing: its long z axis is up on screen
    assert capture(viewer).up == "z"
    viewer.state.up_given.clear()
    assert viewer.open(tall)
    assert viewer.state.display.up == "y" and capture(viewer).up is None


def test_nefertiti_stands_upright_facing_the_camera(mock, viewer):
    if not NEFERTITI.exists():
        pytest.skip(f"{NEFERTITI} is absent (the shared meshes)")
    assert viewer.open(NEFERTITI)
    ps.frame_tick()
    V = viewer.state.mesh.V
    z = V[:, 2]
    lo, hi = z.min(), z.max()
    # the bust is z-up: its crown leans back, so the face is on the side the crown leans from
    crown = V[z > hi - 0.2 * (hi - lo), 1].mean()
    base = V[z < lo + 0.2 * (hi - lo), 1].mean()
    face = np.array([0.0, -np.sign(crown - base), 0.0])
    v = eye_direction_in_mesh_axes(viewer)
    assert abs(v[2]) < 0.3, v  # not from below (the base) nor from above
    assert v @ face > 0.9, v  # in front of the face


# ---------------------------------------------------------------- item 7: the near plane
def clip_distances() -> tuple[float, float]:
    """The near and far planes' distances from the camera (polyscope's "Center Relative"
    mode: ``nearClip`` and ``farClip`` times the distance to the view centre)."""
    view = json.loads(ps.get_view_as_json())
    assert view["viewRelativeMode"] == "Center Relative"
    eye = np.asarray(ps.get_view_camera_parameters().get_position(), dtype=float)
    dist = float(np.linalg.norm(np.asarray(view["viewCenter"]) - eye))
    return view["nearClip"] * dist, view["farClip"] * dist


@pytest.mark.parametrize("size", [(1920, 1080), (1280, 720)])
def test_f_frames_the_ring_of_a_fine_mesh_inside_the_clip_planes(mock, viewer, tmp_path, size):
    fine = tmp_path / "fine.obj"
    V, F = icosphere(5)
    V2, F2 = icosphere(1)  # a second part 40 radii away: the ring is 1/5000 of the scene
    V, F = np.vstack([V, V2 + np.array([40.0, 0.0, 0.0])]), np.vstack([F, F2 + len(V)])
    save_mesh(fine, V, F)
    assert viewer.open(fine)
    ps.set_window_size(*size)
    ps.frame_tick()
    ps.look_at((0.0, 0.0, -30.0), (0.0, 0.0, 0.0))  # a view from far away first (zoomed out)
    viewer.set_panel("onering")
    viewer.ui.script("vertex", 5)
    ps.frame_tick()
    viewer.ui.script("key f", True)
    ps.frame_tick()
    ps.frame_tick()
    r = viewer.panels["onering"].state
    assert r.vertex == 5
    params = ps.get_view_camera_parameters()
    eye = np.asarray(params.get_position(), dtype=float)
    look = np.asarray(params.get_look_dir(), dtype=float)
    ring = viewer.state.display.points(np.vstack([r.polyline, V[[5]]]))
    depth = (ring - eye) @ look
    near, far = clip_distances()
    assert depth.min() > 2 * near, (depth.min(), near)  # the ring whole in front of the plane
    mesh = viewer.state.display.points(V)
    assert np.linalg.norm(mesh - eye, axis=1).max() < far  # the far side of the mesh drawn too


# ---------------------------------------------------------------- item 10: legends off the data
def data_in_box(items, box) -> list[str]:
    """The items with a drawn point inside ``box`` (x0, x1, y0, y1): lines sampled 200 times
    between their points, bars as rectangles from 0, infinite lines across."""
    x0, x1, y0, y1 = box
    hits = []
    for kind, x, y in items:
        if kind == "vlines":
            inside = np.any((np.asarray(x) >= x0) & (np.asarray(x) <= x1))
        elif kind == "hlines":
            inside = np.any((np.asarray(y) >= y0) & (np.asarray(y) <= y1))
        elif kind == "bars":
            cx, h = np.asarray(x, float), np.asarray(y, float)
            half = 0.5 * np.min(np.diff(np.sort(cx))) if len(cx) > 1 else 0.5
            inside = np.any((cx + half >= x0) & (cx - half <= x1) & (h > y0) & (h != 0))
        else:
            xs = np.linspace(np.min(x), np.max(x), 200 * len(x))
            order = np.argsort(x)
            ys = np.interp(xs, np.asarray(x, float)[order], np.asarray(y, float)[order])
            inside = np.any((xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1))
        if inside:
            hits.append(kind)
    return hits


def test_the_smoothing_curve_runs_through_the_old_north_west_legend():
    from meshlap_app.plot_legend import CORNERS, OUTSIDE, corner_box, data_limits, legend_corner

    mu = np.linspace(-1.5, 0.0, 200)
    g = 1.0 / (1.0 - 0.5 * mu)  # implicit, lambda 0.5: from 0.57 at mu = -1.5 up to 1
    items = [("line", mu, g), ("hlines", None, np.array([-1.0, 1.0]))]
    limits = (mu[0], mu[-1], -1.2, 1.2)
    size = (0.25, 0.3)
    assert data_in_box(items, corner_box("NorthWest", limits, size))  # ImPlot's default: covered
    # every corner of this plot holds the curve or a |g| = 1 line: the legend goes above it
    assert legend_corner(items, size, limits) == OUTSIDE
    assert all(data_in_box(items, corner_box(c, limits, size)) for c in CORNERS)
    assert data_limits(items)[2] < -1.0  # the autofit shows the hlines with a margin
    # a histogram's bell: the north-west corner is free above its left tail
    x = np.linspace(-2.0, 2.0, 40)
    bars = [("bars", x, 100.0 * np.exp(-(x**2)))]
    where = legend_corner(bars, size)
    assert where in CORNERS and not data_in_box(bars, corner_box(where, data_limits(bars), size))
    assert data_in_box(bars, corner_box("NorthEast", data_limits(bars), (0.6, 0.3)))


@pytest.mark.parametrize("panel", ["curvature", "smoothing", "spectral", "surfaces"])
def test_every_plot_legend_covers_none_of_its_data(mock, viewer, panel):
    from meshlap_app.plot_legend import OUTSIDE, corner_box, data_limits

    ps.set_window_size(1600, 2400)  # the whole panel on screen (ImPlot skips a clipped plot)
    viewer.set_ui_scale(1.0)
    viewer.set_panel(panel)
    for _ in range(4):
        ps.frame_tick()
    if panel == "spectral":
        viewer.ui.script("compute eigenbasis", True)
        for _ in range(6):
            ps.frame_tick()
    placer = viewer.ui.legends
    titles = [t for t in viewer.ui.legend_at if placer.items.get(t)]
    assert titles, f"no plot drawn in the {panel} panel"
    for title in titles:
        for _ in range(2):  # placed from the last frame's data: one more frame
            ps.frame_tick()
        where = viewer.ui.legend_at[title]
        if where == OUTSIDE or not placer.labels.get(title):  # above the plot, or no legend
            continue
        items = placer.items[title]
        if title in placer.log_y:  # corners are boxes on screen: log10 y
            items = [(k, x, None if y is None else np.log10(y)) for k, x, y in items]
        limits = data_limits(items)
        if title in placer.y_limits:
            limits = (limits[0], limits[1], *placer.y_limits[title])
        box = corner_box(where, limits, placer.sizes[title])
        assert not data_in_box(items, box), (title, where, data_in_box(items, box))


# ---------------------------------------------------------------- the tour's second mesh
def test_a_second_mesh_after_side_by_side_and_an_eigenbasis_shows_no_error(mock, viewer):
    """The tour's order (side by side on the torus, a vertex, its eigenbasis, then bumpy
    opened): the side-by-side copy of the torus (1152 vertices) took bumpy's field, an error
    ("'values' should be a length n_vertices array") shown on every panel."""
    from meshlap_app.scene import MESH_B

    assets = Path(__file__).resolve().parents[2] / "assets"
    assert viewer.open(assets / "torus.obj")
    ps.frame_tick()
    viewer.set_panel("curvature")
    viewer.ui.script("side by side", True)
    ps.frame_tick()
    assert ps.get_surface_mesh(MESH_B).n_vertices() == 1152
    viewer.set_panel("spectral")
    viewer.ui.script("compute eigenbasis", True)
    for _ in range(4):
        ps.frame_tick()
    assert viewer.open(assets / "bumpy.obj")
    for view in ("spectral", "curvature", "smoothing"):
        viewer.set_panel(view)
        for _ in range(3):
            ps.frame_tick()
        assert not viewer.state.errors, (view, viewer.state.errors)
    assert ps.get_surface_mesh(MESH_B).n_vertices() == len(viewer.state.mesh.V) == 2562
