"""Triangle meshes of parametric surfaces: the ``(u, v)`` grid, welded seams, collapsed poles.

:func:`mesh_surface` returns a :class:`SurfaceMesh` (``V, F`` plus the parameters of every vertex);
:func:`meshlap_core.primitives.torus` is the same grid for the torus, without the surface object.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import MeshError
from ..primitives import _grid_faces
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


# largest grid :func:`mesh_surface` builds (2^24 cells: 33.5 M triangles, about 1.3 GB of arrays)
MAX_CELLS = 2**24


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
    if nu * nv > MAX_CELLS:
        raise MeshError(
            f"{nu} x {nv} cells is more than the {MAX_CELLS:,} meshlap meshes a surface with "
            f"(about {2 * MAX_CELLS:,} triangles)",
            name,
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
        On a bad ``res``, or fewer than 3 cells around a closed direction.
    """
    surface = get_surface(surface)
    nu, nv = _parse_res(res)
    for closed, cnt, nm in ((surface.closed_u, nu, "u"), (surface.closed_v, nv, "v")):
        if closed and cnt < 3:
            raise MeshError(
                f"the {surface.name} is closed in {nm}: needs at least 3 cells there", "res"
            )
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
    F = idx.ravel()[_grid_faces(Nu, Nv, surface.closed_u, surface.closed_v)]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
    used, Fc = np.unique(F, return_inverse=True)
    F = Fc.reshape(-1, 3).astype(np.int64)
    U, W = np.meshgrid(us, vs, indexing="ij")
    uv = np.stack([U.ravel(), W.ravel()], axis=1)[used]
    V = surface(uv[:, 0], uv[:, 1])
    collapsed = np.bincount(idx.ravel(), minlength=Nu * Nv) > 1
    pole = collapsed[used]
    return SurfaceMesh(
        V=np.ascontiguousarray(V, dtype=np.float64),
        F=np.ascontiguousarray(F),
        uv=uv,
        pole=pole,
        boundary=boundary_vertex_mask(F, len(V)),
        surface=surface.name,
        res=(nu, nv),
    )
