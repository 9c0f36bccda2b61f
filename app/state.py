"""Viewer state as plain objects, tested headless (no polyscope import here).

``MeshState`` holds the current mesh and keeps the last good one when a load fails (the error
is kept as text for the panel). ``CurvatureState`` computes and caches every curvature field for
the current area / boundary choice and the colour range each one should use.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from meshlap_core import primitives
from meshlap_core.curvature import curvature_fields
from meshlap_core.describe import mesh_info
from meshlap_core.errors import MeshError
from meshlap_core.io import load_mesh
from meshlap_core.types import FloatArray, IntArray
from meshlap_core.validate import validate_mesh

ASSETS_DIR = Path(__file__).resolve().parents[1] / "assets"
DEFAULT_ASSET = "bumpy.obj"

# field name -> (label shown to users, signed?)
FIELD_LABELS: dict[str, tuple[str, bool]] = {
    "uniform": ("mean curvature H (uniform Laplacian)", True),
    "cotan": ("mean curvature H (cotangent Laplace-Beltrami)", True),
    "gaussian": ("Gaussian curvature K (angle deficit)", True),
    "k1": ("principal curvature k1", True),
    "k2": ("principal curvature k2", True),
    "difference": ("H uniform - H cotangent", True),
}


SHARED_MESHES = Path(__file__).resolve().parents[1].parent / "shared" / "meshes"


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


def robust_range(values: FloatArray, signed: bool, percentile: float = 2.0) -> tuple[float, float]:
    """Colour-map range that one outlier cannot wash out.

    Parameters
    ----------
    values : (n,) float
    signed : bool
        Symmetric range ``[-r, r]`` around zero (diverging maps) when true.
    percentile : float
        Clip this percentage at each end (0 = full range).

    Returns
    -------
    lo, hi : float
        ``lo < hi`` always (a constant field gets a small symmetric range).
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return -1.0, 1.0
    p = float(np.clip(percentile, 0.0, 49.0))
    lo, hi = np.percentile(v, [p, 100.0 - p])
    if signed:
        r = max(abs(lo), abs(hi))
        r = r if r > 0 else 1.0
        return -float(r), float(r)
    if hi <= lo:
        return float(lo) - 0.5, float(lo) + 0.5
    return float(lo), float(hi)


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

    def load(self, path: str | Path | None) -> bool:
        """Load ``path`` (the bundled default when ``None``). Returns success."""
        try:
            if path is None:
                default = default_mesh_path()
                if default is not None:
                    mesh = load_mesh(default)
                    name = default.name
                else:  # installed without assets/: generate the same shape
                    mesh = validate_mesh(*primitives.bumpy_sphere(), source="bumpy (generated)")
                    name = "bumpy (generated)"
            else:
                mesh = load_mesh(path)
                name = Path(path).name
        except MeshError as exc:
            self.error = str(exc)
            return False
        except OSError as exc:
            self.error = f"{path}: {exc.strerror or exc}"
            return False
        self.V, self.F, self.name = mesh.V, mesh.F, name
        self.info = mesh_info(mesh.V, mesh.F, mesh.report, str(path) if path else name)
        self.error = ""
        self.version += 1
        return True


