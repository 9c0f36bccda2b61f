"""What the host draws and reads itself: the *view* combo, a click on the scene and a dropped
file (driven by the every-widget tour with the panels' drivers)."""

from __future__ import annotations

import polyscope as ps

from tests.support.widgets import drive, frames


def drive_view_combo_switches_every_panel(viewer):
    for panel in ("onering", "spectral", "smoothing", "surfaces", "curvature"):
        drive(viewer, "view", panel)
        assert viewer.state.panel == panel
    viewer.ui.script("view", "nonsense")
    ps.frame_tick()
    assert viewer.state.panel == "curvature" and "nonsense" in viewer.state.errors["view"]


def drive_click_and_drop(viewer, tmp_path, sphere):
    before = viewer.panels["onering"].state.vertex
    drive(viewer, "click", (10.0, 10.0), (-5.0, 1e9))  # nothing there: nothing happens
    assert viewer.panels["onering"].state.vertex == before
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    n = len(viewer.state.mesh.V)
    viewer.files_dropped([str(bad)])
    assert "bad.obj" in viewer.state.mesh.error and len(viewer.state.mesh.V) == n
    viewer.files_dropped([])
    viewer.files_dropped([str(tmp_path / "assets_missing.ply")])
    frames(viewer)
    viewer.files_dropped([str(sphere)])
    assert viewer.state.mesh.name == "sphere.obj" and not viewer.state.mesh.error
