"""Triangle meshes of parametric surfaces: the ``(u, v)`` grid, welded seams, collapsed poles.

:func:`mesh_surface` returns a :class:`SurfaceMesh` (``V, F`` plus the parameters of every vertex);
:func:`meshlap_core.primitives.torus_mesh` is the same grid for the torus, without the surface
object.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import MeshError
from ..primitives import grid_faces
from ..topology import boundary_vertex_mask
from ..types import BoolArray, FloatArray, IntArray
from .catalogue import ParametricSurface, get_surface


@dataclass(frozen=True)
class SurfaceMesh:
    """A triangulated parametric surface.

    Attributes
    ----------
    V : (n,3) float
    F : (m,3) int
        Counter-clockwise in ``(u, v)``, so face normals agree with ``n = p_u × p_v``.
    uv : (n,2) float
        Parameters of every vertex (a pole vertex gets the pole's ``u`` (or ``v``) and the
        domain's start in the other parameter).
    pole : (n,) bool
        Vertices where an edge of the rectangle collapsed (singular parameterization).
    boundary : (n,) bool
        Vertices on a boundary edge of the mesh.
    surface : str
    res : (nu, nv)
        Number of cells along ``u`` and ``v``.
    """

    V: FloatArray
    F: IntArray
    uv: FloatArray
    pole: BoolArray
    boundary: BoolArray
    surface: str
    res: tuple[int, int]


MAX_MESH_BYTES = 2 * 1024**3
"""Largest estimated peak memory (2 GiB) of one mesh generation; larger ``res`` is refused before
anything is allocated (:func:`check_mesh_res`)."""
MESH_BYTES_PER_CELL = 512
"""Estimated peak bytes per grid cell of :func:`mesh_surface` (and of writing the mesh): measured
456–510 bytes (peak RSS) at 512² and 1024² cells on the helicoid and the sphere; the output alone
(``V, F, uv, pole, boundary``) is 90 bytes per cell, the edge table of the boundary mask most of
the rest."""
STUDY_BYTES_PER_CELL = 1536
"""Estimated peak bytes per cell of one level of
:func:`~meshlap_core.curvature.convergence.convergence_study` (the five discrete estimators):
measured 1170–1440 bytes at 256² and 512² cells."""
STUDY_KEPT_BYTES_PER_CELL = 128
"""Bytes per cell a finished study level keeps (mesh, exact values) until the table is built."""
MAX_CELLS = MAX_MESH_BYTES // MESH_BYTES_PER_CELL
"""Largest grid :func:`mesh_surface` builds: 4,194,304 cells (2048 x 2048), 8.4 M triangles."""


def _gib(n_bytes: float) -> str:
    return f"{n_bytes / 1024**3:.2f} GiB"


def estimate_mesh_bytes(nu: int, nv: int, bytes_per_cell: int = MESH_BYTES_PER_CELL) -> int:
    """Estimated peak memory in bytes of meshing ``nu × nv`` cells (``bytes_per_cell · nu · nv``,
    see :data:`MESH_BYTES_PER_CELL`). Pure arithmetic: nothing is allocated."""
    return int(bytes_per_cell) * int(nu) * int(nv)


def _parse_res(res: int | Sequence[int], name: str = "res") -> tuple[int, int]:
    try:
        if isinstance(res, int | np.integer):
            nu = nv = int(res)
        else:
            nu, nv = (int(x) for x in res)
    except (TypeError, ValueError):
        raise MeshError(f"expected an int or a pair (nu, nv), got {res!r}", name) from None
    if nu < 1 or nv < 1:
        raise MeshError(f"needs at least 1 cell in each direction, got {nu} x {nv}", name)
    return nu, nv


def check_mesh_res(
    surface: ParametricSurface | str,
    res: int | Sequence[int],
    name: str = "res",
    bytes_per_cell: int = MESH_BYTES_PER_CELL,
) -> tuple[int, int]:
    """Check a mesh resolution before anything is allocated and return ``(nu, nv)``.

    Parameters
    ----------
    surface : ParametricSurface or str
    res : int or (nu, nv)
        Cells per direction.
    name : str
        The argument named in errors.
    bytes_per_cell : int
        The memory model (:data:`MESH_BYTES_PER_CELL`, or :data:`STUDY_BYTES_PER_CELL` for a
        convergence level).

    Raises
    ------
    MeshError
        Naming ``name``: not one or two integers, fewer than 1 cell, an estimated peak memory
        ``bytes_per_cell · nu · nv`` above :data:`MAX_MESH_BYTES` (the message gives the
        estimate), or fewer than 3 cells around a closed direction.
    """
    surface = get_surface(surface)
    nu, nv = _parse_res(res, name)
    need = estimate_mesh_bytes(nu, nv, bytes_per_cell)
    if need > MAX_MESH_BYTES:
        most = MAX_MESH_BYTES // bytes_per_cell
        raise MeshError(
            f"{nu} x {nv} cells would need about {_gib(need)} of memory (estimated at "
            f"{bytes_per_cell} bytes per cell), more than the {_gib(MAX_MESH_BYTES)} limit: "
            f"use at most {most:,} cells (e.g. {math.isqrt(most)} x {math.isqrt(most)})",
            name,
        )
    for closed, cnt, nm in ((surface.closed_u, nu, "u"), (surface.closed_v, nv, "v")):
        if closed and cnt < 3:
            raise MeshError(
                f"the {surface.name} is closed in {nm}: needs at least 3 cells there", name
            )
    return nu, nv


def mesh_surface(surface: ParametricSurface | str, res: int | Sequence[int] = 32) -> SurfaceMesh:
    """Triangulate the parameter rectangle with ``res`` cells per direction (or ``(nu, nv)``).

    Each cell ``(i, j)`` of the regular grid becomes two triangles ``(a, b, c), (a, c, d)`` with
    ``a = (i, j), b = (i+1, j), c = (i+1, j+1), d = (i, j+1)`` (counter-clockwise in ``(u, v)``,
    the grid convention of :mod:`meshlap_core.primitives`). Closed directions wrap their indices
    (the seam is welded: no duplicate vertices); each pole edge collapses to one vertex and the
    triangles that would degenerate there are dropped, leaving a fan.

    Returns
    -------
    SurfaceMesh

    Raises
    ------
    MeshError
        On a bad ``res`` (see :func:`check_mesh_res`: checked before anything is allocated,
        including the memory estimate against :data:`MAX_MESH_BYTES`).

    Examples
    --------
    The parametric sphere meshed with 16 cells per direction: the poles collapse to one vertex
    each and the seam is welded, so the mesh is a closed surface (χ = 2):

    >>> from meshlap_core import EdgeTable, mesh_surface
    >>> sm = mesh_surface("sphere", 16)
    >>> sm.V.shape, sm.F.shape
    ((242, 3), (480, 3))
    >>> len(sm.V) - len(EdgeTable.from_faces(sm.F).edges) + len(sm.F)
    2
    """
    surface = get_surface(surface)
    nu, nv = check_mesh_res(surface, res)
    u0, u1, v0, v1 = surface.domain
    # closed directions: the last sample would repeat the first, the seam wraps instead
    us = np.linspace(u0, u1, nu + 1)[:nu] if surface.closed_u else np.linspace(u0, u1, nu + 1)
    vs = np.linspace(v0, v1, nv + 1)[:nv] if surface.closed_v else np.linspace(v0, v1, nv + 1)
    Nu, Nv = len(us), len(vs)
    idx = np.arange(Nu * Nv).reshape(Nu, Nv)
    # collapse each pole edge to one vertex (in this order, so a corner shared by two pole
    # edges, which p maps to one point, joins both)
    if "u0" in surface.poles:
        idx[0, :] = idx[0, 0]
    if "u1" in surface.poles:
        idx[-1, :] = idx[-1, 0]
    if "v0" in surface.poles:
        idx[:, 0] = idx[0, 0]
    if "v1" in surface.poles:
        idx[:, -1] = idx[0, -1]
    F = idx.ravel()[grid_faces(Nu, Nv, surface.closed_u, surface.closed_v)]
    if surface.poles:
        F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
        used, Fc = np.unique(F, return_inverse=True)
        F = Fc.reshape(-1, 3).astype(np.int64)
    else:  # no collapsed edge: no degenerate triangle, every grid node a vertex of some cell
        used = np.arange(Nu * Nv)
        F = F.astype(np.int64)
    U, W = np.meshgrid(us, vs, indexing="ij")
    uv = np.stack([U.ravel(), W.ravel()], axis=1)[used]
    V = surface(uv[:, 0], uv[:, 1])
    collapsed = np.bincount(idx.ravel(), minlength=Nu * Nv) > 1
    pole = collapsed[used]
    if surface.poles:
        boundary = boundary_vertex_mask(F, len(V))
    else:
        # a plain grid (every cell two proper triangles, closed sides wrap over >= 3 cells):
        # the boundary is the rectangle's open sides, no edge table needed
        side = np.zeros((Nu, Nv), dtype=bool)
        if not surface.closed_u:
            side[[0, -1], :] = True
        if not surface.closed_v:
            side[:, [0, -1]] = True
        boundary = side.ravel()[used]
    return SurfaceMesh(
        V=np.ascontiguousarray(V, dtype=np.float64),
        F=np.ascontiguousarray(F),
        uv=uv,
        pole=pole,
        boundary=boundary,
        surface=surface.name,
        res=(nu, nv),
    )
