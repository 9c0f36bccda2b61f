"""The Export panel: a screenshot, or the mesh with the shown field written to files."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import polyscope as ps
import polyscope.imgui as psim

from meshlap_core.errors import MeshError
from meshlap_core.io import save_mesh, save_scalars

from .base import NoStructures

if TYPE_CHECKING:
    from ..viewer import Viewer


class ExportPanel(NoStructures):
    """Screenshot and export buttons, and what the last export did."""

    def __init__(self) -> None:
        self.status = ""

    def draw(self, viewer: Viewer) -> None:
        if not psim.CollapsingHeader("Export"):
            return
        if psim.Button("screenshot"):
            ps.screenshot()
        psim.SameLine()
        if psim.Button("export mesh + field"):
            self.status = self.export(viewer, Path.cwd())
        if self.status:
            psim.TextUnformatted(self.status)

    @staticmethod
    def export(viewer: Viewer, folder: Path) -> str:
        """Write the current mesh (PLY with the shown field) and the field (CSV) into folder."""
        stem = Path(viewer.mesh.name).stem or "mesh"
        curv = viewer.curv
        field = curv.fields.get(curv.field_name)
        try:
            save_mesh(
                folder / f"{stem}_{curv.field_name}.ply",
                viewer.mesh.V,
                viewer.mesh.F,
                scalars=field,
            )
            if field is not None:
                save_scalars(folder / f"{stem}_{curv.field_name}.csv", field)
        except (MeshError, OSError) as exc:
            return f"export failed: {exc}"
        return f"wrote {stem}_{curv.field_name}.ply/.csv in {folder}"
