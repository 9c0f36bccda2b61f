"""The heat equation ``u_t = Δu`` on a mesh, two ways: backward Euler and the eigen-expansion.

``Δ = M⁻¹C`` is the cotangent Laplace–Beltrami operator (negative semidefinite; ``C`` the
cotangent stiffness, ``M`` the lumped Voronoi mass). Writing ``K = −C`` (positive
semidefinite), the exact semi-discrete solution is ``u(t) = exp(−t M⁻¹K) u₀``.

* Backward Euler, ``N`` steps of ``τ = t/N``: ``(M + τK) u_{j+1} = M u_j`` (unconditionally
  stable, first order in ``τ``; each mode is damped by ``(1 + τλ)^−N`` instead of
  ``e^{−λt}``). The matrix is factorized once per ``τ`` and reused for every step and source.
* Eigen-expansion over ``k`` modes of ``K φ = λ M φ`` (``M``-orthonormal ``φ``):
  ``u(t) ≈ Σ_{i<k} e^{−λ_i t} φ_i φ_iᵀ M u₀``. With ``u₀`` a unit of heat at ``s``
  (``e_s / m_s``), ``φ_iᵀ M u₀ = φ_i(s)``. Every omitted mode is damped by at least
  ``e^{−λ_{k−1} t}`` (:func:`truncation_bound`): the expansion is exact for the full basis.

References
----------
Crane, Weischedel & Wardetzky, "Geodesics in heat", ACM TOG 2013 (the backward Euler step).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import expm_multiply

from ..errors import MeshError
from ..linalg.spd import SPDSolver
from ..options import MASS_AREA, MAX_HEAT_STEPS, MAX_STIFFNESS_RATIO, AreaKind
from ..spectral.basis import SpectralBasis
from ..spectral.operators import spectral_operators
from ..types import (
    FloatArray,
    IntArray,
    as_count,
    as_field,
    as_index,
    as_mesh,
    as_real,
    real_array,
)


def check_time(t: float, name: str = "t") -> float:
    """``t`` as a positive finite float, else :class:`MeshError` naming ``name`` (booleans,
    complex numbers and strings refused, not converted)."""
    try:
        return as_real(t, name, positive=True)
    except MeshError as exc:
        raise MeshError(
            f"must be a positive finite time, got {t!r} ({exc.problem})", name
        ) from None


class HeatDiffusion:
    """Backward Euler heat flow on one mesh: operators built once, one factorization per step.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    area : {"voronoi", "barycentric"}
        The lumped mass ``M``.

    Attributes
    ----------
    K : (n,n) scipy.sparse.csr_matrix
        ``−C``, symmetric positive semidefinite.
    mass : (n,) float
        The diagonal of ``M`` (positive).

    Raises
    ------
    MeshError
        No faces, or a vertex of zero area (see :func:`spectral_operators`).

    Examples
    --------
    Backward Euler conserves the total heat ``Σ M_ii u_i`` and converges to the exact
    ``exp(−t M⁻¹K) u₀`` at first order (half the step, half the error):

    >>> import numpy as np
    >>> from meshlap_core import HeatDiffusion, icosphere
    >>> V, F = icosphere(2)
    >>> heat = HeatDiffusion(V, F)
    >>> u0 = np.zeros(len(V))
    >>> u0[0] = 1 / heat.mass[0]  # one unit of heat at vertex 0
    >>> u = heat.euler(u0, t=0.1, steps=10)
    >>> round(float(heat.mass @ u), 12), int(u.argmax())
    (1.0, 0)
    >>> exact = heat.exact(u0, 0.1)
    >>> errors = [np.abs(heat.euler(u0, 0.1, steps=s) - exact).max() for s in (10, 20, 40)]
    >>> [round(float(a / b), 1) for a, b in zip(errors, errors[1:])]
    [2.1, 2.1]
    """

    def __init__(self, V: FloatArray, F: IntArray, area: AreaKind = MASS_AREA) -> None:
        self.V, self.F = as_mesh(V, F)
        self.K, self.mass = spectral_operators(self.V, self.F, "cotan", area)
        self._solvers: dict[float, SPDSolver] = {}

    @property
    def n_vertices(self) -> int:
        return len(self.mass)

    def _solver(self, tau: float) -> SPDSolver:
        solver = self._solvers.get(tau)
        if solver is None:
            # τ·max(K_ii/m_i) bounds τ λ_max: beyond 1e14 the mass is round-off of τK and the
            # constant mode (the total heat) is lost
            top = float(np.max(self.K.diagonal() / self.mass)) if len(self.mass) else 0.0
            if tau * top > MAX_STIFFNESS_RATIO:
                raise MeshError(
                    f"the step {tau:.3g} is too long for this mesh's scale (M + τK is singular "
                    f"in double precision); use t/steps below {MAX_STIFFNESS_RATIO / top:.3g}",
                    "t",
                )
            if len(self._solvers) >= 4:  # a slider sweeps many τ: keep only the latest few
                self._solvers.pop(next(iter(self._solvers)))
            A = (sp.diags(self.mass) + tau * self.K).tocsr()
            solver = self._solvers[tau] = SPDSolver(A)
        return solver

    def euler(self, u0: FloatArray, t: float, steps: int = 1) -> FloatArray:
        """``steps`` backward Euler steps of ``τ = t/steps``: ``(M + τK) u_{j+1} = M u_j``.

        Parameters
        ----------
        u0 : (n,) or (n,c) float
        t : float
            ``> 0``.
        steps : int
            ``1 … MAX_HEAT_STEPS`` (1000).

        Returns
        -------
        u : same shape as ``u0``
        """
        t = check_time(t)
        steps = as_count(steps, "steps", 1, MAX_HEAT_STEPS)
        u = as_field(u0, self.n_vertices, "u0")
        solver = self._solver(t / steps)
        m = self.mass if u.ndim == 1 else self.mass[:, None]
        for _ in range(steps):
            u = solver.solve(m * u)
        return u

    def exact(self, u0: FloatArray, t: float) -> FloatArray:
        """The reference ``exp(−t M⁻¹K) u₀`` by :func:`scipy.sparse.linalg.expm_multiply`
        (Al-Mohy & Higham 2011); slow on big meshes, for tests and error maps.

        Parameters
        ----------
        u0 : (n,) float
        t : float

        Returns
        -------
        u : (n,) float
        """
        t = check_time(t)
        u = as_field(u0, self.n_vertices, "u0", columns=False)
        A = (sp.diags(1.0 / self.mass) @ self.K).tocsr()
        return np.asarray(expm_multiply(-t * A, u))


def truncation_bound(eigenvalues: FloatArray, t: float, k: int) -> float:
    """``e^{−λ_{k−1} t}``: the largest factor by which an omitted mode ``i ≥ k`` survives
    (the eigenvalues ascend, so ``λ_i ≥ λ_{k−1}``). A bound on each omitted mode's weight,
    not the error itself (with the full basis nothing is omitted and the error is 0).

    Parameters
    ----------
    eigenvalues : (k_max,) float
        Ascending frequencies of ``−Δ``.
    t : float
    k : int
        Modes used, ``1 <= k <= k_max``.
    """
    lam = check_eigenvalues(eigenvalues)
    k = as_count(k, "k", 1, len(lam))
    return float(np.exp(-float(lam[k - 1]) * check_time(t)))


def check_eigenvalues(eigenvalues: Any) -> FloatArray:
    """Frequencies as a finite real ``(k,)`` array (``k ≥ 1``), named ``eigenvalues``."""
    lam = real_array(eigenvalues, "eigenvalues", "eigenvalues")
    if lam.ndim != 1 or lam.size == 0:
        raise MeshError(f"should have shape (k,), k >= 1; shape is {lam.shape}", "eigenvalues")
    return as_field(lam, len(lam), "eigenvalues", columns=False)


def check_modes(basis: SpectralBasis, k: Any) -> int:
    """``k`` (``None``: all) checked against the basis's computed modes."""
    if not isinstance(basis, SpectralBasis):
        raise MeshError(f"must be a SpectralBasis, got {type(basis).__name__}", "basis")
    return basis.k_max if k is None else as_count(k, "k", 1, basis.k_max)


