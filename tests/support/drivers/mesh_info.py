"""The Mesh section's widgets: the list of meshes, the path field and bad files."""

from __future__ import annotations

from pathlib import Path

import polyscope as ps

from tests.support.widgets import drive, sphere_file


def drive_mesh_panel_list_path_and_bad_files(viewer, tmp_path, sphere):
    drive(viewer, "bundled / shared", "assets/bumpy.obj")
    assert viewer.state.mesh.name == "bumpy.obj"
    assert ps.get_surface_mesh("mesh").n_vertices() == len(viewer.state.mesh.V)
    n = len(viewer.state.mesh.V)
    bad = tmp_path / "broken.off"
    bad.write_text("OFF\n10 5 0\n0 0 0\n")
    for text in ("", str(tmp_path / "missing.obj"), str(bad), str(tmp_path)):
        viewer.panels["mesh_info"].path_text = text
        drive(viewer, "Open", True)
        assert len(viewer.state.mesh.V) == n  # the last good mesh stays
    assert viewer.state.mesh.error  # said in the Mesh panel
    drive(viewer, "path", str(sphere))  # Enter in the path field opens it
    assert viewer.state.mesh.name == "sphere.obj" and not viewer.state.mesh.error
    # the recent-files entry appears in the list and opens the file again
    drive(viewer, "bundled / shared", "assets/bumpy.obj", "recent: sphere.obj")
    assert viewer.state.mesh.name == "sphere.obj"
    viewer.ui.script("bundled / shared", "no such mesh")
    ps.frame_tick()
    assert "not in the list" in viewer.state.errors["mesh_info"]


def drive_panel_mesh_info(viewer, tmp_path: Path) -> None:
    """The mesh section: the list, the path field and bad files."""
    drive_mesh_panel_list_path_and_bad_files(viewer, tmp_path, sphere_file(tmp_path))
