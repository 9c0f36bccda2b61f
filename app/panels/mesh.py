"""The Mesh panel: what the mesh is, a path field and the list of bundled / shared meshes."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import polyscope.imgui as psim

from ..scene import RED
from ..state.mesh import list_meshes
from .base import NoStructures

if TYPE_CHECKING:
    from ..viewer import Viewer


class MeshPanel(NoStructures):
    """Counts and topology of the current mesh; open a file by path or from the list."""

    def __init__(self) -> None:
        self.path_text = ""

    def draw(self, viewer: Viewer) -> None:
        if not psim.CollapsingHeader("Mesh", psim.ImGuiTreeNodeFlags_DefaultOpen):
            return
        mesh = viewer.mesh
        info = mesh.info
        psim.TextUnformatted(
            f"{mesh.name}: {info.get('n_vertices', 0)} vertices, "
            f"{info.get('n_faces', 0)} faces, chi = {info.get('euler_characteristic')}, "
            f"genus = {info.get('genus')}"
        )
        psim.TextUnformatted(
            f"boundary loops {info.get('n_boundary_loops')}, components "
            f"{info.get('n_components')}, manifold {'yes' if info.get('manifold') else 'no'}"
        )
        for r in info.get("repairs", []):
            psim.TextUnformatted(f"repaired: {r}")
        _, self.path_text = psim.InputText("path", self.path_text)
        psim.SameLine()
        if psim.Button("Open") and self.path_text:
            viewer.open(Path(self.path_text).expanduser())
        choices = list_meshes()
        if choices and psim.BeginCombo("bundled / shared", "choose a mesh"):
            for label, path in choices:
                if psim.Selectable(label)[0]:
                    viewer.open(path)
            psim.EndCombo()
        if mesh.error:
            psim.TextColored(RED, mesh.error)
