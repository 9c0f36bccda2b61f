"""The deformation exercises: a biharmonic displacement and one ARAP local/global step, their
calls, references and classic mistakes.

The references are the lab's own deformers (:mod:`meshlap_core.deform`):
:class:`~meshlap_core.deform.HarmonicDeformer` with ``k = 2`` (``Δ²d = 0`` for the
displacement; libigl's ``harmonic(V, F, b, d_b, 2)``) and one
:meth:`~meshlap_core.deform.ArapDeformer.step` of the spokes energy with the exact rotations
(Sorkine & Alexa 2007). The mistakes are written with :func:`biharmonic_steps` and
:func:`arap_steps`, each the template's formulas spelt out with a switch per classic mistake
(the test suite checks that without any switch they give the reference's answer):

- biharmonic: the positions solved for instead of the displacement, uniform weights instead of
  the cotangent ones, the mass matrix left out between the two Laplacians, ``Δd = 0``
  (harmonic) instead of ``Δ²d = 0``;
- ARAP: rotations without the reflection fix, uniform weights, the rotation transposed, ``R_i``
  alone in the right-hand side (not ``½(R_i + R_j)``), the handles not placed before the local
  step.

Every call holds a moved handle region (rotated about its centroid and moved) and a fixed one
(the same number of vertices at the other end of the mesh's longest extent). The ARAP call's
current positions are the rest pose turned by 25° with the far side of a plane mirrored through
it: the one-rings there fit a reflection best, which the reflection fix must refuse.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import laplacian as lap
from ..deform import ArapDeformer, HarmonicDeformer, rigid_targets, rotation_matrix
from ..deform.rotations import fit_rotations
from ..options import MASS_AREA
from .meshes import Case

Args = tuple[Any, ...]

BIHARMONIC_STUB = '''
def biharmonic_displacement(V, F, handles, handle_displacement):
    """Deform by the biharmonic displacement (Botsch & Kobbelt 2004; Jacobson et al. 2010).

    Solve for the displacement d = U − V, not the positions (then the rest pose is kept exactly
    when nothing moves, and the surface's details ride along): Δ²d = 0 at every free vertex,
    d = handle_displacement at the handles. In weak form with C = cotan_laplacian (cotangent
    weights) and M = mass_matrix (mixed Voronoi): Q = C M⁻¹ C, and for each coordinate
    Q_ff d_f = −Q_fh d_h (f the free vertices, h the handles) — libigl's
    igl.harmonic(V, F, handles, handle_displacement, 2) is the same displacement.

    handles : (h,) int, sorted (the moved and the held vertices; a held one's displacement is 0)
    handle_displacement : (h,3) float
    A vertex that no handle can reach (in no face, or on a piece without a handle) stays put.

    Returns U = V + d : (n,3), exactly V + handle_displacement at the handles.
    """
    raise NotImplementedError
'''
"""The template's stub of the biharmonic task."""

ARAP_STUB = '''
def arap_step(V, F, U, handles, targets):
    """One local/global iteration of as-rigid-as-possible deformation (Sorkine & Alexa 2007),
    the spokes energy E = Σ_i Σ_{j∈N(i)} w_ij ‖(u_i − u_j) − R_i (p_i − p_j)‖² with the
    cotangent weights w_ij = ½(cot α_ij + cot β_ij) (= C_ij of cotan_laplacian), p = V the
    rest positions, U the current ones:

    1. place the handles: U[handles] = targets;
    2. local step: per vertex, S_i = Σ_j w_ij (p_i − p_j)(u_i − u_j)ᵀ (3×3) = A Σ Bᵀ (SVD);
       R_i = B Aᵀ, the rotation taking rest edges to current ones — if det(B Aᵀ) < 0 it is a
       reflection: negate the column of B of the smallest singular value first (the
       reflection fix), so that det R_i = +1;
    3. global step: solve K x = b with K = −C and b_i = Σ_j (w_ij/2)(R_i + R_j)(p_i − p_j)
       for the free vertices, x = targets at the handles (K_ff x_f = b_f − K_fh targets).

    handles : (h,) int, sorted;  targets : (h,3) float;  U : (n,3) float.
    A vertex that no handle can reach (in no face, or on a piece without a handle) goes back
    to its rest position.

    Returns x : (n,3), the new positions.
    """
    raise NotImplementedError
'''
"""The template's stub of the ARAP step."""

DEFORM_CASES = ("bumpy_grid", "cap", "small_sphere", "scaled", "large", "huge")
"""Open and closed, curved (no one-ring is flat: the reflection fix decides), scaled by 250,
and big (a dense n×n system on the torus of 20,480 vertices needs 3.4 GB)."""
TURN = rotation_matrix([1.0, 2.0, 3.0], 25.0)
"""The ARAP call's current positions start from the rest pose turned by this rotation."""


# ---- the calls ------------------------------------------------------------------------------


def handle_sets(case: Case) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(moved, held, axis)``: the tenth of the mesh's vertices (at least 3) farthest along its
    longest extent, and the tenth at the other end (vertices in no face are neither)."""
    used = np.unique(case.F)
    P = case.V[used]
    extent = P.max(axis=0) - P.min(axis=0)
    axis = np.eye(3)[int(np.argmax(extent))]
    order = np.argsort((P - P.mean(axis=0)) @ axis, kind="stable")
    k = max(3, len(used) // 10)
    return np.sort(used[order[-k:]]), np.sort(used[order[:k]]), axis


def _size(case: Case) -> float:
    used = np.unique(case.F)
    return float(np.linalg.norm(np.ptp(case.V[used], axis=0)))


def _handles_and_targets(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """The handles (sorted) and their targets: the moved region rotated by 40° about an axis
    across the longest extent and moved by a quarter of the mesh's size; the held region at
    rest."""
    moved, held, axis = handle_sets(case)
    across = np.cross(axis, [0.3, 0.5, 0.8])
    go = rigid_targets(case.V, moved, rotation_matrix(across, 40.0), 0.25 * _size(case) * axis)
    handles = np.concatenate([moved, held])
    targets = np.concatenate([go, case.V[held]])
    order = np.argsort(handles)
    return handles[order], targets[order]


def biharmonic_calls(case: Case) -> list[tuple[str, Args]]:
    """One call per mesh: ``(V, F, handles, handle_displacement)``."""
    handles, targets = _handles_and_targets(case)
    d = targets - case.V[handles]
    return [(f"{len(handles)} handles", (case.V.copy(), case.F.copy(), handles, d))]


def current_positions(case: Case) -> np.ndarray:
    """The ARAP call's ``U``: the rest pose turned by :data:`TURN` about its centroid, the
    vertices beyond a plane across the longest extent (the last 40 %) mirrored through it."""
    _, _, axis = handle_sets(case)
    used = np.unique(case.F)
    c = case.V[used].mean(axis=0)
    s = (case.V - c) @ axis
    cut = float(np.quantile(s[used], 0.6))
    mirrored = case.V - 2.0 * np.maximum(s - cut, 0.0)[:, None] * axis
    return (mirrored - c) @ TURN.T + c


def arap_calls(case: Case) -> list[tuple[str, Args]]:
    """One call per mesh: ``(V, F, U, handles, targets)``."""
    handles, targets = _handles_and_targets(case)
    U = current_positions(case)
    return [(f"{len(handles)} handles", (case.V.copy(), case.F.copy(), U, handles, targets))]


# ---- the references -------------------------------------------------------------------------


def biharmonic_reference(case: Case, args: Args) -> np.ndarray:
    """The lab's biharmonic displacement (:class:`HarmonicDeformer`, ``k = 2``)."""
    V, F, handles, d = args
    solver = HarmonicDeformer(V, F, handles, k=2)
    return solver.update(V[handles] + d).copy()


def arap_reference(case: Case, args: Args) -> np.ndarray:
    """One step of the lab's :class:`ArapDeformer` (spokes, exact rotations) from ``U``."""
    V, F, U, handles, targets = args
    arap = ArapDeformer(V, F, handles, energy="spokes", rotations="exact")
    arap.reset(U)
    arap.set_targets(targets)
    arap.step()
    return arap.positions.copy()


# ---- the steps, with a switch per mistake ---------------------------------------------------


def _pinned_solve(Q: sp.spmatrix, n: int, handles: np.ndarray, known: np.ndarray,
                  b: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """``Q_ff x_f = b_f − Q_fh known`` (``Q`` need not be symmetric); ``x_h = known``."""
    free = np.setdiff1d(np.arange(n), handles)
    Q = sp.csr_matrix(Q)
    x = np.zeros((n, known.shape[1]))
    x[handles] = known
    rhs = -(Q[free][:, handles] @ known)
    if b is not None:
        rhs = rhs + b[free]
    x[free] = spla.splu(sp.csc_matrix(Q[free][:, free])).solve(rhs)
    return x


def _graph_stiffness(F: np.ndarray, n: int) -> sp.csr_matrix:
    """``D − A`` (weight 1 per edge, positive semidefinite)."""
    A = lap.adjacency_matrix(F, n)
    return (sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A).tocsr()


def biharmonic_steps(
    V: np.ndarray,
    F: np.ndarray,
    handles: np.ndarray,
    d: np.ndarray,
    *,
    weights: str = "cotan",
    positions: bool = False,
    mass: bool = True,
    k: int = 2,
) -> np.ndarray:
    """The template's biharmonic displacement with a switch per classic mistake (a mesh whose
    every piece holds a handle).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    handles : (h,) int
    d : (h,3) float
        The handles' displacement.
    weights : {"cotan", "uniform", "uniform-normalised"}
        ``K = −C``, ``D − A`` (weight 1 per edge), or the strong form with ``D⁻¹A − I`` (the
        uniform Laplacian of the exercises: ``Δ_u² d = 0``, i.e. ``(D − A) D⁻¹ (D − A)``).
    positions : bool
        Solve for the positions (``x_h = V_h + d``) instead of the displacement.
    mass : bool
        ``K M⁻¹ K``; ``False``: ``K K``.
    k : int
        1: ``K d = 0`` (harmonic); 2: biharmonic.

    Returns
    -------
    U : (n,3) float
    """
    n = len(V)
    if weights == "cotan":
        K = -lap.cotan_stiffness(V, F)
        m = lap.vertex_areas(V, F, MASS_AREA)
    else:
        K = _graph_stiffness(F, n)
        degree = K.diagonal()
        m = degree if weights == "uniform-normalised" else lap.vertex_areas(V, F, MASS_AREA)
    inv = np.divide(1.0, m, out=np.zeros_like(m), where=m > 0) if mass else np.ones(n)
    Q = K if k == 1 else K @ sp.diags(inv) @ K
    if positions:
        return _pinned_solve(Q, n, handles, V[handles] + d)
    return V + _pinned_solve(Q, n, handles, d)


def arap_steps(
    V: np.ndarray,
    F: np.ndarray,
    U: np.ndarray,
    handles: np.ndarray,
    targets: np.ndarray,
    *,
    weights: str = "cotan",
    reflection_fix: bool = True,
    transposed: bool = False,
    averaged: bool = True,
    place: bool = True,
) -> np.ndarray:
    """The template's ARAP step with a switch per classic mistake (a mesh whose every piece
    holds a handle).

    Parameters
    ----------
    V, F, U, handles, targets :
        As the task's.
    weights : {"cotan", "uniform"}
        ``w_ij = ½(cot α + cot β)``, or 1 per edge (in the covariances, ``K`` and ``b``).
    reflection_fix : bool
        ``False``: the orthogonal polar factor, a reflection where ``det S < 0``.
    transposed : bool
        ``R_iᵀ`` (``A Bᵀ``) instead of ``R_i``.
    averaged : bool
        ``b_i = Σ_j (w_ij/2)(R_i + R_j)(p_i − p_j)``; ``False``: ``Σ_j w_ij R_i (p_i − p_j)``.
    place : bool
        ``U[handles] = targets`` before the local step.

    Returns
    -------
    x : (n,3) float
    """
    n = len(V)
    K = -lap.cotan_stiffness(V, F) if weights == "cotan" else _graph_stiffness(F, n)
    W = (-K).tocoo()  # off the diagonal: w_ij, each directed spoke once
    off = W.row != W.col
    i, j, w = W.row[off], W.col[off], W.data[off]
    X = np.array(U, dtype=np.float64)
    if place:
        X[handles] = targets
    e, e2 = V[i] - V[j], X[i] - X[j]
    S = np.zeros((n, 3, 3))
    np.add.at(S, i, w[:, None, None] * e[:, :, None] * e2[:, None, :])
    R = fit_rotations(S, reflection_fix)
    if transposed:
        R = R.transpose(0, 2, 1)
    turn = R[i] + R[j] if averaged else 2.0 * R[i]  # twice the edge's rotation
    Re = np.einsum("kab,kb->ka", turn, e)
    b = np.zeros((n, 3))
    np.add.at(b, i, 0.5 * w[:, None] * Re)
    return _pinned_solve(K, n, handles, targets, b)


# ---- the mistakes ---------------------------------------------------------------------------


def bi_positions(case: Case, args: Args) -> np.ndarray:
    """Solving for the positions, not the displacement."""
    return biharmonic_steps(*args, positions=True)


def bi_uniform(weights: str):
    """Uniform weights: ``D − A`` with the Voronoi mass, or the strong form with ``D⁻¹A − I``."""

    def wrong(case: Case, args: Args) -> np.ndarray:
        return biharmonic_steps(*args, weights=weights)

    return wrong


def bi_without_mass(case: Case, args: Args) -> np.ndarray:
    """``K K d = 0``: no ``M⁻¹`` between the two Laplacians."""
    return biharmonic_steps(*args, mass=False)


def bi_harmonic(case: Case, args: Args) -> np.ndarray:
    """``K d = 0``: harmonic, not biharmonic."""
    return biharmonic_steps(*args, k=1)


def arap_mistake(**switch: Any):
    """The ARAP step with one switch (:func:`arap_steps`) as a mistake's wrong answer."""

    def wrong(case: Case, args: Args) -> np.ndarray:
        return arap_steps(*args, **switch)

    return wrong
