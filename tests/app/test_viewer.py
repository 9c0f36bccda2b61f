"""The polyscope layer: frames on the openGL_mock backend, real pixels with EGL (subprocess)."""

import os
import subprocess
import sys

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")


@pytest.fixture(scope="module")
def mock_backend(polyscope_mock):
    return polyscope_mock


def test_every_panel_runs_frames_on_mock(mock_backend, tmp_path):
    from meshlap_app.registry import VIEWS as PANELS
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    mesh = MeshState()
    assert mesh.load(None)
    viewer = Viewer(AppState(mesh=mesh))
    viewer.sync_mesh()
    ps.set_user_callback(viewer.callback)
    for panel in PANELS:
        viewer.state.panel = panel
        viewer.refresh()
        for _ in range(3):
            ps.frame_tick()
    assert ps.get_surface_mesh("mesh").n_vertices() == len(mesh.V)
    # the one-ring panel draws the ring of a selected vertex, numbered in order
    viewer.state.panel = "onering"
    assert viewer.panels["onering"].select(viewer, 7)
    ps.frame_tick()
    assert ps.has_curve_network("one-ring order")
    assert (
        viewer.panels["onering"].state.valence == len(viewer.panels["onering"].state.neighbors) > 2
    )
    # side-by-side curvature registers a second copy of the mesh
    viewer.state.panel = "curvature"
    viewer.state.curv.side_by_side = True
    viewer.panels["curvature"].sync(viewer)
    ps.frame_tick()
    assert ps.has_surface_mesh("mesh (second estimator)")
    # the surfaces panel moves its point with (u, v)
    viewer.state.panel = "surfaces"
    viewer.refresh()
    assert viewer.panels["surfaces"].state.set_uv(0.5, 1.0)
    viewer.panels["surfaces"].push_point(viewer)
    ps.frame_tick()
    assert ps.has_point_cloud("surface point")
    ps.clear_user_callback()


def test_bad_file_in_mesh_panel_keeps_mesh(mock_backend, tmp_path):
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    mesh = MeshState()
    assert mesh.load(None)
    viewer = Viewer(AppState(mesh=mesh))
    viewer.sync_mesh()
    n = ps.get_surface_mesh("mesh").n_vertices()
    bad = tmp_path / "broken.off"
    bad.write_text("OFF\n10 5 0\n0 0 0\n")
    assert not viewer.open(bad)
    assert "broken.off" in mesh.error
    ps.set_user_callback(viewer.callback)
    ps.frame_tick()  # the panel shows the error; nothing crashes
    assert ps.get_surface_mesh("mesh").n_vertices() == n
    ps.clear_user_callback()


def test_export_writes_mesh_and_field(mock_backend, tmp_path):
    from meshlap_app.state import AppState, CurvatureState, MeshState
    from meshlap_app.viewer import Viewer

    from meshlap_core.io import load_mesh

    mesh = MeshState()
    assert mesh.load(None)
    viewer = Viewer(AppState(mesh=mesh, curv=CurvatureState(field_name="gaussian")))
    viewer.sync_mesh()
    msg = viewer.panels["export"].export(viewer, tmp_path)
    assert "wrote" in msg
    back = load_mesh(tmp_path / "bumpy_gaussian.ply")
    assert back.n_vertices == len(mesh.V)
    values = np.loadtxt(tmp_path / "bumpy_gaussian.csv", skiprows=1)
    np.testing.assert_allclose(values, viewer.state.curv.fields["gaussian"], rtol=1e-9)


@pytest.mark.egl
def test_screenshot_shows_a_colour_map(tmp_path):
    import matplotlib.image as mpimg

    out = tmp_path / "shot.png"
    cmd = [
        sys.executable,
        "-m",
        "meshlap_core.cli",
        "view",
        "--screenshot",
        str(out),
        "--field",
        "cotan",
    ]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    img = mpimg.imread(out)[..., :3]
    bg = img[0, 0]
    fg = img[np.abs(img - bg).sum(axis=2) > 0.05]
    assert len(fg) > 0.05 * img.shape[0] * img.shape[1]  # the mesh covers part of the frame
    # a diverging colour map: both reddish and bluish pixels on the mesh
    assert np.sum(fg[:, 0] > fg[:, 2] + 0.15) > 100 and np.sum(fg[:, 2] > fg[:, 0] + 0.15) > 100


