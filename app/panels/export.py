"""The Export section: a screenshot, or what is on screen written to files in a chosen folder."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from meshlap_core.errors import MeshError
from meshlap_core.io import save_mesh, save_scalars

from ..host import Host
from ..panel_spec import PanelSpec
from ..scene import write_png
from .base import ExportItem, Panel, shown_field


class ExportPanel(Panel):
    """Export folder, screenshot and export buttons, and where the last export wrote.

    The folder is the app state's (``AppState.folder``): recordings and relative session
    files go there too.
    """

    def __init__(self, spec: PanelSpec, state: object = None) -> None:
        super().__init__(spec, state)
        self.folder_text = ""
        self.status = ""

    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title, default_open=False):
            return
        if not self.folder_text:
            self.folder_text = str(host.state.folder)
        entered, self.folder_text = ui.input_text(
            "folder",
            self.folder_text,
            "where screenshots and exports are written (press Enter to set)",
        )
        if entered:
            self.set_folder(host, self.folder_text)
        if ui.button(
            "screenshot",
            "save the 3D view as a PNG in the folder: what the window shows left of this "
            "panel, with its colour bars and captions",
        ):
            self.status = self.screenshot(host)
        ui.same_line()
        if ui.button("export what is shown", "write the shown mesh / field to the folder"):
            self.status = self.export(host, host.state.folder)
        if self.status:
            ui.text_whole_words(self.status)

    def set_folder(self, host: Host, text: str) -> None:
        """Use ``text`` as the export folder.

        Raises
        ------
        MeshError
            The folder does not exist (the previous folder stays).
        """
        try:
            self.folder_text = str(host.state.set_folder(text))
        except MeshError:
            self.folder_text = str(host.state.folder)
            raise

    def screenshot(self, host: Host) -> str:
        """Write the view as on screen (:meth:`~meshlap_app.host.Host.picture`) to
        ``<mesh>_<view>.png`` in the folder; returns where it wrote (or why not)."""
        path = host.state.folder / f"{host.state.mesh.stem}_{host.state.panel}.png"
        try:
            rgb = host.picture()
            write_png(path, rgb)
        except (MeshError, OSError) as exc:
            return f"screenshot failed: {exc}"
        return f"wrote {path} ({rgb.shape[1]}×{rgb.shape[0]})"

    @staticmethod
    def export(host: Host, folder: Path) -> str:
        """Write what the active view shows into ``folder``; returns where it wrote.

        The view's own files (:meth:`~.base.Panel.export_items`: each mesh it shows, with the
        field on it, as PLY and the field as CSV), or by default (:func:`default_items`) the
        mesh as the view shows it.
        """
        files = []
        active = host.active()
        try:
            items = active.export_items(host) or default_items(host, active)
            if not items:
                return f"nothing to export: the {active.title} view shows no mesh yet"
            for name, V, F, scalars in items:
                path = Path(folder) / name
                if V is None:
                    save_scalars(path, scalars)
                else:
                    save_mesh(path, V, F, scalars=scalars)
                files.append(name)
        except (MeshError, OSError) as exc:
            return f"export failed: {exc}"
        return f"wrote {', '.join(files)} in {Path(folder).resolve()}"


def default_items(host: Host, active: Any) -> list[ExportItem]:
    """The export of a view without its own: the mesh with the curvature field when the view
    shows it (``shows_curvature``), the plain mesh when it shows the mesh alone, else
    nothing."""
    mesh = host.state.mesh
    if active.shows_curvature:
        return field_items(host)
    if active.shows_mesh:
        return [(f"{mesh.stem}.ply", mesh.V, mesh.F, None)]
    return []


def field_items(host: Host) -> list[ExportItem]:
    """The mesh (PLY with the shown curvature field) and the field (CSV)."""
    mesh, curv = host.state.mesh, host.state.curv
    curv.update(mesh)
    field = curv.values(curv.field_name)
    return shown_field(f"{mesh.stem}_{curv.field_name}", mesh.V, mesh.F, field)
