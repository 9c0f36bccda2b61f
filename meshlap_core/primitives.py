"""Meshes the project generates itself: icosphere, torus, flat grid, cube, bumpy sphere.

Every function returns ``(V, F)`` with ``V : (n,3) float64`` and ``F : (m,3) int64``, faces
counter-clockwise seen from outside (outward normals) on closed meshes and ``+z`` on the grid.
The test suite and the bundled ``assets/`` use only these, so a fresh clone needs no data.
"""

from __future__ import annotations

import igl
import numpy as np

from .errors import MeshError
from .types import FloatArray, IntArray


def icosphere(subdivisions: int = 2, radius: float = 1.0) -> tuple[FloatArray, IntArray]:
    """Icosphere: the icosahedron, midpoint-subdivided ``subdivisions`` times, projected on the
    sphere of the given radius. ``10·4^s + 2`` vertices, ``20·4^s`` faces.

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core import icosphere
    >>> V, F = icosphere(2, radius=2.0)
    >>> V.shape, F.shape  # 10·4² + 2 vertices, 20·4² faces
    ((162, 3), (320, 3))
    >>> bool(np.allclose(np.linalg.norm(V, axis=1), 2.0))
    True
    """
    if subdivisions < 0:
        raise MeshError("must be >= 0", "subdivisions")
    V, F = igl.icosahedron()
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    for _ in range(subdivisions):
        V, F = igl.upsample(V, F)
        V = V / np.linalg.norm(V, axis=1, keepdims=True)
    V = V / np.linalg.norm(V, axis=1, keepdims=True) * radius
    return np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(F, dtype=np.int64)


def grid_faces(nu: int, nv: int, wrap_u: bool, wrap_v: bool) -> IntArray:
    """Two triangles per cell of an ``nu × nv`` vertex grid (index ``i*nv + j``), CCW in (u,v)."""
    cu = nu if wrap_u else nu - 1
    cv = nv if wrap_v else nv - 1
    i, j = np.meshgrid(np.arange(cu), np.arange(cv), indexing="ij")
    i, j = i.ravel(), j.ravel()
    i1 = (i + 1) % nu
    j1 = (j + 1) % nv
    a, b, c, d = i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1
    return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int64)


def grid(nx: int = 10, ny: int = 10, size: float = 1.0) -> tuple[FloatArray, IntArray]:
    """Flat ``nx × ny`` vertex grid in the plane ``z = 0`` over ``[0,size]²``, normals ``+z``.

    Examples
    --------
    >>> from meshlap_core import boundary_loops, grid
    >>> V, F = grid(3, 3)
    >>> V.shape, F.shape, V.max(axis=0).tolist()
    ((9, 3), (8, 3), [1.0, 1.0, 0.0])
    >>> boundary_loops(F)[0].tolist()  # the eight outer vertices, the interior on the left
    [0, 3, 6, 7, 8, 5, 2, 1]
    """
    if nx < 2 or ny < 2:
        raise MeshError("a grid needs at least 2 x 2 vertices", "grid")
    x, y = np.meshgrid(np.linspace(0, size, nx), np.linspace(0, size, ny), indexing="ij")
    V = np.stack([x.ravel(), y.ravel(), np.zeros(nx * ny)], axis=1)
    return V, grid_faces(nx, ny, False, False)


def torus_mesh(
    n_major: int = 32, n_minor: int = 16, R: float = 3.0, r: float = 1.0
) -> tuple[FloatArray, IntArray]:
    """Triangle mesh ``(V, F)`` of the torus around the z axis,
    ``p(u,v) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v)``, sampled on a regular
    ``n_major × n_minor`` grid with welded seams (genus 1, χ = 0).

    The *parametric* torus (exact geometry at any ``(u, v)``) is
    :func:`meshlap_core.surfaces.torus`; ``mesh_surface(surfaces.torus(R, r), (n_major, n_minor))``
    gives this same mesh.

    Examples
    --------
    >>> from meshlap_core import EdgeTable, torus_mesh
    >>> V, F = torus_mesh(32, 16)
    >>> n_edges = len(EdgeTable.from_faces(F).edges)
    >>> len(V), len(F), len(V) - n_edges + len(F)  # Euler characteristic 0: genus 1
    (512, 1024, 0)
    """
    if n_major < 3 or n_minor < 3:
        raise MeshError("a torus needs at least 3 x 3 samples", "torus")
    u, v = np.meshgrid(
        np.linspace(0, 2 * np.pi, n_major, endpoint=False),
        np.linspace(0, 2 * np.pi, n_minor, endpoint=False),
        indexing="ij",
    )
    u, v = u.ravel(), v.ravel()
    V = np.stack(
        [(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], 1
    )
    return V, grid_faces(n_major, n_minor, True, True)


def cube(subdivisions: int = 0, size: float = 1.0) -> tuple[FloatArray, IntArray]:
    """Axis-aligned cube ``[0,size]³`` (8 vertices, 12 faces), optionally midpoint-subdivided.

    Subdivision keeps the vertices on the faces, so the corner angle sums and the volume
    (``size³``) are unchanged.

    Examples
    --------
    Midpoint subdivision keeps the cube's shape: only its 8 corners carry an angle deficit
    (π/2 each, 4π in all):

    >>> import numpy as np
    >>> from meshlap_core import cube, curvature_field, vertex_areas
    >>> V, F = cube(1)
    >>> V.shape, F.shape
    ((26, 3), (48, 3))
    >>> A = vertex_areas(V, F, "barycentric")
    >>> deficit = curvature_field(V, F, "gaussian", area="barycentric") * A  # K·A = 2π − Σθ
    >>> curved = np.abs(deficit) > 1e-9
    >>> int(curved.sum()), bool(np.allclose(deficit[curved], np.pi / 2))
    (8, True)
    """
    V = (
        np.array(
            [
                [0, 0, 0],
                [1, 0, 0],
                [1, 1, 0],
                [0, 1, 0],
                [0, 0, 1],
                [1, 0, 1],
                [1, 1, 1],
                [0, 1, 1],
            ],
            dtype=np.float64,
        )
        * size
    )
    F = np.array(
        [
            [0, 2, 1],
            [0, 3, 2],  # z = 0 (normal -z)
            [4, 5, 6],
            [4, 6, 7],  # z = 1
            [0, 1, 5],
            [0, 5, 4],  # y = 0
            [2, 3, 7],
            [2, 7, 6],  # y = 1
            [1, 2, 6],
            [1, 6, 5],  # x = 1
            [0, 4, 7],
            [0, 7, 3],  # x = 0
        ],
        dtype=np.int64,
    )
    for _ in range(subdivisions):
        V, F = igl.upsample(V, F)
    return np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(F, dtype=np.int64)


def bumpy_sphere(
    subdivisions: int = 4, amplitude: float = 0.12, frequency: int = 5
) -> tuple[FloatArray, IntArray]:
    """A closed genus-0 surface with bumps of both curvature signs: an icosphere whose radius is
    ``1 + amplitude · sin(f x) sin(f y) sin(f z)``.
    """
    V, F = icosphere(subdivisions)
    bump = np.sin(frequency * V[:, 0]) * np.sin(frequency * V[:, 1]) * np.sin(frequency * V[:, 2])
    return V * (1.0 + amplitude * bump)[:, None], F


PRIMITIVES = {
    "icosphere": icosphere,
    "torus": torus_mesh,
    "grid": grid,
    "cube": cube,
    "bumpy": bumpy_sphere,
}