def _scene_fraction(png) -> float:
    """Fraction of the left 55 % of the picture (the 3D view; the panel is on the right) that
    differs from the background."""
    import matplotlib.image as mpimg

    img = mpimg.imread(png)[..., :3]
    left = img[:, : int(0.55 * img.shape[1])]
    return float(np.mean(np.abs(left - img[0, 0]).sum(axis=2) > 0.05))


@pytest.mark.egl
@pytest.mark.parametrize("scale", [1e74, 1e-55])
def test_screenshot_of_extreme_but_accepted_coordinates_is_not_blank(tmp_path, scale, python_ok):
    """float32 holds at most 3.4e38: the viewer centres and scales before every upload."""
    from meshlap_core import primitives
    from meshlap_core.io import save_mesh

    V, F = primitives.bumpy_sphere(3)
    mesh = tmp_path / "extreme.ply"
    save_mesh(mesh, V * scale + 3 * scale, F)
    for panel in ("curvature", "smoothing"):
        out = tmp_path / f"{panel}.png"
        cli = ("-m", "meshlap_core.cli", "view", mesh, "--panel", panel)
        python_ok(*cli, "--screenshot", out, timeout=300)
        assert _scene_fraction(out) > 0.05  # the mesh is drawn (before the fix: 0.0)


PICK_SCRIPT = """
import json, sys
import numpy as np
import polyscope as ps
from meshlap_app.camera import project_to_screen
from meshlap_app.state import AppState, CurvatureState, MeshState
from meshlap_app.viewer import Viewer, init_polyscope

mesh = MeshState(); mesh.load(None)
init_polyscope("openGL3_egl")
viewer = Viewer(AppState(mesh=mesh, panel="onering"))
viewer.sync_mesh()
ps.set_user_callback(viewer.callback)
ps.reset_camera_to_home_view()
ps.frame_tick()
target = int(sys.argv[1])
params = ps.get_view_camera_parameters()
w, h = ps.get_window_size()
xy, front = project_to_screen(viewer.state.display.points(mesh.V[[target]]), params.get_view_mat(),
                              params.get_fov_vertical_deg(), w, h)
hit = viewer.pick_at((float(xy[0, 0]), float(xy[0, 1])))
picked = viewer.panels["onering"].state.vertex
print(json.dumps({"hit": hit, "vertex": picked, "front": bool(front[0]),
                  "dist": float(np.linalg.norm(mesh.V[picked] - mesh.V[target]))}))
"""


@pytest.mark.egl
def test_picking_a_projected_vertex_selects_its_one_ring(tmp_path, python_ok):
    import json

    from meshlap_app.state import MeshState

    from meshlap_core.curvature import vertex_normals

    mesh = MeshState()
    mesh.load(None)
    # a vertex near the middle, facing the default camera (which looks along +z from -z)
    N = vertex_normals(mesh.V, mesh.F)
    target = int(np.argmin(N[:, 2] + 0.2 * np.abs(mesh.V[:, 1]) + 0.2 * np.abs(mesh.V[:, 0])))
    res = python_ok("-c", PICK_SCRIPT, target, timeout=300)
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["front"] and out["hit"]
    assert out["vertex"] == target


def test_no_display_is_one_clear_error(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    res = subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", "view"],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
        env=env,
    )
    if sys.platform.startswith("linux"):
        assert res.returncode == 2
        lines = [ln for ln in res.stderr.splitlines() if not ln.startswith("[polyscope]")]
        assert lines == [lines[0]] and lines[0].startswith("meshlap: error: view: no display")
        assert "--screenshot" in lines[0]


def test_cli_uses_the_viewers_single_definition_of_panels_and_fields():
    """`meshlap view` takes its choices from the registry and the field names from the
    setting that declares ``--field`` (pure data, no polyscope)."""
    from meshlap_app import registry
    from meshlap_app.commands import view

    from meshlap_core import options

    assert view.VIEWS is registry.VIEWS
    flags = {f.name: s for spec in registry.REGISTRY for s, f in spec.flags("view")}
    assert flags["--field"].choices is options.CURVATURE_FIELDS
