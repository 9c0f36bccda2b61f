"""The Export section's widgets: the folder, *export what is shown* and the screenshot."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from meshlap_core.io import load_mesh
from tests.support.widgets import drive, frames


def drive_export_writes_what_is_on_screen(viewer, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    drive(viewer, "folder", str(tmp_path / "does-not-exist"))
    assert "export folder" in viewer.state.errors["export"]
    drive(viewer, "folder", str(out))
    assert viewer.state.folder == out.resolve()
    # smoothing: the smoothed mesh as it is now, not the original vertices
    viewer.set_panel("smoothing")
    frames(viewer)
    drive(viewer, "step", True, True)
    drive(viewer, "export what is shown", True)
    status = viewer.panels["export"].status
    assert str(out.resolve()) in status
    st = viewer.panels["smoothing"].state
    name = f"sphere_{st.method}_{st.laplacian}_it{st.smoother.iteration}.ply"
    assert status == f"wrote {name}, sphere_input.ply in {out.resolve()}"
    back = load_mesh(out / name)
    np.testing.assert_allclose(back.V, st.V, atol=1e-6)
    assert not np.allclose(back.V, viewer.state.mesh.V, atol=1e-6)
    drive(viewer, "screenshot", True)
    assert (out / "sphere_smoothing.png").is_file()


def drive_panel_export(viewer, tmp_path: Path) -> None:
    drive_export_writes_what_is_on_screen(viewer, tmp_path)
