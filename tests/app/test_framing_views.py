"""Framing views whose structures arrive later (issue 33, item 6), headless (``openGL_mock``,
jobs in threads as in the window's way):

- the Curvature lab opened with the camera inside its torus: the view was framed when the
  torus was not computed yet (polyscope's home view); now a view that shows nothing yet is
  framed when its structures appear;
- after a mesh opened in another view, the Smoothing view stayed empty: polyscope remembers a
  structure's enabled flag by name, and the copies removed while hidden came back hidden;
  now every copy is registered shown or hidden as its view is.

``tests/window/test_framing.py`` checks both in the real window.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.camera import project_to_screen  # noqa: E402
from meshlap_app.panels.curvature_lab import LAB  # noqa: E402
from meshlap_app.scene import SMOOTH_INPUT, SMOOTHED  # noqa: E402

from meshlap_core import primitives  # noqa: E402
from meshlap_core.io import save_mesh  # noqa: E402


def settle(viewer, timeout: float = 120.0) -> None:
    """Frames until no job runs, then a few more (results applied, copies registered)."""
    end = time.monotonic() + timeout
    ps.frame_tick()
    while viewer.state.jobs.busy:
        assert time.monotonic() < end, "a job did not finish"
        ps.frame_tick()
        time.sleep(0.005)
    for _ in range(4):
        ps.frame_tick()


def eye() -> np.ndarray:
    """The camera's position (world coordinates)."""
    M = np.asarray(ps.get_camera_view_matrix())
    return -M[:3, :3].T @ M[:3, 3]


def on_screen(viewer, name: str) -> bool:
    """The structure is shown, in front of the camera, its box inside the window left of
    meshlap's panel."""
    if not ps.has_surface_mesh(name) or not ps.get_surface_mesh(name).is_enabled():
        return False
    box = viewer.structure_box(name)
    corners = np.array([[x, y, z] for x in box[:, 0] for y in box[:, 1] for z in box[:, 2]])
    params = ps.get_view_camera_parameters()
    w, h = ps.get_window_size()
    xy, front = project_to_screen(
        corners, params.get_view_mat(), params.get_fov_vertical_deg(), w, h
    )
    pane = ps.get_right_gui_pane_width() * viewer.state.ui_scale
    return bool(front.all() and xy[:, 0].min() >= 0 and xy[:, 0].max() <= w - pane + 1)


@pytest.fixture
def windowed(viewer):
    """The viewer with background jobs (threads), as in the window."""
    viewer.background = True
    ps.set_window_size(1280, 720)
    yield viewer
    viewer.state.jobs.cancel_all()


def test_the_lab_is_framed_once_its_surface_is_computed(windowed):
    v = windowed
    ps.look_at((0.0, 0.0, -0.8), (0.0, 0.0, 0.0))  # the camera near the sphere, as framed
    for _ in range(2):  # the first visit computes the torus; the second finds it
        v.set_panel("curvature_lab")
        settle(v)
        r = v.panels["curvature_lab"].state.result
        shown = v.panels["curvature_lab"]._shown(r)[0]  # as uploaded (float32-safe scale)
        lo, hi = shown.min(axis=0), shown.max(axis=0)
        e = eye()
        assert not np.all((e > lo) & (e < hi)), f"camera at {e} inside the lab's box"
        assert on_screen(v, LAB)
        v.set_panel("curvature")
        settle(v)


def test_a_view_with_nothing_to_show_keeps_the_camera_and_frames_later(windowed):
    v = windowed
    settle(v)
    before = np.asarray(ps.get_camera_view_matrix()).copy()
    ps.get_surface_mesh("mesh").set_enabled(False)  # nothing shown (a job computes it)
    v.request_frame()
    ps.frame_tick()
    assert np.allclose(np.asarray(ps.get_camera_view_matrix()), before)
    assert v.reframe  # still to do
    ps.get_surface_mesh("mesh").set_enabled(True)
    ps.look_at((5.0, 5.0, 5.0), (0.0, 0.0, 0.0))  # elsewhere meanwhile
    ps.frame_tick()
    assert not v.reframe and on_screen(v, "mesh")


def test_smoothing_copies_come_back_shown_after_a_mesh_opened_in_another_view(windowed, tmp_path):
    v = windowed
    v.set_panel("smoothing")
    settle(v)
    assert on_screen(v, SMOOTHED) and on_screen(v, SMOOTH_INPUT)
    for number, view in enumerate(("curvature", "spectral")):
        v.set_panel(view)  # the copies hidden, then removed with the mesh they showed
        settle(v)
        path = tmp_path / f"other{number}.obj"
        save_mesh(path, *primitives.icosphere(2 + number))
        v.open(path)
        settle(v)
        v.set_panel("smoothing")  # a new stepper is built for the new mesh
        settle(v)
        assert on_screen(v, SMOOTHED), f"the smoothed copy is not shown (after {view})"
        assert on_screen(v, SMOOTH_INPUT), f"the input copy is not shown (after {view})"
