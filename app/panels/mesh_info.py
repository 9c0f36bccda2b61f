"""The Mesh section (``mesh_info``): the mesh on screen, a path field, bundled / shared meshes."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from ..host import Host
from ..panel_spec import PanelSpec
from ..state.mesh import list_meshes
from ..state.preview import MeshPreview
from ..ui import UI
from .base import Panel


class MeshPanel(Panel):
    """Counts and topology of the current mesh; open a file by path or from the list."""

    def __init__(self, spec: PanelSpec, state: object = None) -> None:
        super().__init__(spec, state)
        self.path_text = ""
        self.recent: list[Path] = []  # the last meshes opened, newest first
        self._listed: tuple[float, list[tuple[str, Path]]] = (-1e9, [])
        # the version of the first mesh shown, kept apart from ``watch`` (which a preview's
        # failed or cancelled job forgets: app/opening.py, restore_mesh)
        self._first: int | None = None

    def on_new_mesh(self, host: Host) -> None:
        """A mesh opened after the first one goes to the top of the recent list."""
        version = host.state.mesh.version
        self.watch.changed("mesh", version)
        if self._first is None:
            self._first = version
        elif version != self._first and host.state.mesh.path is not None:
            self.remember(host.state.mesh.path)

    def open_path(self, host: Host, path: Path) -> None:
        """Open the mesh or the saved session (``.json``, as when dropped on the window) that
        the path field names; the field is emptied once it opened (a refused file raises
        :class:`MeshError` or sets the mesh's error, and the field keeps the text)."""
        if path.suffix.lower() == ".json":
            _load_session(host, path)
            self.path_text = ""
        elif host.open(path):
            self.path_text = ""

    def draw(self, host: Host) -> None:
        ui = host.ui
        if not ui.header(self.title):
            return
        mesh = host.state.mesh
        loading = host.loading()
        if loading is not None:  # not the mesh's figures beside another mesh's preview
            draw_loading(ui, mesh.name, *loading)
        else:
            draw_figures(ui, mesh.name, mesh.info)
        entered, self.path_text = ui.input_text(
            "path",
            self.path_text,
            "a mesh file (.obj .off .ply .stl) or a saved session (.json); Enter or Open loads it",
        )
        ui.same_line()
        if (ui.button("Open", "load the file named in the path field") or entered) and (
            self.path_text.strip()
        ):
            self.open_path(host, Path(self.path_text.strip()).expanduser())
        now = time.monotonic()
        if now - self._listed[0] > 2.0:  # the folders are listed at most every 2 s, not per frame
            self._listed = (now, list_meshes())
        choices = dict(self._listed[1])
        for p in self.recent:
            choices.setdefault(f"recent: {p.name}", p)
        picked = ui.choose(
            "bundled / shared",
            "choose a mesh",
            list(choices),
            "the bundled assets, ../shared/meshes and recently opened files",
        )
        if picked:
            host.open(choices[picked])
        host.draw_job(self.name)  # opening a file: progress and Cancel (the mesh stays)
        if mesh.error:
            ui.error(mesh.error)

    def remember(self, path: Path) -> None:
        """Put ``path`` first in the recent-files list (at most 8)."""
        path = Path(path).resolve()
        self.recent = [path, *(p for p in self.recent if p != path)][:8]


def draw_figures(ui: UI, name: str, info: dict[str, Any]) -> None:
    """The mesh's name, sizes and topology (and why a genus is undefined, the repairs)."""
    genus = info.get("genus")
    # the name and sizes on their own line: a long file name never splits "genus = 0"
    ui.text(f"{name}: {info.get('n_vertices', 0)} vertices, {info.get('n_faces', 0)} faces")
    ui.text(
        f"chi = {info.get('euler_characteristic')}, "
        + (f"genus = {genus}" if genus is not None else "genus undefined (see below)")
        + f", boundary loops {info.get('n_boundary_loops')}, components "
        f"{info.get('n_components')}, {'' if info.get('manifold') else 'non-'}manifold"
    )
    if genus is None:
        ui.note(genus_reason(info))
    for r in info.get("repairs", []):
        ui.text(f"repaired: {r}")


def draw_loading(ui: UI, shown: str, name: str, preview: MeshPreview | None) -> None:
    """While ``name`` is being opened: its name, and its sizes as parsed once its preview is
    on screen (until then the mesh ``shown`` stays, and says so)."""
    ui.text(f"{name}: loading...")
    if preview is None:
        ui.note(f"{shown} stays on screen until {name} is read")
    else:
        ui.note(
            f"{len(preview.V):,} vertices, {len(preview.F):,} faces as read: a preview, "
            "the checks and curvature fields are still running"
        )


def _load_session(host: Host, path: Path) -> None:
    from ..session import load

    load(host, path)


def genus_reason(info: dict[str, Any]) -> str:
    """Why a mesh has no genus: the core's note (``2c − χ − b`` negative: not a manifold; the
    boundary not a set of loops), the manifold flag and the number of components."""
    why = [str(info.get("genus_note") or "genus undefined")]
    if not info.get("manifold"):
        why.append(
            "the mesh is not a manifold (an edge with more than two faces, or a vertex "
            "whose faces do not form one fan)"
        )
    n = info.get("n_components") or 1
    if n > 1:
        why.append(f"{n} components: the genus is a property of one connected surface")
    return "; ".join(why)
