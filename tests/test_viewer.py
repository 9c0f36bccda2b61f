"""The polyscope layer: frames on the openGL_mock backend, real pixels with EGL (subprocess)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")


@pytest.fixture(scope="module")
def mock_backend():
    ps.set_allow_headless_backends(True)
    ps.init("openGL_mock")
    yield ps
    ps.remove_all_structures()


def test_panels_run_frames_on_mock(mock_backend, tmp_path):
    from app.state import CurvatureState, MeshState
    from app.viewer import Viewer, push_mesh

    mesh, curv = MeshState(), CurvatureState()
    assert mesh.load(None)
    push_mesh(mesh, curv)
    viewer = Viewer(mesh, curv)
    ps.set_user_callback(viewer.callback)
    for _ in range(3):
        ps.frame_tick()
    sm = ps.get_surface_mesh("mesh")
    assert sm.n_vertices() == len(mesh.V)
    # a bad path typed into the panel keeps the mesh and shows the error
    viewer.path_text = str(tmp_path / "nope.obj")
    assert not mesh.load(Path(viewer.path_text)) and "nope.obj" in mesh.error
    ps.frame_tick()
    assert ps.get_surface_mesh("mesh").n_vertices() == len(mesh.V)
    ps.clear_user_callback()


def _egl_available() -> bool:
    code = "import polyscope as ps; ps.set_allow_headless_backends(True); ps.init('openGL3_egl')"
    try:
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=120)
    except subprocess.TimeoutExpired:
        return False
    return res.returncode == 0


@pytest.mark.egl
def test_screenshot_shows_a_colour_map(tmp_path):
    if not _egl_available():
        pytest.skip("polyscope's EGL backend cannot start on this machine (no EGL/Mesa)")
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
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    img = mpimg.imread(out)[..., :3]
    bg = img[0, 0]
    fg = img[np.abs(img - bg).sum(axis=2) > 0.05]
    assert len(fg) > 0.05 * img.shape[0] * img.shape[1]  # the mesh covers part of the frame
    # a diverging colour map: both reddish and bluish pixels on the mesh
    assert np.sum(fg[:, 0] > fg[:, 2] + 0.15) > 100 and np.sum(fg[:, 2] > fg[:, 0] + 0.15) > 100
