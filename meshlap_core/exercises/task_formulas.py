"""The references and the classic mistakes of the per-vertex, spectral and smoothing exercises,
each written as the answer it gives for one call ``(case, args)`` (:mod:`.tasks` declares which
task uses which).

Every reference comes from the core (``laplacian``, ``curvature``, ``topology.rings``,
``spectral``): the exercises check a student against the code the rest of the lab is tested
with. Conventions are the project's: Laplacians negative semidefinite (``Δx = −2Hn``),
``K = −C``, the generalized eigenproblem ``K u = λ M u`` with the mixed Voronoi mass,
``UᵀMU = I``. A mistake's wrong answer is ``None`` where it makes no difference.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import curvature as cv
from .. import laplacian as lap
from ..options import BOUNDARY_RULES, MASS_AREA
from ..spectral.operators import laplacian_eigenpairs, spectral_operators
from ..topology.rings import one_ring
from .meshes import Case

Output = Any
Args = tuple[Any, ...]
Formula = Callable[[Case, Args], Output]


def vf_calls(case: Case) -> list[tuple[str, Args]]:
    """One call ``f(V, F)``."""
    return [("", (case.V.copy(), case.F.copy()))]


def _inv(a: np.ndarray) -> np.ndarray:
    return np.divide(1.0, a, out=np.zeros_like(a), where=a > 0)


# ---- operators -----------------------------------------------------------------------------


def uniform(case: Case, args: Args) -> sp.csr_matrix:
    return lap.uniform_laplacian(case.F, len(case.V))


def graph(case: Case, args: Args) -> sp.csr_matrix:
    """``A − D``: the graph Laplacian not normalised by the degree."""
    A = lap.adjacency_matrix(case.F, len(case.V))
    return (A - sp.diags(np.asarray(A.sum(axis=1)).ravel())).tocsr()


def cotan(case: Case, args: Args) -> sp.csr_matrix:
    return lap.cotan_stiffness(case.V, case.F)


def _reweighted(case: Case, weight: Callable[[sp.csr_matrix], sp.csr_matrix]) -> sp.csr_matrix:
    C = cotan(case, ()).tolil()
    C.setdiag(0)
    W = weight(C.tocsr())
    return (W - sp.diags(np.asarray(W.sum(axis=1)).ravel())).tocsr()


def cotan_abs(case: Case, args: Args) -> sp.csr_matrix:
    """Cot weights made positive (``abs``): a non-Delaunay edge's negative weight lost."""
    return _reweighted(case, abs)


def cotan_clamped(case: Case, args: Args) -> sp.csr_matrix:
    """Cot weights clamped at 0 (``max(w, 0)``)."""
    return _reweighted(case, lambda W: W.maximum(0))


def cotan_corners_abs(case: Case, args: Args) -> sp.csr_matrix:
    """Each corner's cot made positive before the two of an edge are summed (the same mistake
    as :func:`cotan_abs`, written per triangle)."""
    half = 0.5 * np.abs(lap.cotangents_intrinsic(lap.squared_edge_lengths(case.V, case.F)))
    F = case.F
    i = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])  # the edge opposite corner k
    j = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    w = half.T.ravel()
    rows, cols = np.concatenate([i, j, i, j]), np.concatenate([j, i, i, j])
    n = len(case.V)
    return sp.coo_matrix((np.concatenate([w, w, -w, -w]), (rows, cols)), shape=(n, n)).tocsr()


def row_normalised(case: Case, args: Args) -> sp.csr_matrix:
    C = cotan(case, args)
    return (sp.diags(_inv(-C.diagonal())) @ C).tocsr()


def areas(kind: str) -> Formula:
    return lambda case, args: lap.vertex_areas(case.V, case.F, kind)


