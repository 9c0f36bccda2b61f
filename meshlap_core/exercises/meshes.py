"""The battery of meshes every exercise is checked on, each chosen to expose a classic mistake.

=====================  ==========================================================================
case                   what it catches
=====================  ==========================================================================
``one_triangle``       the hand-computable case: wrong factors (2, ½, 3) show at once
``tetrahedron``        a closed regular mesh: sign and orientation, angle defect π per vertex
``obtuse_fan``         an interior vertex with an obtuse triangle: barycentric vs Voronoi vs mixed
``boundary_fan``       an open fan: the boundary rule of the angle defect, one-sided cot weights
``cube_corner``        three squares around a corner: defect exactly π/2, zero-curvature faces
``non_delaunay_pair``  two triangles whose opposite angles sum past π: a negative cot weight
``unreferenced``       vertices in no face (one in the middle, one last): shape ``(n,n)`` not
                       ``F.max()+1``, zero rows, no division by zero
``scaled``             a bumpy sphere scaled by 250 and moved: units and scale-aware tolerances
``small_sphere``       a closed bumpy sphere (42 vertices) for the eigenproblem
``degenerate``         a triangle of zero area (three collinear corners): no NaN or inf, its
                       cot weights, normal and areas are 0
``slivers``            a needle and a cap (angles of 0.06° and 179.9°): cot weights near ±1000,
                       float32 loses them, an absolute "small area" threshold drops them
``large``              an icosphere of 2562 vertices, perturbed: correctness at size and speed
``huge``               a bumpy torus of 20,480 vertices: a dense n×n array there needs 3.4 GB
                       (fails on memory or time, and is named so)
``bumpy_grid``         an open 9×7 grid, jittered and bumpy: a disk for the maps, an open patch
                       for the deformations
``jittered_disk``      a Delaunay disk whose boundary vertices are unevenly spaced: arc length,
                       not index, on the circle
``cap``                a curved disk cut from a bumpy sphere (not developable: LSCM distorts)
``scaled_cap``         the cap scaled by 250 and moved: units of the maps
``large_disk``         a disk of ~1900 vertices (a bumpy sphere below its top): the maps at size,
                       and their speed
=====================  ==========================================================================

Every mesh is generated here (seeded), never read from disk, and oriented counter-clockwise
seen from outside. :func:`battery` builds them once per process; their arrays are read-only
(the checker hands every student call a copy).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import Delaunay

from ..laplacian import mean_edge_length
from ..primitives import grid, icosphere, torus_mesh
from ..types import FloatArray, IntArray


@dataclass(frozen=True)
class Case:
    """One mesh of the battery.

    Attributes
    ----------
    name : str
    V : (n,3) float
    F : (m,3) int
    catches : str
        The mistake this mesh is there to expose (shown with a failure).
    closed : bool
        No boundary and no unreferenced vertex (the eigenproblem needs it).
    """

    name: str
    V: FloatArray
    F: IntArray
    catches: str
    closed: bool = False
    tags: tuple[str, ...] = field(default=())

    @property
    def scale(self) -> float:
        """Mean edge length ``h`` (each edge once): a quantity with units of length^p is
        compared at ``h^p``."""
        return mean_edge_length(self.V, self.F)


def _outward(V: FloatArray, F: IntArray, inside: FloatArray) -> IntArray:
    """Flip faces whose normal points towards ``inside`` (a convex-ish patch or solid)."""
    P = V[F]
    n = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    flip = np.einsum("ij,ij->i", n, P.mean(axis=1) - inside) < 0
    F = F.copy()
    F[flip] = F[flip][:, ::-1]
    return F


def _fan(angles: list[float], radii: list[float], heights: list[float], closed: bool):
    """A fan around vertex 0 at the origin: ring vertices at the given polar angles (degrees)."""
    t = np.radians(angles)
    ring = np.column_stack([np.cos(t) * radii, np.sin(t) * radii, heights])
    V = np.vstack([[0.0, 0.0, 0.0], ring])
    k = len(angles)
    stop = k if closed else k - 1
    F = np.array([[0, 1 + j, 1 + (j + 1) % k] for j in range(stop)], dtype=np.int64)
    return V, F


def _bumpy_sphere(subdivisions: int, seed: int, amount: float = 0.08):
    V, F = icosphere(subdivisions)
    rng = np.random.default_rng(seed)
    V = V * (1.0 + amount * rng.uniform(-1.0, 1.0, size=(len(V), 1)))
    return V, F


def _degenerate() -> tuple[FloatArray, IntArray]:
    """Vertex 1 on the segment from 0 to 2 (exact coordinates: the face (2, 0, 1) has area 0 in
    any formula), a face above and two below; vertex 1 is interior (angles π, π/2, π/2)."""
    V = np.array(
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.3], [1.0, -1.0, 0.2]]
    )
    return V, np.array([[0, 2, 3], [2, 0, 1], [1, 0, 4], [2, 1, 4]])


def _slivers() -> tuple[FloatArray, IntArray]:
    """The same layout with vertex 1 lifted 10⁻³ off the segment (a cap: 179.9° at vertex 1,
    0.06° at vertices 0 and 2) and a needle beside it (0.08° at vertex 4, on a base 0.002
    long from vertex 2 to vertex 5)."""
    V, F = _degenerate()
    V = np.vstack([V, [[2.0, -0.002, 0.0]]])
    V[1, 1] = 0.001
    F = np.vstack([F, [[2, 4, 5]]])
    return V, F


def _huge() -> tuple[FloatArray, IntArray]:
    V, F = torus_mesh(160, 128, R=3.0, r=1.0)
    rng = np.random.default_rng(11)
    ring = V.copy()
    ring[:, 2] = 0.0
    centre = 3.0 * ring / np.linalg.norm(ring, axis=1, keepdims=True)  # the core circle
    return centre + (V - centre) * (1.0 + 0.02 * rng.uniform(-1.0, 1.0, (len(V), 1))), F


def _bumpy_grid() -> tuple[FloatArray, IntArray]:
    """A 9×7 grid over ``[0, 1.6] × [0, 1.2]``, its interior vertices jittered in the plane, every
    vertex lifted by a bump and a little noise."""
    V, F = grid(9, 7)
    V[:, 0] *= 1.6
    V[:, 1] *= 1.2
    rng = np.random.default_rng(5)
    inner = (V[:, 0] > 0) & (V[:, 0] < 1.6) & (V[:, 1] > 0) & (V[:, 1] < 1.2)
    V[inner, :2] += rng.uniform(-0.06, 0.06, (int(inner.sum()), 2))
    V[:, 2] = 0.25 * np.sin(2.5 * V[:, 0]) * np.cos(2.0 * V[:, 1])
    V[:, 2] += 0.05 * rng.uniform(-1.0, 1.0, len(V))
    return V, F


def _jittered_disk(b: int = 26, inside: int = 70) -> tuple[FloatArray, IntArray]:
    """The Delaunay triangulation of ``b`` points on the unit circle at unevenly spaced angles
    and ``inside`` points in it (at least 0.12 apart), lifted onto a saddle with a ripple;
    faces counter-clockwise seen from above."""
    rng = np.random.default_rng(13)
    t = 2.0 * np.pi * (np.arange(b) + rng.uniform(-0.35, 0.35, b)) / b
    points = [*np.stack([np.cos(t), np.sin(t)], axis=1)]
    while len(points) < b + inside:
        p = rng.uniform(-0.88, 0.88, 2)
        if np.linalg.norm(p) < 0.88 and all(np.linalg.norm(p - q) > 0.12 for q in points[b:]):
            points.append(p)
    P = np.array(points)
    F = Delaunay(P).simplices.astype(np.int64)
    e1, e2 = P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]]
    clockwise = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    F[clockwise] = F[clockwise][:, ::-1]
    z = 0.3 * P[:, 0] ** 2 - 0.2 * P[:, 1] ** 2 + 0.1 * np.sin(4.0 * P[:, 0] + 1.0)
    return np.column_stack([P, z]), F


def _cap(subdivisions: int, below: float, seed: int, amount: float):
    """The faces of a bumpy sphere above the height ``below`` (every corner above it), the
    vertices renumbered: a curved disk."""
    V, F = _bumpy_sphere(subdivisions, seed, amount)
    F = F[(V[F][:, :, 2] > below).all(axis=1)]
    used = np.unique(F)
    renumber = np.zeros(len(V), dtype=np.int64)
    renumber[used] = np.arange(len(used))
    return np.ascontiguousarray(V[used]), renumber[F]


@functools.cache
def battery() -> tuple[Case, ...]:
    """All cases, in the order they are tried (the small hand-checkable ones first); built once,
    their arrays read-only."""
    cases = _cases()
    for c in cases:
        c.V.flags.writeable = False
        c.F.flags.writeable = False
    return tuple(cases)


def _cases() -> list[Case]:
    """Long because it is the battery itself: one mesh per paragraph, read top to bottom."""
    cases: list[Case] = []
    V = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, 0.8, 0.0]])
    cases.append(Case("one_triangle", V, np.array([[0, 1, 2]]), "factors 2, ½, 3 by hand"))

    s = 1.0 / np.sqrt(2.0)
    V = np.array([[1.0, 0.0, -s], [-1.0, 0.0, -s], [0.0, 1.0, s], [0.0, -1.0, s]])
    F = _outward(V, np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]), V.mean(axis=0))
    cases.append(Case("tetrahedron", V, F, "sign and orientation on a closed mesh", True))

    V, F = _fan([0, 70, 130, 250, 310], [1.0, 0.8, 1.2, 0.9, 1.1], [0.3, 0.1, 0.4, 0.2, 0.35], True)
    cases.append(Case("obtuse_fan", V, F, "barycentric instead of Voronoi (obtuse triangle)"))

    V, F = _fan(
        [0, 50, 110, 160, 210], [1.0, 1.1, 0.9, 1.0, 1.2], [0.2, 0.0, 0.3, 0.1, 0.25], False
    )
    cases.append(Case("boundary_fan", V, F, "the boundary rule, one-sided cot weights"))

    V = np.array(
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [0, 1, 1], [1, 0, 1]], float
    )
    F = np.array([[0, 2, 4], [0, 4, 1], [0, 1, 6], [0, 6, 3], [0, 3, 5], [0, 5, 2]])
    F = _outward(V, F, np.array([0.5, 0.5, 0.5]))
    cases.append(Case("cube_corner", V, F, "defect π/2 at the corner, flat faces"))

    V = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.2, 0.0], [0.1, -0.3, 0.1]])
    F = np.array([[0, 1, 2], [1, 0, 3]])
    cases.append(Case("non_delaunay_pair", V, F, "a negative cot weight (no abs, no clamp)"))

    V0, F0 = _fan([0, 80, 150, 220, 290], [1.0, 0.9, 1.1, 1.0, 0.95], [0.2] * 5, True)
    V0[0, 2] = 0.5
    # insert an unreferenced vertex in the middle and one at the end
    V = np.vstack([V0[:3], [[5.0, 5.0, 5.0]], V0[3:], [[-4.0, 2.0, 1.0]]])
    F = np.where(F0 >= 3, F0 + 1, F0)
    cases.append(Case("unreferenced", V, F, "shape (n,n) with zero rows for vertices in no face"))

    V, F = _bumpy_sphere(1, seed=3)
    cases.append(Case("small_sphere", V, F, "a closed surface for the eigenproblem", True))
    cases.append(
        Case("scaled", 250.0 * V + [40.0, -7.0, 3.0], F, "units: a copy scaled by 250", True)
    )
    V, F = _degenerate()
    cases.append(Case("degenerate", V, F, "a triangle of zero area: no NaN or inf"))
    V, F = _slivers()
    cases.append(Case("slivers", V, F, "a needle and a cap: cot weights near ±1000"))
    V, F = _bumpy_sphere(4, seed=7, amount=0.02)
    cases.append(Case("large", V, F, "correct at size, and the speed", True, ("speed",)))
    V, F = _huge()
    cases.append(Case("huge", V, F, "20,480 vertices: sparse, not dense n×n", True, ("huge",)))
    V, F = _bumpy_grid()
    cases.append(Case("bumpy_grid", V, F, "an open bumpy patch: uniform vs cot weights"))
    V, F = _jittered_disk()
    cases.append(Case("jittered_disk", V, F, "a boundary unevenly spaced: arc length, not index"))
    V, F = _cap(3, 0.25, seed=4, amount=0.05)
    cases.append(Case("cap", V, F, "a curved disk (not developable)"))
    V = 250.0 * V + [40.0, -7.0, 3.0]
    cases.append(Case("scaled_cap", V, F, "units: a disk scaled by 250"))
    V, F = _cap(4, -0.5, seed=8, amount=0.02)
    cases.append(Case("large_disk", V, F, "a disk at size, and the maps' speed", tags=("speed",)))
    return cases


def case_named(name: str) -> Case:
    """The battery case called ``name``."""
    for c in battery():
        if c.name == name:
            return c
    raise KeyError(name)
