"""Stability of smoothing: the operator parts ``W``, ``K`` of ``L = W⁻¹K``, its most negative
eigenvalue, the amplification factor ``g(μ)`` of each method, and the largest stable ``λ``.

Sign convention: ``L`` is negative semidefinite, its eigenvalues ``μ`` lie in ``[μ_min, 0]``;
explicit smoothing is stable iff ``λ ≤ 2/|μ_min|`` (see :mod:`meshlap_core.smoothing`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ..errors import MeshError
from ..laplacian import adjacency_matrix, cotan_stiffness, vertex_areas
from ..linalg.blas import blas_threads
from ..options import (
    AREA_KINDS,
    LAPLACIAN_KINDS,
    MASS_AREA,
    SMOOTHING_METHODS,
    AreaKind,
    LaplacianKind,
    SmoothingMethod,
    check_choice,
)
from ..types import FloatArray, IntArray, as_mesh
from .params import (
    DEFAULT_PASS_BAND,
    check_lam,
    resolve_nu,
    taubin_mu,
)


def operator_parts(
    V: FloatArray, F: IntArray, laplacian: LaplacianKind = "uniform", area: AreaKind = MASS_AREA
) -> tuple[FloatArray, sp.csr_matrix]:
    """The mass ``W`` and stiffness ``K`` of a Laplacian ``L = W⁻¹K`` (negative semidefinite).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    laplacian : {"uniform", "cotan"}
        ``uniform``: ``W = D`` (degrees), ``K = A − D``. ``cotan``: ``W`` the lumped areas of
        kind ``area``, ``K = C`` the cotangent stiffness (libigl ``cotmatrix``).
    area : {"voronoi", "barycentric"}
        Used by ``cotan`` only.

    Returns
    -------
    W : (n,) float
        ``>= 0``; zero for unreferenced vertices.
    K : (n,n) scipy.sparse.csr_matrix
        Symmetric, negative semidefinite, rows summing to 0.
    """
    V, F = as_mesh(V, F)
    check_choice(laplacian, LAPLACIAN_KINDS, "laplacian")
    check_choice(area, AREA_KINDS, "area")
    n = len(V)
    if laplacian == "uniform":
        A = adjacency_matrix(F, n)
        W = np.asarray(A.sum(axis=1), dtype=np.float64).ravel()
        K = (A - sp.diags(W)).tocsr()
    else:
        K = cotan_stiffness(V, F)
        W = vertex_areas(V, F, area)  # type: ignore[arg-type]
    K.sort_indices()
    return W, K


def gershgorin_mu_min(W: FloatArray, K: sp.csr_matrix, active: np.ndarray) -> float:
    """A lower bound on the eigenvalues of ``W⁻¹K``: ``−max_i Σ_j |K_ij| / W_i``."""
    if not active.any():
        return 0.0
    row_abs = np.asarray(abs(K).sum(axis=1)).ravel()
    return -float(np.max(row_abs[active] / W[active]))


def most_negative_eigenvalue(
    W: FloatArray, K: sp.csr_matrix, tol: float = 1e-6
) -> tuple[float, bool]:
    """Most negative eigenvalue ``μ_min`` of ``L = W⁻¹K`` (all eigenvalues lie in ``[μ_min, 0]``).

    Parameters
    ----------
    W : (n,) float
        Positive on active vertices; vertices with ``W = 0`` are left out (they never move).
    K : (n,n) sparse
        Symmetric negative semidefinite.
    tol : float
        Relative tolerance of the Lanczos iteration.

    Returns
    -------
    mu_min : float
        ``<= 0``.
    exact : bool
        ``False`` when Lanczos did not converge within its work budget (about ``3e8``
        multiply-adds, a second or two) and the Gershgorin bound ``−max_i Σ_j |K_ij| / W_i``
        (never above the true value) is returned instead.

    Notes
    -----
    ``W⁻¹K`` is similar to the symmetric ``W^{-1/2} K W^{-1/2}``, whose largest eigenvalue in
    magnitude ARPACK's Lanczos finds (``scipy.sparse.linalg.eigsh``).
    """
    W = np.asarray(W, dtype=np.float64)
    active = W > 0
    bound = gershgorin_mu_min(W, K, active)
    idx = np.flatnonzero(active)
    if len(idx) == 0:
        return 0.0, True
    S = _scaled_negative(K, W, idx)
    if len(idx) <= 400:
        with blas_threads(1):  # threaded BLAS collapses on small dense work under load
            ev = np.linalg.eigvalsh(S.toarray())
        return -float(max(ev[-1], 0.0)), True
    # bounded work: about 3e8 multiply-adds (a second or two whatever the mesh), then the
    # Gershgorin bound; a clustered top of the spectrum (a perfectly regular grid) can otherwise
    # keep ARPACK busy for minutes on a million vertices
    budget = max(50, int(_EIGEN_WORK // (S.nnz + 20 * len(idx))))
    calls = [0]

    def matvec(x: FloatArray) -> FloatArray:
        calls[0] += 1
        if calls[0] > budget:
            raise _OverBudget
        return S @ x

    op = sla.LinearOperator(S.shape, matvec=matvec, dtype=np.float64)
    try:
        ev = sla.eigsh(
            op, k=1, which="LA", tol=tol, return_eigenvectors=False, maxiter=20 * len(idx)
        )
    except (sla.ArpackNoConvergence, _OverBudget):
        return bound, False
    return -float(max(ev[0], 0.0)), True


def _scaled_negative(K: sp.csr_matrix, W: FloatArray, idx: np.ndarray) -> sp.csr_matrix:
    """``S = W^{-1/2} (−K) W^{-1/2}`` on the rows and columns ``idx`` (CSR, sorted indices).

    Each entry is ``(s_i · (−K_ij)) · s_j`` with ``s = W^{-1/2}``, scaled in the stored entries of
    ``K`` (one new data array; the index arrays are ``K``'s when every vertex is active), where
    ``diags(s) @ (−K) @ diags(s)`` made three copies of the matrix: 0.7 GB at 2.77M vertices.
    """
    s = 1.0 / np.sqrt(W[idx])
    Ka = sp.csr_matrix(K) if len(idx) == K.shape[0] else sp.csr_matrix(K)[idx][:, idx]
    if not Ka.has_sorted_indices:
        Ka = Ka.sorted_indices()  # a copy: the caller's K is left as it is
    data = -Ka.data
    data *= np.repeat(s, np.diff(Ka.indptr))  # s_i, row by row
    data *= s[Ka.indices]
    return sp.csr_matrix((data, Ka.indices, Ka.indptr), shape=Ka.shape)


_EIGEN_WORK = 3e8  # multiply-adds most_negative_eigenvalue may spend before giving the bound


class _OverBudget(Exception):
    """The eigensolver used up its work budget."""


def amplification_curve(
    method: SmoothingMethod,
    lam: float,
    mu: Any,
    *,
    taubin_nu: float | None = None,
    k_pb: float = DEFAULT_PASS_BAND,
) -> FloatArray:
    """Amplification factor ``g(μ)`` of one iteration on the eigenmode with eigenvalue ``μ ≤ 0``.

    Parameters
    ----------
    method : {"explicit", "implicit", "taubin"}
    lam : float
        Step ``λ > 0``.
    mu : array_like of float
        Eigenvalues of the (negative semidefinite) Laplacian, all ``<= 0``.
    taubin_nu : float, optional
        Taubin's negative factor; default :func:`taubin_mu` ``(lam, k_pb)``.
    k_pb : float
        Taubin's pass-band frequency (eigenvalue units) when ``taubin_nu`` is not given.

    Returns
    -------
    g : ndarray of float, the shape of ``mu``
        explicit ``1 + λμ``; implicit ``1 / (1 − λμ)``; taubin ``(1 + λμ)(1 + νμ)``. A mode is
        amplified when ``|g| > 1`` and changes sign each step when ``g < 0``.
    """
    check_choice(method, SMOOTHING_METHODS, "method")
    lam = check_lam(lam)
    m = np.asarray(mu, dtype=np.float64)
    if not np.isfinite(m).all():
        raise MeshError("eigenvalues must be finite", "mu")
    if (m > 1e-12 * max(1.0, float(np.abs(m).max(initial=0.0)))).any():
        raise MeshError("eigenvalues of a negative semidefinite Laplacian must be <= 0", "mu")
    m = np.minimum(m, 0.0)
    if method == "explicit":
        return 1.0 + lam * m
    if method == "implicit":
        return 1.0 / (1.0 - lam * m)
    nu = taubin_mu(lam, k_pb) if taubin_nu is None else float(taubin_nu)
    return (1.0 + lam * m) * (1.0 + nu * m)


@dataclass(frozen=True)
class Stability:
    """Stability figures of one smoothing iteration on one mesh.

    Attributes
    ----------
    method, laplacian : str
    lam : float
    taubin_nu : float or None
        Taubin's second factor (``None`` for the other methods).
    mu_min : float
        Most negative eigenvalue of ``L`` (``<= 0``); the highest frequency is ``−mu_min``.
    mu_min_exact : bool
        ``False`` if only the Gershgorin bound (more negative than the truth) is known.
    explicit_lam_limit : float
        Largest stable explicit ``λ = 2 / |μ_min|`` for this mesh and Laplacian.
    max_stable_lam : float or None
        Largest stable ``λ`` of this method (``None``: unconditionally stable, i.e. implicit; for
        Taubin the largest ``λ`` with the same pass band such that ``g(μ_min) >= −1``).
    spectral_radius : float
        ``max |g(μ)|`` over ``μ ∈ [μ_min, 0]``: the spectral radius of the iteration matrix
        (1 for explicit/implicit when stable; slightly above 1 for Taubin, whose pass band is
        amplified on purpose).
    high_freq_gain : float
        ``g(μ_min)``, the factor applied to the highest-frequency mode (negative: it flips sign
        every step).
    stable : bool
        No mode above the pass band grows: ``|g(μ_min)| <= 1``.
    """

    method: str
    laplacian: str
    lam: float
    taubin_nu: float | None
    mu_min: float
    mu_min_exact: bool
    explicit_lam_limit: float
    max_stable_lam: float | None
    spectral_radius: float
    high_freq_gain: float
    stable: bool

    def as_dict(self) -> dict[str, Any]:
        """Plain dict (for JSON)."""
        return asdict(self)

    def message(self) -> str | None:
        """A warning sentence when the iteration is unstable, else ``None``."""
        if self.stable:
            return None
        limit = (
            ""
            if self.max_stable_lam is None
            else f" (largest stable lam {self.max_stable_lam:.4g})"
        )
        return (
            f"{self.method} smoothing with lam={self.lam:g} is unstable on this mesh{limit}: "
            f"the highest-frequency mode is multiplied by {self.high_freq_gain:.4g} per iteration "
            "and will blow up; use a smaller lam or the implicit method"
        )


def _taubin_gain(lam: float, nu: float, mu: float) -> float:
    return (1.0 + lam * mu) * (1.0 + nu * mu)


def stability_from_mu(
    method: str,
    laplacian: str,
    lam: float,
    nu: float | None,
    mu_min: float,
    exact: bool,
    k_pb: float,
) -> Stability:
    """The stability of ``method`` with step ``lam`` (and Taubin's ``nu``) given ``mu_min``, the
    most negative eigenvalue of ``W⁻¹K`` (``exact``: computed, not bounded)."""
    k = -mu_min
    explicit_limit = 2.0 / k if k > 0 else math.inf
    if method == "explicit":
        gain = 1.0 + lam * mu_min
        radius = max(1.0, abs(gain))
        max_lam: float | None = explicit_limit
        stable = abs(gain) <= 1.0 + 1e-12
    elif method == "implicit":
        gain = 1.0 / (1.0 - lam * mu_min)
        radius, max_lam, stable = 1.0, None, True
    else:
        if nu is None:
            nu = taubin_mu(lam, k_pb)
        gain = _taubin_gain(lam, nu, mu_min)
        kpb = 1.0 / lam + 1.0 / nu
        if not kpb > 0:  # 1/lam + 1/nu cancelled to 0 (k_pb far below 1/lam): use the known one
            kpb = k_pb
        candidates = [1.0, abs(gain)]
        if 0 < kpb / 2 < k:  # the parabola's peak (the amplified pass band)
            candidates.append(abs(_taubin_gain(lam, nu, -kpb / 2)))
        radius = max(candidates)
        stable = gain >= -1.0 - 1e-12
        max_lam = _taubin_max_lam(k, kpb) if k > 0 else None
    return Stability(
        method=method,
        laplacian=laplacian,
        lam=lam,
        taubin_nu=nu,
        mu_min=mu_min,
        mu_min_exact=exact,
        explicit_lam_limit=explicit_limit,
        max_stable_lam=max_lam,
        spectral_radius=radius,
        high_freq_gain=gain,
        stable=stable,
    )


def _taubin_max_lam(k: float, kpb: float) -> float | None:
    """Largest ``λ < 1/k_PB`` with ``(1 − λk)(1 − ν(λ)k) >= −1`` (bisection; monotone in λ)."""

    def h(lam: float) -> float:
        nu = 1.0 / (kpb - 1.0 / lam)
        return _taubin_gain(lam, nu, -k) + 1.0

    if not kpb > 0 or not math.isfinite(1.0 / kpb):
        return None
    hi = (1.0 / kpb) * (1 - 1e-9)
    if h(hi) >= 0:
        return None
    lo = min(1.0 / k, hi) * 1e-3
    if h(lo) < 0:
        return lo
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if h(mid) >= 0:
            lo = mid
        else:
            hi = mid
    return lo


def stability(
    V: FloatArray,
    F: IntArray,
    method: SmoothingMethod = "explicit",
    laplacian: LaplacianKind = "uniform",
    lam: float = 0.5,
    *,
    taubin_nu: float | None = None,
    pass_band: float = DEFAULT_PASS_BAND,
    area: AreaKind = MASS_AREA,
) -> Stability:
    """Stability figures of ``method`` with step ``lam`` on the mesh ``(V, F)``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    method : {"explicit", "implicit", "taubin"}
    laplacian : {"uniform", "cotan"}
        ``L = W⁻¹K``, negative semidefinite (see :func:`operator_parts`).
    lam : float
    taubin_nu : float, optional
        Taubin's negative factor (default from ``pass_band``).
    pass_band : float
        Taubin's pass band relative to the mesh: ``k_PB = pass_band × mean_i(−L_ii)`` (exactly
        ``pass_band`` for the uniform Laplacian, whose diagonal is −1).
    area : {"voronoi", "barycentric"}

    Returns
    -------
    Stability

    Notes
    -----
    Explicit: ``ρ(I + λL) = max(1, |1 + λμ_min|)``, stable iff ``λ <= 2/|μ_min|``. With fixed
    (boundary) vertices the iteration acts on a principal submatrix, whose eigenvalues lie in
    ``[μ_min, 0]`` too (Cauchy interlacing), so the figures here are on the safe side.
    """
    V, F = as_mesh(V, F)
    check_choice(method, SMOOTHING_METHODS, "method")
    lam = check_lam(lam)
    W, K = operator_parts(V, F, laplacian, area)
    k_pb = check_lam(pass_band, "pass_band") * diagonal_scale(W, K)
    nu = resolve_nu(method, lam, taubin_nu, k_pb)
    mu_min, exact = most_negative_eigenvalue(W, K)
    return stability_from_mu(method, laplacian, lam, nu, mu_min, exact, k_pb)


def diagonal_scale(W: FloatArray, K: sp.csr_matrix) -> float:
    """``mean_i(−L_ii) = mean_i(−K_ii / W_i)`` over active vertices: 1 for the uniform Laplacian,
    a typical squared inverse edge length for the cotan one."""
    active = W > 0
    if not active.any():
        return 1.0
    return float(np.mean(-K.diagonal()[active] / W[active]))


ILL_CONDITIONED = 1e10
"""Implicit smoothing warns when ``λ · max_i(−L_ii)`` exceeds this: its solve may then lose
more than about 7 of 16 digits."""


def ill_conditioning(lam: float, stiff: float) -> str | None:
    """The warning for implicit smoothing with ``λ`` on a mesh whose stiffest vertex has
    ``−L_ii = stiff``, or ``None`` when ``λ · stiff`` is at most :data:`ILL_CONDITIONED`.

    The condition number of ``W⁻¹(W − λK)`` is ``1 + λ|μ_min| ≈ 1 + 2λ max_i(−L_ii)``; the
    weighted centroid ``Σ W_i x_i``, which an exact implicit step conserves, was measured to
    drift by about ``2e-17 · λ max(−L_ii)`` relative on spheres (2e-5 at 1e12, 1e-3 at 1e14,
    20–50 % at 5e15: a silently wrong mesh without this warning).
    """
    x = lam * stiff
    if not x > ILL_CONDITIONED:
        return None
    return (
        f"implicit smoothing with lam={lam:g} is ill-conditioned on this mesh: "
        f"lam times the stiffest vertex's -L_ii = {stiff:.3g} is {x:.3g} > "
        f"{ILL_CONDITIONED:.0e}, so the result may carry relative errors of order "
        f"{x:.0e} x 1e-16; lam below {ILL_CONDITIONED / stiff:.3g} already collapses "
        "the mesh to a point in a few steps"
    )