def circumcentric_areas(case: Case, args: Args) -> np.ndarray:
    """Pure Voronoi cells ``⅛ Σ (l_ij² cot θ_k)`` without Meyer's obtuse-triangle rule."""
    l2 = lap.squared_edge_lengths(case.V, case.F)
    cot = lap.cotangents_intrinsic(l2)
    F = case.F
    a = np.zeros(len(case.V))
    for c in range(3):  # corner c: its two edges are opposite corners c+1 and c+2
        j, k = (c + 1) % 3, (c + 2) % 3
        np.add.at(a, F[:, c], (l2[:, j] * cot[:, j] + l2[:, k] * cot[:, k]) / 8.0)
    return a


def mass(kind: str) -> Formula:
    return lambda case, args: lap.mass_matrix(case.V, case.F, kind)


def hn(area: str) -> Formula:
    def f(case: Case, args: Args) -> np.ndarray:
        w = lap.vertex_areas(case.V, case.F, area)
        return -0.5 * _inv(w)[:, None] * (cotan(case, args) @ case.V)

    return f


def hn_without_mass(case: Case, args: Args) -> np.ndarray:
    return -0.5 * (cotan(case, args) @ case.V)


def hn_uniform(case: Case, args: Args) -> np.ndarray:
    return -0.5 * (uniform(case, args) @ case.V)


def mean_curvature(area: str) -> Formula:
    return lambda case, args: cv.mean_curvature_cotan(case.V, case.F, area)


def divided_by_area(case: Case, args: Args) -> sp.csr_matrix:
    return lap.laplace_beltrami(case.V, case.F, MASS_AREA)


# ---- angle defect --------------------------------------------------------------------------


def defect_calls(case: Case) -> list[tuple[str, Args]]:
    """One call per boundary rule, ``f(V, F, rule)``."""
    return [(f"boundary={b}", (case.V.copy(), case.F.copy(), b)) for b in BOUNDARY_RULES]


def defect(case: Case, args: Args) -> np.ndarray:
    return cv.angle_deficit(case.V, case.F, args[2])


def defect_rule(rule: str) -> Formula:
    """The rule ``rule`` applied whatever the argument."""

    def f(case: Case, args: Args) -> np.ndarray | None:
        return None if args[2] == rule else cv.angle_deficit(case.V, case.F, rule)

    return f


def defect_degrees(case: Case, args: Args) -> np.ndarray:
    return np.degrees(defect(case, args))


def defect_density(case: Case, args: Args) -> np.ndarray:
    return cv.gaussian_curvature(case.V, case.F, "barycentric", args[2])


# ---- one-ring ------------------------------------------------------------------------------


def ring_calls(case: Case) -> list[tuple[str, Args]]:
    """One call ``f(F, n)``."""
    return [("", (case.F.copy(), len(case.V)))]


def ring(case: Case, args: Args) -> list[np.ndarray]:
    r = one_ring(case.F, len(case.V))
    return [np.asarray(r[i]) for i in range(len(r))]


def ring_cw(case: Case, args: Args) -> list[np.ndarray]:
    r = one_ring(case.F, len(case.V)).reversed()
    return [np.asarray(r[i]) for i in range(len(r))]


def ring_sorted(case: Case, args: Args) -> list[np.ndarray]:
    return [np.sort(x) for x in ring(case, args)]


# ---- spectral ------------------------------------------------------------------------------

EIGEN_K = 6
DENSE_EIGEN_MAX = 600
"""Up to this many vertices the eigenpairs (the reference's and the mistakes') are dense; above
(the large and huge meshes, the viewer's) they come from the lab's sparse solver."""


def eig_calls(case: Case) -> list[tuple[str, Args]]:
    """One call ``f(V, F, k)``."""
    k = min(EIGEN_K, len(case.V))
    return [(f"k={k}", (case.V.copy(), case.F.copy(), k))]


