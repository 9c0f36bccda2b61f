"""The mesh on screen (``MeshState``) and the meshes offered in the viewer's list."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from meshlap_core import primitives
from meshlap_core.describe import mesh_info
from meshlap_core.errors import MeshError
from meshlap_core.io import load_mesh
from meshlap_core.types import FloatArray, IntArray
from meshlap_core.validate import validate_mesh

if TYPE_CHECKING:
    from .preview import MeshPreview

ROOT = Path(__file__).resolve().parents[2]  # the checkout (app/ sits beside assets/)
ASSETS_DIR = ROOT / "assets"
DEFAULT_ASSET = "bumpy.obj"

SHARED_MESHES = ROOT.parent / "shared" / "meshes"


def list_meshes() -> list[tuple[str, Path]]:
    """Bundled assets and, when present, the meshes of ``../shared/meshes`` (label, path)."""
    out = [(f"assets/{p.name}", p) for p in sorted(ASSETS_DIR.glob("*.obj"))]
    if SHARED_MESHES.is_dir():
        out += [(f"shared/{p.name}", p) for p in sorted(SHARED_MESHES.glob("*.obj"))]
    return out


def default_mesh_path() -> Path | None:
    """The bundled default mesh, or ``None`` when ``assets/`` is not beside the package."""
    path = ASSETS_DIR / DEFAULT_ASSET
    return path if path.is_file() else None


@dataclass
class MeshState:
    """The mesh on screen. ``load`` never raises: on failure ``error`` is set and the previous
    mesh stays.
    """

    V: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    F: IntArray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))
    name: str = ""
    info: dict[str, Any] = field(default_factory=dict)
    error: str = ""
    version: int = 0  # bumped on every successful load, so panels know to recompute
    path: Path | None = None  # the file loaded (resolved); None for the generated default

    def show(self, other: MeshState) -> None:
        """Take the mesh ``other`` loaded (a session's, read before anything changed): its
        arrays, name, info and path; the version moves on, so everything derived is redone."""
        if other is self:
            return
        self.V, self.F, self.name, self.info, self.path = (
            other.V,
            other.F,
            other.name,
            other.info,
            other.path,
        )
        self.error = ""
        self.version += 1

    @property
    def stem(self) -> str:
        """The mesh's name without its extension (for output file names)."""
        return Path(self.name).stem or "mesh"

    def load(self, path: str | Path | None) -> bool:
        """Load ``path`` (the bundled default when ``None``). Returns success."""
        try:
            loaded = read_mesh(path)
        except MeshError as exc:
            self.error = str(exc)
            return False
        except OSError as exc:
            self.error = f"{path}: {exc.strerror or exc}"
            return False
        self.adopt(loaded)
        return True

    def adopt(self, loaded: LoadedMesh) -> None:
        """Show ``loaded`` (read by :func:`read_mesh`, maybe in a job): the new current mesh."""
        self.V, self.F, self.name = loaded.mesh.V, loaded.mesh.F, loaded.name
        self.path = loaded.path
        self.info = loaded.info
        self.error = ""
        self.version += 1


@dataclass
class LoadedMesh:
    """A mesh read and validated off the UI thread, with what the Mesh section shows."""

    mesh: Any
    name: str
    path: Path | None
    info: dict[str, Any]
    previewed: bool = False  # a preview was handed over with exactly this geometry
    shared: bool = True  # mesh.V and mesh.F are here (False: sent without them, see below)

    def without_geometry(self) -> LoadedMesh:
        """Itself with ``mesh.V`` and ``mesh.F`` dropped when they are the preview's (what a
        child process sends back: the window already holds them, :meth:`with_geometry`)."""
        if self.previewed:
            self.mesh.V = self.mesh.F = None
            self.shared = False
        return self

    def with_geometry(self, preview: Any) -> LoadedMesh:
        """Itself with the geometry of ``preview`` (the :class:`~.preview.MeshPreview` it
        was sent without) put back.

        Raises
        ------
        MeshError
            The geometry was dropped and no preview is given.
        """
        if not self.shared:
            if preview is None:
                raise MeshError("the preview of the geometry was lost", self.name)
            self.mesh.V, self.mesh.F, self.shared = preview.V, preview.F, True
        return self


def read_mesh(path: str | Path | None, progress: Any = None) -> LoadedMesh:
    """Read, validate and describe ``path`` (the bundled default when ``None``).

    ``progress`` is a job's reporter (:class:`meshlap_app.jobs.Reporter`): passed on to
    ``load_mesh`` as ``progress=`` / ``cancel=`` when the core takes them, and told each phase;
    a reporter with ``partial`` (a job's) is handed a :class:`~.preview.MeshPreview` as soon as
    the file is parsed (before the validation), for the window to show at once.

    Raises
    ------
    MeshError, OSError
        The file is refused or unreadable.
    """
    from ..jobs import accepts, call_hooked
    from . import preview
    from .preview import make_preview

    def phase(message: str) -> None:
        if progress is not None:
            progress.phase_only(message)

    if path is None:
        default = default_mesh_path()
        if default is None:  # installed without assets/: generate the same shape
            mesh = validate_mesh(*primitives.bumpy_sphere(), source="bumpy (generated)")
            name = "bumpy (generated)"
            return LoadedMesh(mesh, name, None, mesh_info(mesh.V, mesh.F, mesh.report, name))
        path, label = default, None
        name = default.name
    else:
        label = str(path)
        name = Path(path).name
    phase(f"reading {name}")
    if progress is not None:
        extra: dict[str, Any] = {}
        partial = getattr(progress, "partial", None)
        sent: list[MeshPreview] = []
        if partial is not None and accepts(load_mesh, "on_parsed"):

            def show_parsed(V: FloatArray, F: IntArray) -> None:
                if len(F) < preview.PREVIEW_FACES:
                    return
                phase("a preview of the geometry read")
                sent.append(make_preview(name, V, F))
                partial(sent[-1])

            extra["on_parsed"] = show_parsed
        mesh = call_hooked(load_mesh, path, reporter=progress, **extra)
    else:
        mesh, sent = load_mesh(path), []
    phase("describing the mesh")
    info = mesh_info(mesh.V, mesh.F, mesh.report, label or name, table=mesh.edge_table)
    previewed = bool(sent) and sent[-1].same_geometry(mesh.V, mesh.F)
    if previewed:  # one copy of the arrays, the preview's (as the window holds them)
        mesh.V, mesh.F = sent[-1].V, sent[-1].F
    return LoadedMesh(mesh, name, Path(path).resolve(), info, previewed)


def read_mesh_with_fields(
    path: str | Path | None, area: str, boundary: str, progress: Any = None
) -> tuple[LoadedMesh, dict[str, FloatArray]]:
    """:func:`read_mesh`, then every curvature field for ``area`` and ``boundary``: the job of
    opening a file in the window (run in a child process, see
    :func:`meshlap_app.jobs.in_child`)."""
    from meshlap_core.curvature import all_curvature_fields

    loaded = read_mesh(path, progress)
    if progress is not None:
        progress(None, f"curvature fields of {len(loaded.mesh.V):,} vertices")
    m = loaded.mesh
    fields = all_curvature_fields(m.V, m.F, area, boundary, table=m.edge_table)
    # the viewer asks nothing more of the edge table: not sent back from the child process
    # (about 140 MB of the 240 MB at 692k vertices) nor kept in the window's memory
    m.edge_table = None
    if getattr(progress, "remote", False):  # a child process: the window has the preview's
        loaded.without_geometry()
    return loaded, fields