def heat_spectral(
    basis: SpectralBasis, u0: FloatArray, t: float, k: int | None = None
) -> FloatArray:
    """The eigen-expansion ``Σ_{i<k} e^{−λ_i t} φ_i φ_iᵀ M u₀`` over a computed basis.

    Parameters
    ----------
    basis : SpectralBasis
        Cotangent Laplacian with the mass ``M`` the heat uses.
    u0 : (n,) float
    t : float
        ``> 0``.
    k : int, optional
        Modes used (default all of the basis).

    Returns
    -------
    u : (n,) float

    Examples
    --------
    With enough modes the eigen-expansion matches the exact heat:

    >>> import numpy as np
    >>> from meshlap_core import HeatDiffusion, SpectralBasis, heat_spectral, icosphere
    >>> V, F = icosphere(2)
    >>> basis = SpectralBasis.compute(V, F, 60, cache=False)
    >>> heat = HeatDiffusion(V, F)
    >>> u0 = np.zeros(len(V))
    >>> u0[0] = 1 / heat.mass[0]
    >>> u = heat_spectral(basis, u0, t=0.5)
    >>> bool(np.abs(u - heat.exact(u0, 0.5)).max() < 1e-6), round(float(heat.mass @ u), 9)
    (True, 1.0)
    """
    t = check_time(t)
    k = check_modes(basis, k)
    u = as_field(u0, len(basis.mass), "u0", columns=False)
    U = basis.vectors[:, :k]
    lam = basis.eigenvalues[:k]
    c = U.T @ (basis.mass * u)
    return U @ (np.exp(-lam * t) * c)


def heat_kernel_column(
    basis: SpectralBasis, source: int, t: float, k: int | None = None
) -> FloatArray:
    """``k_t(·, s) = Σ_{i<k} e^{−λ_i t} φ_i φ_i(s)``: heat at time ``t`` from a unit at ``s``.

    Parameters
    ----------
    basis : SpectralBasis
    source : int
    t : float
    k : int, optional

    Returns
    -------
    u : (n,) float
    """
    k = check_modes(basis, k)
    s = as_index(source, len(basis.mass), "source")
    U = basis.vectors[:, :k]
    return U @ (np.exp(-basis.eigenvalues[:k] * check_time(t)) * U[s])