@dataclass
class CurvatureState:
    """Curvature fields of the current mesh for the chosen area and boundary rule."""

    area: str = "barycentric"
    boundary: str = "pi"
    field_name: str = "cotan"
    percentile: float = 2.0
    _key: tuple[Any, ...] = ()
    fields: dict[str, FloatArray] = field(default_factory=dict)
    _summaries: dict[tuple[Any, ...], dict[str, Any]] = field(default_factory=dict)

    def update(self, mesh: MeshState) -> bool:
        """Recompute when the mesh, area or boundary rule changed. Returns whether it did."""
        key = (mesh.version, self.area, self.boundary)
        if key == self._key:
            return False
        self.fields = curvature_fields(mesh.V, mesh.F, self.area, self.boundary)
        self._key = key
        return True

    def color_range(self, name: str | None = None) -> tuple[float, float]:
        """Robust colour range of a field (symmetric around 0 for signed fields)."""
        return self.summary(name)["range"]

    def summary(self, name: str | None = None, bins: int = 60) -> dict[str, Any]:
        """Range, min/max and histogram of a field, cached until the field or the clip
        percentage changes (the panel reads it every frame)."""
        name = name or self.field_name
        key = (self._key, name, self.percentile, bins)
        cached = self._summaries.get(key)
        if cached is None:
            values = self.fields[name]
            lo, hi = robust_range(values, FIELD_LABELS[name][1], self.percentile)
            counts, edges = np.histogram(np.clip(values, lo, hi), bins=bins, range=(lo, hi))
            cached = {
                "range": (lo, hi),
                "min": float(values.min()),
                "max": float(values.max()),
                "centers": 0.5 * (edges[1:] + edges[:-1]),
                "counts": counts.astype(np.float64),
                "width": float(edges[1] - edges[0]),
            }
            self._summaries = {k: v for k, v in self._summaries.items() if k[0] == self._key}
            self._summaries[key] = cached
        return cached


@dataclass
class OneRingState:
    """The clicked vertex and its ordered neighbourhood, ready to draw.

    ``select(mesh, curv, i)`` fills ``neighbors`` (ordered, counter-clockwise unless
    ``reverse``), ``boundary``, ``valence``, the vertex's ``H`` and ``K``, and the geometry of the
    drawing: ``polyline`` (neighbour positions in order, closed for interior vertices),
    ``edges`` (consecutive pairs), ``arrows`` (direction of travel at each neighbour) and
    ``order_t`` (position in the order, 0..1, for the colour map).
    """

    vertex: int = -1
    reverse: bool = False
    neighbors: list[int] = field(default_factory=list)
    boundary: bool = False
    ordered: bool = True
    H: float = float("nan")
    K: float = float("nan")
    normal: FloatArray = field(default_factory=lambda: np.zeros(3))
    _ring_key: int = -1
    _ring: Any = None
    _normals: Any = None
    polyline: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    edges: IntArray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    arrows: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    order_t: FloatArray = field(default_factory=lambda: np.zeros(0))

    @property
    def valence(self) -> int:
        return len(self.neighbors)

    def select(self, mesh: MeshState, curv: CurvatureState, vertex: int) -> bool:
        """Select ``vertex``; returns False (and keeps the old selection) when out of range."""
        if not 0 <= vertex < len(mesh.V):
            return False
        from meshlap_core.topology import one_ring  # local: keeps app.state import light

        if self._ring_key != mesh.version:
            from meshlap_core.curvature import vertex_normals

            self._ring = one_ring(mesh.F, len(mesh.V))
            self._normals = vertex_normals(mesh.V, mesh.F)
            self._ring_key = mesh.version
        self.normal = self._normals[vertex]
        ring = self._ring.reversed() if self.reverse else self._ring
        nb = ring[vertex]
        self.vertex = int(vertex)
        self.neighbors = [int(j) for j in nb]
        self.boundary = bool(ring.boundary[vertex])
        self.ordered = bool(ring.regular[vertex])
        curv.update(mesh)
        self.H = float(curv.fields["cotan"][vertex])
        self.K = float(curv.fields["gaussian"][vertex])
        k = len(nb)
        self.polyline = mesh.V[nb]
        closed = not self.boundary and k > 2
        nxt = np.arange(1, k + 1) % k if closed else np.minimum(np.arange(1, k + 1), k - 1)
        self.edges = np.stack([np.arange(k), nxt], axis=1)[: k if closed else max(k - 1, 0)]
        step = self.polyline[nxt] - self.polyline
        if not closed:
            step[-1] = 0.0  # an open fan ends at its last neighbour
        self.arrows = step
        self.order_t = np.linspace(0.0, 1.0, k) if k > 1 else np.zeros(k)
        return True

    def toggle_reverse(self, mesh: MeshState, curv: CurvatureState) -> None:
        self.reverse = not self.reverse
        if self.vertex >= 0:
            self.select(mesh, curv, self.vertex)
