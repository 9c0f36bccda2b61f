"""The flattening exercises: Tutte's map (and the harmonic map) and LSCM, their calls,
references and classic mistakes.

The references are the lab's own maps (:class:`~meshlap_core.flatten.Flattener`, the mesh taken
as the disk it is): ``map("tutte" | "harmonic", "circle")`` and ``lscm()``. The student is
given what the lab chooses, so the comparison is exact, not up to a rotation or a similarity:
the outer boundary loop in the lab's order (its first vertex goes to ``(1, 0)``) and LSCM's two
pins with their positions ``(0, 0)`` and ``(d, 0)`` (``d`` their distance in space). The
mistakes are written with :func:`tutte_steps` and :func:`lscm_steps`, the template's formulas
with a switch per classic mistake (the test suite checks that without a switch they give the
reference's answer):

- Tutte / harmonic: uniform weights where the cotangent ones are asked for, the boundary spaced
  evenly by index (not by arc length), the disk rotated or mirrored (the loop started elsewhere
  or run backwards: recognised up to any rotation or mirror, :func:`fits_rotated`), the boundary
  not on the unit circle (any such answer, :func:`fits_off_circle`);
- LSCM: no area term (``E_D`` alone: ``v = 0``), the area term's sign (a mirrored map), uniform
  weights, and no pins (any collapsed map, or pins not where given: :func:`fits_unpinned`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from ..flatten import Flattener
from ..flatten.boundary import arc_shares, boundary_positions
from ..flatten.conformal import area_matrix, image_area
from ..flatten.fixed_boundary import (
    DirichletSolver,
    cotan_laplacian,
    graph_laplacian,
    sorted_csr,
)
from .compare import compare_array
from .meshes import Case

Args = tuple[Any, ...]

TUTTE_STUB = '''
def tutte_map(V, F, loop, weights):
    """Map a disk onto the unit disk, its boundary fixed on the unit circle: Tutte's embedding
    (weights="uniform": weight 1 per edge; Tutte 1963, Floater 1997) or the harmonic map
    (weights="cotan": w_ij = ½(cot α_ij + cot β_ij) = C_ij of cotan_laplacian; Eck et al. 1995).

    loop : (b,) int, the outer boundary loop in order, the interior on its left.
    Boundary, by arc length: loop[k] goes to (cos θ_k, sin θ_k), θ_k = 2π s_k / L, s_k the
    length (in 3-D) of the loop's edges from loop[0] to loop[k], L the whole loop's length:
    loop[0] lands on (1, 0) and the loop runs counter-clockwise.
    Inside: each other vertex is the weighted average of its neighbours,
    Σ_j w_ij (uv_j − uv_i) = 0, that is K_ff uv_f = −K_fb uv_b for both coordinates (K = D − A
    or K = −C, f the free vertices, b the loop's). Other boundary loops (holes) stay free.

    Returns uv : (n,2).
    """
    raise NotImplementedError
'''
"""The template's stub of the Tutte task."""

LSCM_STUB = '''
def lscm(V, F, pins, pin_uv):
    """Least-squares conformal map (Lévy, Petitjean, Ray & Maillot 2002) with two pins.

    Minimize the conformal energy E_C = E_D − A = ½ xᵀ L_C x over x = [u; v] (2n unknowns):
    E_D = ½ (uᵀKu + vᵀKv) the Dirichlet energy (K = −C, cotangent weights) and A the image's
    signed area, A = ½ Σ (u_a v_b − u_b v_a) over every boundary half-edge a → b (its face on
    the left). So L_C = [[K, 0], [0, K]] − Q_A, where Q_A has +½ at (u_a, v_b) and (v_b, u_a)
    and −½ at (u_b, v_a) and (v_a, u_b) for each such half-edge (summed face by face, the same
    energy is Σ_f E_D,f − A_f). E_C is 0 for a map to a point and blind to similarities, so pin
    both coordinates of pins[0] at pin_uv[0] and of pins[1] at pin_uv[1] (4 known unknowns)
    and solve L_C's free rows for the others.

    pins : (2,) int;  pin_uv : (2,2) float.
    Returns uv : (n,2), with uv[pins] = pin_uv.
    """
    raise NotImplementedError
'''
"""The template's stub of the LSCM task."""

FLATTEN_CASES = ("obtuse_fan", "bumpy_grid", "jittered_disk", "cap", "scaled_cap", "large_disk")
"""Disks: a fan to check by hand, a bumpy grid, unevenly spaced boundary vertices, a curved
cap and a copy scaled by 250, and one of ~1900 vertices (correctness at size, the speed)."""
FLATTEN_SPEED_CASE = "large_disk"
"""The flattening tasks are timed on this disk (the ``large`` sphere has no boundary)."""
WEIGHTS = {"uniform": "tutte", "cotan": "harmonic"}
"""The Tutte task's ``weights`` -> the lab's map of that name."""
COLLAPSED = 1e-6
"""An image whose area is below this share of the reference's has collapsed."""


# ---- the disk and the calls -----------------------------------------------------------------


def flattener(case: Case) -> Flattener:
    """The lab's flattener of the case's mesh taken as the disk it is.

    Raises
    ------
    MeshError
        Not a disk (closed, a handle), or not one with the mesh's own vertices (vertices in no
        face, or where several fans of faces meet): the flattening tasks cannot be checked on it.
    """
    try:
        flat = Flattener(case.V, case.F, cut=False)
    except MeshError as exc:
        raise MeshError(
            f"the flattening exercises cannot use this mesh: "
            f"{exc.problem.split(' and cutting is off')[0]} (they need a disk: "
            "one connected piece with a boundary loop, no handle, no face of zero area)",
            "mesh",
        ) from None
    if flat.disk.n_vertices != len(case.V):
        raise MeshError(
            "the flattening exercises need a disk made of the mesh's own vertices; this one has "
            "vertices in no face or where several fans of faces meet",
            "mesh",
        )
    return flat


def tutte_calls(case: Case) -> list[tuple[str, Args]]:
    """Two calls per mesh, ``(V, F, loop, weights)``: uniform weights, then cotangent ones."""
    loop = flattener(case).disk.outer.copy()
    return [(f"weights={w}", (case.V.copy(), case.F.copy(), loop, w)) for w in WEIGHTS]


def lscm_calls(case: Case) -> list[tuple[str, Args]]:
    """One call per mesh, ``(V, F, pins, pin_uv)``: the lab's pins (two outer-boundary vertices
    far apart) at ``(0, 0)`` and ``(d, 0)``."""
    flat = flattener(case)
    _, pins = flat.lscm()
    p = np.array(pins, dtype=np.int64)
    d = float(np.linalg.norm(case.V[p[0]] - case.V[p[1]]))
    pin_uv = np.array([[0.0, 0.0], [d, 0.0]])
    return [(f"pins={p[0]},{p[1]}", (case.V.copy(), case.F.copy(), p, pin_uv))]


# ---- the references -------------------------------------------------------------------------


def tutte_reference(case: Case, args: Args) -> np.ndarray:
    """The lab's Tutte (uniform) or harmonic (cotan) map with the boundary on the circle."""
    return flattener(case).map(WEIGHTS[args[3]], "circle").uv.copy()


def lscm_reference(case: Case, args: Args) -> np.ndarray:
    """The lab's LSCM map (its pins are the call's, at the call's positions)."""
    return flattener(case).lscm()[0].copy()


# ---- the steps, with a switch per mistake ---------------------------------------------------


def _stiffness(V: np.ndarray, F: np.ndarray, weights: str) -> sp.csr_matrix:
    from ..topology import EdgeTable

    table = EdgeTable.from_faces(F, len(V))
    return graph_laplacian(table) if weights == "uniform" else cotan_laplacian(V, F, table=table)


def tutte_steps(
    V: np.ndarray,
    F: np.ndarray,
    loop: np.ndarray,
    weights: str,
    *,
    spacing: str = "arc",
    boundary: str = "circle",
    start: int = 0,
) -> np.ndarray:
    """The template's fixed-boundary map with a switch per classic mistake.

    Parameters
    ----------
    V, F, loop, weights :
        As the task's (``weights`` ``"uniform"`` or ``"cotan"``).
    spacing : {"arc", "index"}
        Angles by arc length, or ``2πk/b`` by index.
    boundary : {"circle", "square"}
        The unit circle, or the square ``[−1, 1]²`` (the lab's other shape, not the circle).
    start : int
        The loop rolled by this many vertices first (the disk turns).

    Returns
    -------
    uv : (n,2) float
    """
    loop = np.roll(loop, -start)
    if boundary == "square":
        at = boundary_positions(V, loop, "square")
    else:
        t = arc_shares(V, loop) if spacing == "arc" else np.arange(len(loop)) / len(loop)
        at = np.stack([np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)], axis=1)
    return DirichletSolver(_stiffness(V, F, weights), loop).solve(at)


