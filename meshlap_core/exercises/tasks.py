"""The exercise table: for every task the student's function, the meshes it is checked on, the
reference answer (the project's own core) and the classic mistakes, each written as the wrong
answer it produces so that :mod:`.diagnose` can recognise it.

Every reference comes from the core (``laplacian``, ``curvature``, ``topology.rings``,
``spectral``): the exercises check a student against the code the rest of the lab is tested with.
Conventions are the project's: Laplacians negative semidefinite (``Δx = −2Hn``), ``K = −C``,
the generalized eigenproblem ``K u = λ M u`` with the mixed Voronoi mass, ``UᵀMU = I``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import curvature as cv
from .. import laplacian as lap
from ..options import BOUNDARY_RULES, EXERCISE_TASKS, MASS_AREA
from ..spectral.operators import laplacian_eigenpairs
from ..topology.rings import one_ring
from . import geodesic_task as geo
from .meshes import Case

Output = Any
Args = tuple[Any, ...]
OPERATOR_CASES = (
    "one_triangle",
    "tetrahedron",
    "obtuse_fan",
    "boundary_fan",
    "cube_corner",
    "non_delaunay_pair",
    "unreferenced",
    "scaled",
    "large",
)
"""Cases of every per-vertex task (all but the eigenproblem's)."""
CLOSED_CASES = ("tetrahedron", "small_sphere", "scaled")
STEP_CASES = ("tetrahedron", "obtuse_fan", "boundary_fan", "cube_corner", "scaled", "large")


@dataclass(frozen=True)
class Mistake:
    """A classic mistake: its diagnosis key (see :data:`.diagnose.DIAGNOSES`) and the wrong
    answer it gives, ``wrong(case, args)`` (``None`` where it makes no difference).

    ``fits(got, expected, case)``, when given, recognises a mistake whose wrong answer is a
    family (the distance up to an additive constant): ``wrong`` is then one member of it."""

    key: str
    wrong: Callable[[Case, Args], Output]
    fits: Callable[[Any, Output, Case], bool] | None = None


@dataclass(frozen=True)
class Task:
    """One exercise.

    Attributes
    ----------
    name : str
        The student's function name, and ``--task`` name.
    kind : {"matrix", "array", "ring", "eigen"}
        How outputs are compared (:mod:`.compare`).
    power : int
        Units of the answer, length^power (scale of the tolerance).
    cases : tuple of str
        Battery cases it is checked on.
    calls : callable
        ``calls(case) -> [(label, args)]``: the student is called ``f(*args)``.
    reference : callable
        ``reference(case, args) -> expected``.
    mistakes : tuple of Mistake
        Task-specific mistakes, tried before the generic ones.
    generic : bool
        Also try the generic mistakes (sign, factor 2, factor ½).
    speed : bool
        Time the student against the reference on the large case.
    not_judged : callable or None
        ``not_judged(case, args) -> reason or None``: a failing call that the mesh cannot
        judge (the reason is reported as a note, the call is not counted as failed).
    """

    name: str
    kind: str
    power: int
    cases: tuple[str, ...]
    calls: Callable[[Case], list[tuple[str, Args]]]
    reference: Callable[[Case, Args], Output]
    mistakes: tuple[Mistake, ...] = ()
    generic: bool = True
    speed: bool = False
    not_judged: Callable[[Case, Args], str | None] | None = None


def _vf(case: Case) -> list[tuple[str, Args]]:
    return [("", (case.V.copy(), case.F.copy()))]


def _inv(a: np.ndarray) -> np.ndarray:
    return np.divide(1.0, a, out=np.zeros_like(a), where=a > 0)


# ---- operators -----------------------------------------------------------------------------


def _uniform(case: Case, args: Args) -> sp.csr_matrix:
    return lap.uniform_laplacian(case.F, len(case.V))


def _graph(case: Case, args: Args) -> sp.csr_matrix:
    A = lap.adjacency_matrix(case.F, len(case.V))
    return (A - sp.diags(np.asarray(A.sum(axis=1)).ravel())).tocsr()


def _cotan(case: Case, args: Args) -> sp.csr_matrix:
    return lap.cotan_stiffness(case.V, case.F)


def _cotan_clamped(case: Case, args: Args) -> sp.csr_matrix:
    """Cot weights with their absolute value (negative weights of a non-Delaunay edge lost)."""
    C = _cotan(case, args).tolil()
    C.setdiag(0)
    W = abs(C.tocsr())
    return (W - sp.diags(np.asarray(W.sum(axis=1)).ravel())).tocsr()


def _row_normalised(case: Case, args: Args) -> sp.csr_matrix:
    C = _cotan(case, args)
    d = -C.diagonal()
    return (sp.diags(_inv(d)) @ C).tocsr()


def _areas(kind: str) -> Callable[[Case, Args], np.ndarray]:
    return lambda case, args: lap.vertex_areas(case.V, case.F, kind)


def _circumcentric_areas(case: Case, args: Args) -> np.ndarray:
    """Pure Voronoi cells ``⅛ Σ (l_ij² cot θ_k)`` without Meyer's obtuse-triangle rule."""
    l2 = lap.squared_edge_lengths(case.V, case.F)
    cot = lap.cotangents_intrinsic(l2)
    F = case.F
    a = np.zeros(len(case.V))
    for c in range(3):  # corner c: its two edges are opposite corners c+1 and c+2
        j, k = (c + 1) % 3, (c + 2) % 3
        np.add.at(a, F[:, c], (l2[:, j] * cot[:, j] + l2[:, k] * cot[:, k]) / 8.0)
    return a


def _mass(kind: str) -> Callable[[Case, Args], sp.csr_matrix]:
    return lambda case, args: lap.mass_matrix(case.V, case.F, kind)


def _hn(area: str) -> Callable[[Case, Args], np.ndarray]:
    def f(case: Case, args: Args) -> np.ndarray:
        w = lap.vertex_areas(case.V, case.F, area)
        return -0.5 * _inv(w)[:, None] * (_cotan(case, args) @ case.V)

    return f


def _hn_uniform(case: Case, args: Args) -> np.ndarray:
    return -0.5 * (_uniform(case, args) @ case.V)


def _H(area: str) -> Callable[[Case, Args], np.ndarray]:
    return lambda case, args: cv.mean_curvature_cotan(case.V, case.F, area)


# ---- angle defect --------------------------------------------------------------------------


def _defect_calls(case: Case) -> list[tuple[str, Args]]:
    return [(f"boundary={b}", (case.V.copy(), case.F.copy(), b)) for b in BOUNDARY_RULES]


def _defect(case: Case, args: Args) -> np.ndarray:
    return cv.angle_deficit(case.V, case.F, args[2])


def _defect_rule(rule: str) -> Callable[[Case, Args], np.ndarray | None]:
    def f(case: Case, args: Args) -> np.ndarray | None:
        return None if args[2] == rule else cv.angle_deficit(case.V, case.F, rule)

    return f


def _defect_degrees(case: Case, args: Args) -> np.ndarray:
    return np.degrees(_defect(case, args))


def _defect_density(case: Case, args: Args) -> np.ndarray:
    return cv.gaussian_curvature(case.V, case.F, "barycentric", args[2])


# ---- one-ring ------------------------------------------------------------------------------


def _ring_calls(case: Case) -> list[tuple[str, Args]]:
    return [("", (case.F.copy(), len(case.V)))]


def _ring(case: Case, args: Args) -> list[np.ndarray]:
    r = one_ring(case.F, len(case.V))
    return [np.asarray(r[i]) for i in range(len(r))]


def _ring_cw(case: Case, args: Args) -> list[np.ndarray]:
    r = one_ring(case.F, len(case.V)).reversed()
    return [np.asarray(r[i]) for i in range(len(r))]


def _ring_sorted(case: Case, args: Args) -> list[np.ndarray]:
    return [np.sort(x) for x in _ring(case, args)]


# ---- spectral ------------------------------------------------------------------------------

EIGEN_K = 6


def _eig_calls(case: Case) -> list[tuple[str, Args]]:
    k = min(EIGEN_K, len(case.V))
    return [(f"k={k}", (case.V.copy(), case.F.copy(), k))]


def _dense_eig(K: sp.spmatrix, M: sp.spmatrix | None, k: int) -> tuple[np.ndarray, np.ndarray]:
    lam, U = sla.eigh(K.toarray(), None if M is None else M.toarray())
    return lam[:k], U[:, :k]


DENSE_EIGEN_MAX = 600
"""Up to this many vertices the reference eigenpairs are dense (the battery's meshes); above
(the viewer's mesh) they come from the lab's sparse solver."""


def _eigen(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    """The ``k = args[2]`` smallest pairs of ``K u = λ M u`` (``K = −C``, mixed Voronoi ``M``)."""
    if len(case.V) > DENSE_EIGEN_MAX:
        lam, U, _ = laplacian_eigenpairs(case.V, case.F, args[2], area=MASS_AREA)
        return np.asarray(lam), np.asarray(U)
    K = -_cotan(case, args)
    return _dense_eig(K, lap.mass_matrix(case.V, case.F, MASS_AREA), args[2])


def _eigen_ordinary(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    return _dense_eig(-_cotan(case, args), None, args[2])


def _eigen_bary(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    return _dense_eig(-_cotan(case, args), lap.mass_matrix(case.V, case.F, "barycentric"), args[2])


def _eigen_negative(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    lam, U = _eigen(case, args)
    return -lam, U


def _eigen_euclid(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    lam, U = _eigen(case, args)
    return lam, U / np.linalg.norm(U, axis=0)


RECON_K = 10


def _recon_calls(case: Case) -> list[tuple[str, Args]]:
    k = min(RECON_K, len(case.V))
    _, U = _eigen(case, (case.V, case.F, k))
    M = lap.mass_matrix(case.V, case.F, MASS_AREA)
    return [(f"k={k}", (case.V.copy(), U, M))]


def _recon(case: Case, args: Args) -> np.ndarray:
    X, U, M = args
    return U @ (U.T @ (M @ X))


def _recon_no_mass(case: Case, args: Args) -> np.ndarray:
    X, U, _ = args
    return U @ (U.T @ X)


# ---- smoothing steps -----------------------------------------------------------------------

STEP_LAM = 0.4
TAUBIN_MU = -0.42


def _explicit_calls(case: Case) -> list[tuple[str, Args]]:
    return [(f"lam={STEP_LAM}", (case.V.copy(), case.F.copy(), STEP_LAM))]


def _explicit(sign: float = 1.0, transpose: bool = False):
    def f(case: Case, args: Args) -> np.ndarray:
        L = _uniform(case, args)
        L = L.T if transpose else L
        return case.V + sign * args[2] * (L @ case.V)

    return f


def _implicit_calls(case: Case) -> list[tuple[str, Args]]:
    lam = 0.5 * case.scale**2  # λ has units of length² for the cotan Laplacian
    return [("lam=h²/2", (case.V.copy(), case.F.copy(), lam))]


def _implicit(sign: float = 1.0, area: str | None = MASS_AREA):
    def f(case: Case, args: Args) -> np.ndarray:
        C = _cotan(case, args)
        n = len(case.V)
        M = lap.mass_matrix(case.V, case.F, area) if area else sp.identity(n, format="csr")
        A = (M - sign * args[2] * C).tocsc()
        return spla.spsolve(A, M @ case.V)

    return f


def _implicit_as_explicit(case: Case, args: Args) -> np.ndarray:
    return case.V + args[2] * (lap.laplace_beltrami(case.V, case.F, MASS_AREA) @ case.V)


def _taubin_calls(case: Case) -> list[tuple[str, Args]]:
    return [("lam,mu", (case.V.copy(), case.F.copy(), STEP_LAM, TAUBIN_MU))]


def _taubin(variant: str = ""):
    def f(case: Case, args: Args) -> np.ndarray:
        L = _uniform(case, args)
        V, lam, mu = case.V, args[2], args[3]
        V1 = V + lam * (L @ V)
        if variant == "lambda_only":
            return V1
        if variant == "not_sequential":
            return V1 + mu * (L @ V)
        return V1 + (-mu if variant == "mu_sign" else mu) * (L @ V1)

    return f


def _table() -> dict[str, Task]:
    """Long because it is the table itself: one entry per exercise, read top to bottom."""
    M = Mistake
    tasks = [
        Task(
            "uniform_laplacian", "matrix", 0, OPERATOR_CASES, _vf, _uniform,
            (M("graph_not_normalised", _graph),
             M("transposed", lambda c, a: _uniform(c, a).T.tocsr())), speed=True,
        ),
        Task(
            "cotan_laplacian", "matrix", 0, OPERATOR_CASES, _vf, _cotan,
            (
                M("cot_not_half", lambda c, a: 2.0 * _cotan(c, a)),
                M("row_normalised", _row_normalised),
                M("clamped_weights", _cotan_clamped),
                M("divided_by_area", lambda c, a: lap.laplace_beltrami(c.V, c.F, MASS_AREA)),
            ),
            speed=True,
        ),
        Task(
            "barycentric_areas", "array", 2, OPERATOR_CASES, _vf, _areas("barycentric"),
            (M("voronoi_not_barycentric", _areas("voronoi")),
             M("not_divided_by_3", lambda c, a: 3.0 * lap.vertex_areas(c.V, c.F, "barycentric"))),
            speed=True,
        ),
        Task(
            "voronoi_areas", "array", 2, OPERATOR_CASES, _vf, _areas("voronoi"),
            (M("barycentric_not_voronoi", _areas("barycentric")),
             M("no_obtuse_rule", _circumcentric_areas)),
            speed=True,
        ),
        Task(
            "mass_matrix", "matrix", 2, OPERATOR_CASES, _vf, _mass("voronoi"),
            (M("barycentric_not_voronoi", _mass("barycentric")),),
        ),
        Task(
            "mean_curvature_normal", "array", -1, OPERATOR_CASES, _vf, _hn("voronoi"),
            (M("barycentric_not_voronoi", _hn("barycentric")),
             M("missing_mass", lambda c, a: -0.5 * (_cotan(c, a) @ c.V)),
             M("uniform_not_cotan", _hn_uniform)),
            speed=True,
        ),
        Task(
            "mean_curvature", "array", -1, OPERATOR_CASES, _vf, _H("voronoi"),
            (M("barycentric_not_voronoi", _H("barycentric")),),
        ),
        Task(
            "angle_defect", "array", 0, OPERATOR_CASES, _defect_calls, _defect,
            (M("missing_boundary_term", _defect_rule("2pi")),
             M("wrong_boundary_rule", _defect_rule("pi")),
             M("wrong_boundary_rule", _defect_rule("zero")),
             M("degrees", _defect_degrees),
             M("divided_by_area", _defect_density)),
        ),
        Task(
            "one_ring", "ring", 0, OPERATOR_CASES, _ring_calls, _ring,
            (M("wrong_orientation", _ring_cw), M("unordered", _ring_sorted)), generic=False,
        ),
        Task(
            "eigenbasis", "eigen", -2, CLOSED_CASES, _eig_calls, _eigen,
            (M("ordinary_eigenproblem", _eigen_ordinary),
             M("barycentric_not_voronoi", _eigen_bary),
             M("sign_flip", _eigen_negative),
             M("not_m_orthonormal", _eigen_euclid)),
            generic=False,
        ),
        Task(
            "spectral_reconstruction", "array", 1, CLOSED_CASES, _recon_calls, _recon,
            (M("projection_without_mass", _recon_no_mass),),
        ),
        Task(
            "explicit_step", "array", 1, STEP_CASES, _explicit_calls, _explicit(),
            (M("sign_flip", _explicit(-1.0)), M("transposed", _explicit(1.0, True))),
            generic=False,
        ),
        Task(
            "implicit_step", "array", 1, STEP_CASES, _implicit_calls, _implicit(),
            (M("sign_flip", _implicit(-1.0)), M("explicit_not_implicit", _implicit_as_explicit),
             M("missing_mass", _implicit(1.0, None)),
             M("barycentric_not_voronoi", _implicit(1.0, "barycentric"))),
            generic=False,
        ),
        Task(
            "taubin_step", "array", 1, STEP_CASES, _taubin_calls, _taubin(),
            (M("mu_sign", _taubin("mu_sign")), M("lambda_only", _taubin("lambda_only")),
             M("not_sequential", _taubin("not_sequential"))),
            generic=False,
        ),
        Task(
            "heat_geodesic", "array", 1, geo.HEAT_CASES, geo.heat_calls, geo.heat_reference,
            (M("gradient_not_normalised", geo.heat_unnormalised),
             M("time_not_scaled", geo.heat_time_not_scaled),
             M("divergence_sign", geo.heat_negated, geo.fits_negated),
             M("not_shifted", geo.heat_unshifted, geo.fits_shifted)),
            not_judged=geo.heat_not_judged,
        ),
    ]  # fmt: skip
    table = {t.name: t for t in tasks}
    if tuple(table) != EXERCISE_TASKS:  # the vocabulary in options and this table agree
        raise RuntimeError("exercise table and options.EXERCISE_TASKS differ")
    return table


TASKS: dict[str, Task] = _table()
"""Every exercise by name, in the order of :data:`~meshlap_core.options.EXERCISE_TASKS`."""
