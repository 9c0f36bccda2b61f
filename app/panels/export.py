"""The Export panel: a screenshot, or what is on screen written to files in a chosen folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from meshlap_core.errors import MeshError
from meshlap_core.io import save_mesh, save_scalars

from ..scene import save_screenshot
from .base import NoStructures

if TYPE_CHECKING:
    from ..viewer import Viewer


class ExportPanel(NoStructures):
    """Export folder, screenshot and export buttons, and where the last export wrote."""

    def __init__(self, folder: Path | None = None) -> None:
        self.folder = Path(folder) if folder is not None else Path.cwd()
        self.folder_text = str(self.folder)
        self.status = ""

    def draw(self, viewer: Viewer) -> None:
        ui = viewer.ui
        if not ui.header("Export", default_open=False):
            return
        entered, self.folder_text = ui.input_text(
            "folder",
            self.folder_text,
            "where screenshots and exports are written (press Enter to set)",
        )
        if entered:
            self.set_folder(self.folder_text)
        if ui.button("screenshot", "save the window as a PNG in the folder"):
            self.status = self.screenshot(viewer)
        ui.same_line()
        if ui.button("export what is shown", "write the shown mesh / field to the folder"):
            self.status = self.export(viewer, self.folder)
        if self.status:
            ui.text(self.status)

    def set_folder(self, text: str) -> None:
        """Use ``text`` as the export folder.

        Raises
        ------
        MeshError
            The folder does not exist (the previous folder stays).
        """
        folder = Path(text.strip()).expanduser()
        if not folder.is_dir():
            self.folder_text = str(self.folder)
            raise MeshError(f"{text!r} is not an existing folder", "export folder")
        self.folder = folder.resolve()
        self.folder_text = str(self.folder)

    def screenshot(self, viewer: Viewer) -> str:
        stem = Path(viewer.mesh.name).stem or "mesh"
        path = self.folder / f"{stem}_{viewer.panel}.png"
        try:
            save_screenshot(path)
        except (MeshError, OSError) as exc:
            return f"screenshot failed: {exc}"
        return f"wrote {path}"

    @staticmethod
    def export(viewer: Viewer, folder: Path) -> str:
        """Write what the current panel shows into ``folder``; returns where it wrote.

        curvature / one-ring: the mesh as PLY with the shown field, and the field as CSV;
        spectral: the k-reconstruction (PLY with the per-vertex error) and the shown
        eigenfunction (CSV); smoothing: the smoothed mesh as it is now (PLY); surfaces: the
        parametric surface's mesh (PLY with the exact Gaussian curvature).
        """
        files = []
        try:
            for name, V, F, scalars in _shown(viewer):
                path = Path(folder) / name
                if V is None:
                    save_scalars(path, scalars)
                else:
                    save_mesh(path, V, F, scalars=scalars)
                files.append(name)
        except (MeshError, OSError) as exc:
            return f"export failed: {exc}"
        return f"wrote {', '.join(files)} in {Path(folder).resolve()}"


def _shown(viewer: Viewer) -> list[tuple[str, np.ndarray | None, np.ndarray | None, np.ndarray]]:
    """(file name, V or None, F, scalars) for what the current panel shows."""
    stem = Path(viewer.mesh.name).stem or "mesh"
    mesh, curv = viewer.mesh, viewer.curv
    if viewer.panel == "spectral":
        st = viewer.panels["spectral"].state
        if st.basis is not None:
            f, _ = st.eigenfunction()
            return [
                (f"{stem}_k{st.k}.ply", st.reconstruction, mesh.F, st.vertex_error),
                (f"{stem}_mode{st.mode}.csv", None, None, f),
            ]
    if viewer.panel == "smoothing":
        st = viewer.panels["smoothing"].state
        if st.smoother is not None:
            name = f"{stem}_{st.method}_{st.laplacian}_it{st.smoother.iteration}.ply"
            return [(name, np.array(st.V), st.F, None)]
    if viewer.panel == "surfaces":
        s = viewer.surf
        if s.mesh is not None:
            return [(f"{s.name}_res{s.res}.ply", s.mesh.V, s.mesh.F, None)]
    curv.update(mesh)
    field = curv.fields.get(curv.field_name)
    return [
        (f"{stem}_{curv.field_name}.ply", mesh.V, mesh.F, field),
        (f"{stem}_{curv.field_name}.csv", None, None, field),
    ]