def lscm_steps(
    V: np.ndarray,
    F: np.ndarray,
    pins: np.ndarray,
    pin_uv: np.ndarray,
    *,
    weights: str = "cotan",
    area: float = 1.0,
) -> np.ndarray:
    """The template's LSCM with a switch per classic mistake: ``L = diag(K, K) − area·Q_A``
    (``area`` 1: the conformal energy; 0: no area term; −1: its sign flipped), ``K`` with
    ``weights`` ``"cotan"`` or ``"uniform"``; both coordinates of the pins given.

    Returns
    -------
    uv : (n,2) float
    """
    from ..topology import EdgeTable

    n = len(V)
    K = _stiffness(V, F, weights)
    halfedges = EdgeTable.from_faces(F, n).boundary_halfedges()
    L = sorted_csr(sp.block_diag([K, K], format="csr") - area * area_matrix(halfedges, n))
    i, j = int(pins[0]), int(pins[1])
    known = np.array([[pin_uv[0, 0]], [pin_uv[1, 0]], [pin_uv[0, 1]], [pin_uv[1, 1]]])
    x = DirichletSolver(L, np.array([i, j, n + i, n + j])).solve(known)[:, 0]
    return np.stack([x[:n], x[n:]], axis=1)


# ---- the mistakes ---------------------------------------------------------------------------