def _pairs(case: Case, k: int, m: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` smallest pairs of ``K u = λ diag(m) u`` (``m`` None: the mixed Voronoi mass)."""
    K, voronoi = spectral_operators(case.V, case.F, "cotan", MASS_AREA)
    m = voronoi if m is None else m
    if len(case.V) <= DENSE_EIGEN_MAX:
        lam, U = sla.eigh(K.toarray(), np.diag(m))
        return lam[:k], U[:, :k]
    lam, U, _ = laplacian_eigenpairs(case.V, case.F, k, pencil=(K, m))
    return np.asarray(lam), np.asarray(U)


def eigen(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    """The ``k = args[2]`` smallest pairs of ``K u = λ M u`` (``K = −C``, mixed Voronoi ``M``)."""
    return _pairs(case, args[2], None)


def eigen_ordinary(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    return _pairs(case, args[2], np.ones(len(case.V)))


def eigen_bary(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    return _pairs(case, args[2], lap.vertex_areas(case.V, case.F, "barycentric"))


def eigen_negative(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    lam, U = eigen(case, args)
    return -lam, U


def eigen_euclid(case: Case, args: Args) -> tuple[np.ndarray, np.ndarray]:
    lam, U = eigen(case, args)
    return lam, U / np.linalg.norm(U, axis=0)


RECON_K = 10


def recon_calls(case: Case) -> list[tuple[str, Args]]:
    """One call ``f(X, U, M)`` with the reference's ``RECON_K`` eigenvectors."""
    k = min(RECON_K, len(case.V))
    _, U = eigen(case, (case.V, case.F, k))
    M = lap.mass_matrix(case.V, case.F, MASS_AREA)
    return [(f"k={k}", (case.V.copy(), U, M))]


def recon(case: Case, args: Args) -> np.ndarray:
    X, U, M = args
    return U @ (U.T @ (M @ X))


def recon_without_mass(case: Case, args: Args) -> np.ndarray:
    X, U, _ = args
    return U @ (U.T @ X)


# ---- smoothing steps -----------------------------------------------------------------------

STEP_LAM = 0.4
TAUBIN_MU = -0.42


def explicit_calls(case: Case) -> list[tuple[str, Args]]:
    """One call ``f(V, F, λ)``."""
    return [(f"lam={STEP_LAM}", (case.V.copy(), case.F.copy(), STEP_LAM))]


def explicit(sign: float = 1.0, transpose: bool = False) -> Formula:
    def f(case: Case, args: Args) -> np.ndarray:
        L = uniform(case, args)
        L = L.T if transpose else L
        return case.V + sign * args[2] * (L @ case.V)

    return f


def implicit_calls(case: Case) -> list[tuple[str, Args]]:
    """One call ``f(V, F, λ)`` with ``λ = h²/2`` (units of length² for the cotan Laplacian)."""
    lam = 0.5 * case.scale**2
    return [("lam=h²/2", (case.V.copy(), case.F.copy(), lam))]


def implicit(sign: float = 1.0, area: str | None = MASS_AREA) -> Formula:
    def f(case: Case, args: Args) -> np.ndarray:
        C = cotan(case, args)
        n = len(case.V)
        M = lap.mass_matrix(case.V, case.F, area) if area else sp.identity(n, format="csr")
        A = (M - sign * args[2] * C).tocsc()
        return spla.spsolve(A, M @ case.V)

    return f


def implicit_as_explicit(case: Case, args: Args) -> np.ndarray:
    return case.V + args[2] * (lap.laplace_beltrami(case.V, case.F, MASS_AREA) @ case.V)


def taubin_calls(case: Case) -> list[tuple[str, Args]]:
    """One call ``f(V, F, λ, μ)``."""
    return [("lam,mu", (case.V.copy(), case.F.copy(), STEP_LAM, TAUBIN_MU))]


def taubin(variant: str = "") -> Formula:
    def f(case: Case, args: Args) -> np.ndarray:
        L = uniform(case, args)
        V, lam, mu = case.V, args[2], args[3]
        V1 = V + lam * (L @ V)
        if variant == "lambda_only":
            return V1
        if variant == "not_sequential":
            return V1 + mu * (L @ V)
        return V1 + (-mu if variant == "mu_sign" else mu) * (L @ V1)

    return f
