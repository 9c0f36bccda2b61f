"""Surfaces panel state: a parametric surface, its mesh, and the geometry at a chosen (u, v).

No polyscope import. Signs follow ``meshlap_core.surfaces`` (``e = p_uu · n`` with
``n = p_u × p_v``), which is the opposite of the mesh convention ``Δx = −2Hn`` for ``H``:
the panel says so next to the numbers.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from meshlap_core import surfaces
from meshlap_core.errors import MeshError
from meshlap_core.types import FloatArray

MAX_RES = 512  # cells per direction the viewer meshes (512² cells: 0.5 M triangles)


@dataclass
class SurfaceState:
    """The chosen surface, its mesh at ``res`` and everything at ``(u, v)``."""

    name: str = "helicoid"
    res: int = 48
    u: float = 0.0
    v: float = 0.0
    error: str = ""
    mesh: surfaces.SurfaceMesh | None = None
    point: surfaces.PointGeometry | None = None
    theta: FloatArray = field(default_factory=lambda: np.zeros(0))
    kn: FloatArray = field(default_factory=lambda: np.zeros(0))
    version: int = 0  # bumped when the mesh changes (re-register), not when (u, v) moves

    @property
    def names(self) -> list[str]:
        return list(surfaces.SURFACES)

    @property
    def domain(self) -> tuple[float, float, float, float]:
        return tuple(float(x) for x in surfaces.get_surface(self.name).domain)  # type: ignore[return-value]

    def set_surface(self, name: str, res: int | None = None) -> bool:
        """Switch surface (and resolution); (u, v) goes to the surface's default point."""
        try:
            surf = surfaces.get_surface(name)
            mesh = surfaces.mesh_surface(surf, res if res is not None else self.res)
        except MeshError as exc:
            self.error = str(exc)
            return False
        self.name, self.mesh = name, mesh
        self.res = res if res is not None else self.res
        self.version += 1
        u, v = surf.default_uv
        return self.set_uv(u, v)

    def set_resolution(self, res: int) -> None:
        """Re-mesh the surface with ``res`` cells per direction.

        Raises
        ------
        MeshError
            ``res`` too small or too large for this surface (the old mesh stays).
        """
        if res > MAX_RES:
            raise MeshError(f"at most {MAX_RES} in the viewer, got {res}", "resolution")
        if not self.set_surface(self.name, int(res)):
            message, self.error = self.error, ""
            raise MeshError(message)

    def set_uv(self, u: float, v: float) -> bool:
        """Move the point (clamped into the domain); singular points keep the old point.

        Raises
        ------
        MeshError
            ``u`` or ``v`` is not a finite number (the point stays).
        """
        if not (np.isfinite(u) and np.isfinite(v)):
            raise MeshError(f"must be finite numbers, got u = {u!r}, v = {v!r}", "(u, v)")
        u0, u1, v0, v1 = self.domain
        u = float(np.clip(u, u0, u1))
        v = float(np.clip(v, v0, v1))
        try:
            point = surfaces.point_geometry(self.name, u, v)
            theta, kn = surfaces.normal_curvature_curve(self.name, u, v, n=181)
        except MeshError as exc:
            self.error = str(exc)
            return False
        self.u, self.v, self.point, self.theta, self.kn = u, v, point, theta, kn
        self.error = ""
        return True

    def pick_vertex(self, i: int) -> bool:
        """Move the point to the parameters of mesh vertex ``i`` (a click on the surface)."""
        if self.mesh is None or not 0 <= i < len(self.mesh.uv):
            return False
        u, v = self.mesh.uv[i]
        return self.set_uv(float(u), float(v))

    def direction_vectors(self, scale: float = 0.25) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Base point ``(1,3)`` and the two principal directions ``(1,3)`` scaled for drawing."""
        p = self.point
        if p is None:
            raise MeshError("no point selected on the surface yet", "surface")
        return p.p[None, :], scale * p.dir1[None, :], scale * p.dir2[None, :]