def tutte_uniform(case: Case, args: Args) -> np.ndarray | None:
    """Uniform weights where the cotangent ones are asked for (``None`` for the Tutte call)."""
    if args[3] != "cotan":
        return None
    return tutte_steps(*args[:3], "uniform")


def tutte_by_index(case: Case, args: Args) -> np.ndarray:
    """The boundary spaced evenly by index (``2πk/b``), not by arc length."""
    return tutte_steps(*args, spacing="index")


def tutte_turned(case: Case, args: Args) -> np.ndarray:
    """A representative of the turned disk: the loop started a quarter of the way round."""
    return tutte_steps(*args, start=len(args[2]) // 4)


def tutte_square(case: Case, args: Args) -> np.ndarray:
    """A representative of a boundary off the circle: the loop on the square ``[−1, 1]²``."""
    return tutte_steps(*args, boundary="square")


def _finite(got: Any, shape: tuple[int, ...]) -> np.ndarray | None:
    try:
        g = np.asarray(got, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    return g if g.shape == shape and np.isfinite(g).all() else None


def fits_rotated(got: Any, expected: np.ndarray, case: Case) -> bool:
    """``got`` is the reference turned or mirrored about the origin (the orthogonal ``Q``
    closest to it, orthogonal Procrustes), and not the reference itself."""
    g = _finite(got, expected.shape)
    if g is None:
        return False
    A, _, Bt = np.linalg.svd(expected.T @ g)
    turned = expected @ (A @ Bt)
    return compare_array(g, turned, case, 0).ok and not compare_array(turned, expected, case, 0).ok


def fits_off_circle(got: Any, expected: np.ndarray, case: Case) -> bool:
    """Some vertex of the outer loop is not on the unit circle."""
    g = _finite(got, expected.shape)
    if g is None:
        return False
    loop = flattener(case).disk.outer
    return bool(np.abs(np.linalg.norm(g[loop], axis=1) - 1.0).max() > 1e-6)


def lscm_uniform(case: Case, args: Args) -> np.ndarray:
    """Uniform weights (``D − A``) in the Dirichlet energy."""
    return lscm_steps(*args, weights="uniform")


def lscm_no_area(case: Case, args: Args) -> np.ndarray:
    """``E_D`` alone (no area term): two harmonic coordinates, ``v = 0`` for pins on the u axis."""
    return lscm_steps(*args, area=0.0)


def lscm_area_sign(case: Case, args: Args) -> np.ndarray:
    """``E_D + A``: the mirror image."""
    return lscm_steps(*args, area=-1.0)


def lscm_collapsed(case: Case, args: Args) -> np.ndarray:
    """A representative of an unpinned answer: every vertex at the origin (the conformal
    energy's minimum without pins)."""
    return np.zeros((len(case.V), 2))


def fits_unpinned(got: Any, expected: np.ndarray, case: Case) -> bool:
    """The image has collapsed (its area below :data:`COLLAPSED` of the reference's), or the
    pins are not at their given positions."""
    g = _finite(got, expected.shape)
    if g is None:
        return False
    flat = flattener(case)
    pins = np.array(flat.lscm()[1])
    if not compare_array(g[pins], expected[pins], case, 1).ok:
        return True
    return image_area(g, flat.halfedges) < COLLAPSED * image_area(expected, flat.halfedges)
