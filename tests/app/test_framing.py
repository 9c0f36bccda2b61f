"""Where the camera puts things: F frames the one-ring clear of the colour bars and the panel, and
inside the clip planes on a fine mesh seen from far; side by side, the primary mesh keeps the
left whichever front the mesh has."""

from __future__ import annotations

import json

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")


from meshlap_core.io import save_mesh  # noqa: E402
from meshlap_core.primitives import icosphere  # noqa: E402
from tests.support.widgets import drive, frames  # noqa: E402


@pytest.mark.parametrize("scale", [1.0, 1.5])
def test_f_frames_the_ring_clear_of_the_colour_bars_and_the_panel(viewer, scale):
    from meshlap_app import scene
    from meshlap_app.camera import project_to_screen

    ps.set_window_size(1280, 720)  # another module's test may have left another size
    viewer.set_ui_scale(scale)
    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)
    ps.look_at((5.0, 2.0, 3.0), (0.0, 0.0, 0.0))
    viewer.ui.script("key f", True)
    frames(viewer, 2)
    r = viewer.panels["onering"].state
    params = ps.get_view_camera_parameters()
    w, h = ps.get_window_size()
    pts = viewer.state.display.points(np.vstack([r.polyline, viewer.state.mesh.V[[r.vertex]]]))
    xy, front = project_to_screen(pts, params.get_view_mat(), params.get_fov_vertical_deg(), w, h)
    assert front.all()  # nothing behind the camera (or cut by the near plane)
    bars = scene.COLORBAR_PX * scale
    pane = w - ps.get_right_gui_pane_width() * scale
    assert (xy[:, 0] > bars).all() and (xy[:, 0] < pane).all(), (xy[:, 0], bars, pane)
    assert (xy[:, 1] > 0).all() and (xy[:, 1] < h).all()


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


def test_the_primary_keeps_the_left_side_whichever_front_the_mesh_has(viewer, tmp_path):
    from meshlap_app.camera import project_to_screen
    from meshlap_app.scene import FRONT_VIEWS, MESH, MESH_B

    from meshlap_core import primitives
    from meshlap_core.io import save_mesh

    V, F = primitives.icosphere(2)
    V = V * np.array([2.0, 1.0, 0.5])  # not symmetric: the copy's width is the screen's
    # the default front (eye at -z) and a mesh known to face +z (its eye on the other side)
    names = ["blob.obj", next(iter(FRONT_VIEWS))]
    for name in names:
        path = tmp_path / name
        save_mesh(path, V, F)
        assert viewer.open(path)
        viewer.set_panel("curvature")
        frames(viewer)
        if not viewer.state.curv.side_by_side:
            drive(viewer, "side by side", True)
        frames(viewer, 2)
        params = ps.get_view_camera_parameters()
        w, h = ps.get_window_size()
        centres = np.array(
            [viewer.structure_points(n).mean(axis=0) for n in (MESH, MESH_B)], dtype=float
        )
        xy, front = project_to_screen(
            centres, params.get_view_mat(), params.get_fov_vertical_deg(), w, h
        )
        assert front.all()
        assert xy[0, 0] < xy[1, 0], f"{name}: the copy is left of the mesh"
    drive(viewer, "side by side", False)
