"""Laplacian smoothing: explicit, implicit and Taubin steppers, stability, denoising sweeps.

Sign convention (the whole project uses it): every Laplacian is **negative semidefinite**. Here
a Laplacian is always written ``L = W⁻¹ K`` with ``W`` a positive diagonal "mass" and ``K`` a
symmetric negative semidefinite "stiffness":

* ``uniform``: ``W = D`` (vertex degrees), ``K = A − D`` (adjacency minus degrees), so
  ``L = D⁻¹A − I`` (:func:`meshlap_core.laplacian.uniform_laplacian`, the course formula);
* ``cotan``: ``W = M`` (lumped Voronoi or barycentric areas), ``K = C`` (cotangent stiffness),
  so ``L = M⁻¹C`` is the Laplace–Beltrami operator (``Lx = −2Hn``).

Its eigenvalues ``μ`` are real and ``≤ 0`` (the frequencies shown to users are ``−μ ≥ 0``).

Methods (one iteration each):

* explicit (diffusion flow, forward Euler): ``x′ = x + λ L x``; amplification per mode
  ``g(μ) = 1 + λμ``, stable iff ``λ ≤ 2 / |μ_min|``;
* implicit (backward Euler, Desbrun et al. 1999): ``(I − λL) x′ = x``, solved in the symmetric
  positive definite form ``(W − λK) x′ = W x``; for the uniform Laplacian that is
  ``((1+λ)D − λA) x′ = D x``. ``g(μ) = 1 / (1 − λμ)``: unconditionally stable;
* Taubin λ|μ (Taubin 1995): an explicit step with ``λ > 0`` then one with ``ν < −λ``
  (``1/λ + 1/ν = k_PB``, the pass-band frequency); ``g(μ) = (1 + λμ)(1 + νμ)``. It barely
  shrinks, because ``g ≈ 1`` at low frequencies.

:class:`Smoother` is the stepper (the implicit system is factorized once with a sparse Cholesky
factorization and reused for every step while ``λ`` and the operator are unchanged);
:func:`smooth` is the one-shot wrapper, :func:`stability` and :func:`amplification_curve` give
the stability numbers, :func:`denoise_sweep` the evaluation table.

References
----------
Desbrun, Meyer, Schröder & Barr, "Implicit fairing of irregular meshes using diffusion and
curvature flow", SIGGRAPH 1999.
Taubin, "A signal processing approach to fair surface design", SIGGRAPH 1995.
Kazhdan, Solomon & Ben-Chen, "Can mean-curvature flow be modified to be non-singular?",
SGP 2012 (stiffness frozen, mass recomputed).
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import sys
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .errors import MeshError, MeshWarning
from .laplacian import adjacency_matrix, cotan_stiffness, vertex_areas
from .linalg.blas import blas_threads
from .metrics import Reference, _signed_volume_unchecked, n_boundary_edges, percent_volume_change
from .noise import NOISE_MODES, add_noise, bbox_diagonal
from .options import AREA_KINDS, LAPLACIAN_KINDS, MASS_AREA, AreaKind, LaplacianKind
from .topology import boundary_vertex_mask
from .types import FloatArray, IntArray, as_mesh, as_vertices

Method = Literal["explicit", "implicit", "taubin"]
MassMode = Literal["frozen", "recompute"]
METHODS: tuple[str, ...] = ("explicit", "implicit", "taubin")
LAPLACIANS = LAPLACIAN_KINDS  # the name this module's callers use
MASS_MODES: tuple[str, ...] = ("frozen", "recompute")

DEFAULT_PASS_BAND = 0.1  # Taubin's k_PB, in the units of the Laplacian's eigenvalues


# --------------------------------------------------------------------------- argument checks


def check_lam(lam: Any, name: str = "lam") -> float:
    """Return ``lam`` as a float, or raise MeshError naming ``name`` unless it is finite and > 0."""
    try:
        value = float(lam)
    except (TypeError, ValueError):
        raise MeshError(f"must be a number > 0, got {lam!r}", name) from None
    if not math.isfinite(value) or value <= 0:
        raise MeshError(f"must be a finite number > 0, got {lam!r}", name)
    return value


def check_iters(iters: Any, name: str = "iters") -> int:
    """Return ``iters`` as an int; MeshError naming ``name`` unless it is an integer >= 0."""
    if isinstance(iters, bool) or not isinstance(iters, int | np.integer):
        if isinstance(iters, float) and iters.is_integer():
            iters = int(iters)
        else:
            raise MeshError(f"must be an integer >= 0, got {iters!r}", name)
    if iters < 0:
        raise MeshError(f"must be an integer >= 0, got {iters!r}", name)
    return int(iters)


def _check_choice(value: str, choices: tuple[str, ...], name: str) -> str:
    if value not in choices:
        raise MeshError(f"unknown {name} {value!r}; choose one of {', '.join(choices)}", name)
    return value


def taubin_mu(lam: float, k_pb: float = DEFAULT_PASS_BAND) -> float:
    """Taubin's negative factor ``ν`` from ``λ`` and the pass-band frequency ``k_PB``.

    Parameters
    ----------
    lam : float
        The shrinking factor ``λ > 0``.
    k_pb : float
        ``k_PB > 0`` with ``k_PB < 1/λ``, in the units of the (negated) Laplacian eigenvalues
        (Taubin recommends 0.01 to 0.1 for the uniform Laplacian).

    Returns
    -------
    nu : float
        ``ν = 1 / (k_PB − 1/λ) < −λ``, so that ``1/λ + 1/ν = k_PB``.
    """
    lam = check_lam(lam)
    kpb = check_lam(k_pb, "pass_band")
    if kpb >= 1.0 / lam:
        raise MeshError(
            f"the Taubin pass band {kpb:g} must be below 1/lam = {1.0 / lam:g}", "pass_band"
        )
    return 1.0 / (kpb - 1.0 / lam)


# --------------------------------------------------------------------------- operators


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
    _check_choice(laplacian, LAPLACIANS, "laplacian")
    _check_choice(area, AREA_KINDS, "area")
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


def _gershgorin_mu_min(W: FloatArray, K: sp.csr_matrix, active: np.ndarray) -> float:
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
    bound = _gershgorin_mu_min(W, K, active)
    idx = np.flatnonzero(active)
    if len(idx) == 0:
        return 0.0, True
    s = 1.0 / np.sqrt(W[idx])
    Ka = K[idx][:, idx]
    S = (sp.diags(s) @ (-Ka) @ sp.diags(s)).tocsr()
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


_EIGEN_WORK = 3e8  # multiply-adds most_negative_eigenvalue may spend before giving the bound


class _OverBudget(Exception):
    """The eigensolver used up its work budget."""


def amplification_curve(
    method: Method,
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
    _check_choice(method, METHODS, "method")
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


def _stability_from_mu(
    method: str,
    laplacian: str,
    lam: float,
    nu: float | None,
    mu_min: float,
    exact: bool,
    k_pb: float,
) -> Stability:
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
    method: Method = "explicit",
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
    _check_choice(method, METHODS, "method")
    lam = check_lam(lam)
    W, K = operator_parts(V, F, laplacian, area)
    k_pb = check_lam(pass_band, "pass_band") * _diagonal_scale(W, K)
    nu = _resolve_nu(method, lam, taubin_nu, k_pb)
    mu_min, exact = most_negative_eigenvalue(W, K)
    return _stability_from_mu(method, laplacian, lam, nu, mu_min, exact, k_pb)


def _diagonal_scale(W: FloatArray, K: sp.csr_matrix) -> float:
    """``mean_i(−L_ii) = mean_i(−K_ii / W_i)`` over active vertices: 1 for the uniform Laplacian,
    a typical squared inverse edge length for the cotan one."""
    active = W > 0
    if not active.any():
        return 1.0
    return float(np.mean(-K.diagonal()[active] / W[active]))


def _resolve_nu(method: str, lam: float, nu: float | None, k_pb: float) -> float | None:
    if method != "taubin":
        return None
    if nu is None:
        return taubin_mu(lam, k_pb)
    try:
        nu = float(nu)
    except (TypeError, ValueError):
        raise MeshError(f"must be a number, got {nu!r}", "taubin_nu") from None
    if not math.isfinite(nu) or nu >= -lam:
        raise MeshError(f"must be a finite number below -lam = {-lam:g}, got {nu!r}", "taubin_nu")
    return nu


# --------------------------------------------------------------------------- linear solver


def _surely_positive_definite(A: sp.csr_matrix, margin: float = 1e-8) -> bool:
    """True when the Jacobi-scaled ``D^-1/2 A D^-1/2`` is diagonally dominant by ``margin``.

    Then all its eigenvalues are at least ``margin`` (Gershgorin) and a Cholesky factorization
    cannot fail; ``False`` means "not proven" (the factorization may still succeed).
    """
    d = A.diagonal()
    if len(d) == 0:
        return True
    if not np.all(d > 0):
        return False
    s = 1.0 / np.sqrt(d)
    B = abs(A).tocsr()
    off = np.asarray((sp.diags(s) @ B @ sp.diags(s)).sum(axis=1)).ravel() - 1.0
    return bool(np.all(off <= 1.0 - margin))


@contextlib.contextmanager
def quiet_c_stdout() -> Iterator[None]:
    """Silence what C libraries print on the process's standard output (file descriptor 1).

    CHOLMOD (inside ``cholespy``) prints ``CHOLMOD warning: not positive definite`` with
    ``printf`` before the Python exception is raised; on a ``--json`` command that line would
    corrupt the output. Python's own ``sys.stdout`` is flushed first and is unaffected.
    """
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):  # no real descriptor 1 (embedded interpreter)
        yield
        return
    libc = None
    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        if libc is not None:
            with contextlib.suppress(Exception):
                libc.fflush(None)  # drop C stdio's buffered copy of the message too
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


class _SPDSolver:
    """Sparse Cholesky factorization of a symmetric positive definite matrix, reused per solve.

    Uses ``cholespy`` (CHOLMOD); falls back to SciPy's SuperLU when cholespy is unavailable.
    A matrix that is not provably positive definite is factorized with the C standard output
    silenced (:func:`quiet_c_stdout`), so CHOLMOD's complaint never reaches the user's output.
    """

    def __init__(self, A: sp.spmatrix) -> None:
        A = sp.csr_matrix(A)
        A.sum_duplicates()
        A.sort_indices()
        self.n = A.shape[0]
        try:
            from cholespy import CholeskySolverD, MatrixType
        except ImportError:  # pragma: no cover - cholespy is a dependency
            self._lu = sla.splu(A.tocsc())
            self._chol = None
            return
        self._lu = None
        quiet = contextlib.nullcontext() if _surely_positive_definite(A) else quiet_c_stdout()
        try:
            with quiet:
                self._chol = CholeskySolverD(
                    self.n,
                    np.ascontiguousarray(A.indptr, dtype=np.int32),
                    np.ascontiguousarray(A.indices, dtype=np.int32),
                    np.ascontiguousarray(A.data, dtype=np.float64),
                    MatrixType.CSR,
                )
        except ValueError:
            raise MeshError(
                "the implicit smoothing system is not numerically positive definite", "mesh"
            ) from None

    def solve(self, B: FloatArray) -> FloatArray:
        B = np.ascontiguousarray(B, dtype=np.float64)
        if self._chol is None:
            return self._lu.solve(B)  # type: ignore[union-attr]
        X = np.empty_like(B)
        self._chol.solve(B, X)
        return X


# --------------------------------------------------------------------------- the stepper


class Smoother:
    """Laplacian smoothing stepper: build once, then ``step()`` (cheap) as often as needed.

    Parameters
    ----------
    V : (n,3) float
        Initial positions (copied; never modified).
    F : (m,3) int
    method : {"explicit", "implicit", "taubin"}
        See the module docstring for the update formulas.
    laplacian : {"uniform", "cotan"}
        ``L = W⁻¹K`` negative semidefinite: uniform ``D⁻¹A − I`` or cotangent Laplace–Beltrami
        ``M⁻¹C``. ``λ`` is dimensionless for ``uniform`` (stable explicit ``λ <= 1`` always) but has
        units of length² for ``cotan`` (see :attr:`stability` for the limit on this mesh).
    lam : float
        Step ``λ > 0``.
    taubin_nu : float, optional
        Taubin's second (negative) factor; default from ``pass_band``.
    pass_band : float
        Taubin's pass band relative to the mesh (default 0.1): ``k_PB = pass_band × mean_i(−L_ii)``,
        which is exactly ``pass_band`` for the uniform Laplacian (diagonal −1) and scales with
        the inverse squared edge length for the cotan one (see :attr:`k_pb`).
    fix_boundary : bool
        Keep boundary vertices where they are.
    preserve_volume : bool
        After each step, scale about the vertex centroid so the enclosed volume stays that of the
        input (closed meshes only).
    mass : {"frozen", "recompute"}
        ``frozen``: ``W`` and ``K`` from the input mesh, the implicit system factorized once.
        ``recompute``: ``W`` (the areas) recomputed from the current positions every step with
        ``K`` frozen (Kazhdan et al. 2012); the implicit system is then refactorized every step.
        No effect for the uniform Laplacian (``W = D`` depends on connectivity only).
    area : {"voronoi", "barycentric"}
        Lumped area of the cotan mass.
    reference : (n,3) float, optional
        Clean positions; the history then also records ``rmse`` against them.
    track_history : bool
        Record a metrics dict per iteration in :attr:`history` (cheap: O(n + m)).
    history_limit : int, optional
        Keep at most this many entries: the input's (``history[0]``) and the latest
        ``history_limit − 1`` iterations (each entry carries its ``iteration``). An interactive
        stepper that runs without end should set it (about 0.5 kB per entry); ``None`` (the
        default) keeps every entry.
    warn : bool
        Emit a :class:`MeshWarning` when an explicit or Taubin ``λ`` is unstable on this mesh.

    Attributes
    ----------
    iteration : int
        Iterations done since construction or :meth:`reset`.
    history : list of dict
        ``history[k]`` describes the mesh after ``k`` iterations (``history[0]`` the input;
        with ``history_limit`` only the latest iterations are kept, so use ``iteration``):
        ``iteration``, ``time_ms`` (the step alone), ``step_rms``/``step_max`` (displacement of
        this step), ``drift_rms`` (from the input), ``volume`` and ``volume_change_pct`` (both
        ``None`` on open meshes, see :attr:`volume_note`), and ``rmse`` with a reference.
    diverged : bool
        ``True`` once a step blew up (a non-finite coordinate, or one farther than 1000 bounding-box
        diagonals from the input's bounding box: no smoothing moves a vertex that far); that step
        is discarded and later steps do nothing.
    closed : bool
    volume_note : str or None
        Why the volume is undefined (open mesh), else ``None``.
    n_factorizations : int
        How many times a linear system was factorized (1 for a frozen implicit smoother).

    Examples
    --------
    >>> from meshlap_core.primitives import bumpy_sphere
    >>> V, F = bumpy_sphere(3)
    >>> s = Smoother(V, F, "implicit", "uniform", lam=1.0)
    >>> s.run(5).shape
    (642, 3)
    >>> s.iteration, s.n_factorizations
    (5, 1)
    """

    def __init__(
        self,
        V: FloatArray,
        F: IntArray,
        method: Method = "explicit",
        laplacian: LaplacianKind = "uniform",
        lam: float = 0.5,
        *,
        taubin_nu: float | None = None,
        pass_band: float = DEFAULT_PASS_BAND,
        fix_boundary: bool = False,
        preserve_volume: bool = False,
        mass: MassMode = "frozen",
        area: AreaKind = MASS_AREA,
        reference: FloatArray | None = None,
        track_history: bool = True,
        history_limit: int | None = None,
        warn: bool = True,
    ) -> None:
        self.V0, self.F = as_mesh(V, F)
        if history_limit is not None and check_iters(history_limit, "history_limit") < 2:
            raise MeshError(f"must be at least 2, got {history_limit}", "history_limit")
        self.history_limit = history_limit
        self.n = len(self.V0)
        self.method = _check_choice(method, METHODS, "method")
        self.laplacian = _check_choice(laplacian, LAPLACIANS, "laplacian")
        self.mass = _check_choice(mass, MASS_MODES, "mass")
        self.area = _check_choice(area, AREA_KINDS, "area")
        self.pass_band = check_lam(pass_band, "pass_band")
        self.lam = check_lam(lam)
        self._nu_given = taubin_nu
        self.track_history = bool(track_history)
        self.reference = None if reference is None else as_vertices(reference, "reference")
        if self.reference is not None and self.reference.shape != self.V0.shape:
            raise MeshError(
                f"has {len(self.reference)} vertices but the mesh has {self.n}", "reference"
            )

        nb = n_boundary_edges(self.F) if len(self.F) else 0
        self.closed = len(self.F) > 0 and nb == 0
        if self.closed:
            self.volume_note: str | None = None
        elif len(self.F) == 0:
            self.volume_note = "undefined: the mesh has no faces"
        else:
            self.volume_note = f"undefined: the mesh is open ({nb} boundary edges)"
        self.preserve_volume = bool(preserve_volume)
        self._FT = np.ascontiguousarray(self.F.T)
        self.volume0 = _signed_volume_unchecked(self.V0, self.F) if self.closed else None
        if self.preserve_volume:
            if not self.closed:
                raise MeshError(
                    f"needs a closed mesh; the enclosed volume is {self.volume_note}",
                    "preserve_volume",
                )
            if self.volume0 == 0.0 or not math.isfinite(self.volume0 or 0.0):
                raise MeshError("the mesh encloses zero volume", "preserve_volume")

        self.fix_boundary = bool(fix_boundary)
        scale = float(np.abs(self.V0).max(initial=0.0))
        self._blowup = scale + 1e3 * max(bbox_diagonal(self.V0), 1e-300)
        W, K = operator_parts(self.V0, self.F, self.laplacian, self.area)
        self._W0, self._K = W, K
        self.k_pb = self.pass_band * _diagonal_scale(W, K)
        self.taubin_nu = self._nu_for(self.lam)
        fixed = (
            boundary_vertex_mask(self.F, self.n)
            if self.fix_boundary
            else np.zeros(self.n, dtype=bool)
        )
        self.pinned = fixed | ~(W > 0)  # fixed boundary, plus vertices with no faces / zero area
        self._free = np.flatnonzero(~self.pinned)
        self._fixed = np.flatnonzero(self.pinned)
        self._K_free_rows = K[self._free].tocsr()  # rows of free vertices, all columns
        self._K_ff = self._K_free_rows[:, self._free].tocsr()
        self._K_fp = self._K_free_rows[:, self._fixed].tocsr()
        self._recompute_mass = self.mass == "recompute" and self.laplacian == "cotan"
        self._stability: Stability | None = None
        self.n_factorizations = 0
        self._solver: _SPDSolver | None = None
        self._solver_key: tuple[float, int] | None = None
        self._rhs_fixed: FloatArray | None = None
        self._explicit_cache: dict[float, sp.csr_matrix] = {}

        if warn and self.method != "implicit":
            self._warn_if_unstable()
        self.reset()

    # ---------------------------------------------------------------- public state

    @property
    def V(self) -> FloatArray:
        """Current positions ``(n,3)`` (a read-only view; copy it to keep it)."""
        view = self._V.view()
        view.flags.writeable = False
        return view

    @property
    def stability(self) -> Stability:
        """Stability figures of this smoother on the input mesh (computed once, on first use)."""
        if self._stability is None:
            mu_min, exact = most_negative_eigenvalue(self._W0, self._K)
            self._stability = _stability_from_mu(
                self.method,
                self.laplacian,
                self.lam,
                self.taubin_nu,
                mu_min,
                exact,
                self.k_pb,
            )
        return self._stability

    def set_lam(self, lam: float) -> None:
        """Change ``λ`` (and Taubin's ``ν`` if it was derived from it) without losing the state.

        The implicit system is refactorized on the next step; nothing else is recomputed.
        """
        lam = check_lam(lam)
        if lam == self.lam:
            return
        nu = self._nu_for(lam)
        self.lam = lam
        self.taubin_nu = nu
        self._stability = None

    def reset(self) -> None:
        """Back to the input positions: iteration 0, history with the input's entry only.

        A frozen implicit factorization is kept.
        """
        self._V = self.V0.copy()
        self._W = self._W0
        self.iteration = 0
        self.diverged = False
        self.history: list[dict[str, Any]] = []
        if self.track_history:
            self.history.append(self._metrics(self._V, None, 0.0))

    # ---------------------------------------------------------------- stepping

    def step(self) -> FloatArray:
        """Do one iteration and return the current positions (see :attr:`V`)."""
        if self.diverged:
            return self.V
        t0 = time.perf_counter()
        x = self._V
        if self._recompute_mass and self.iteration > 0:
            self._W = vertex_areas(x, self.F, self.area)  # type: ignore[arg-type]
        if self.method == "explicit":
            new = self._explicit(x, self.lam)
        elif self.method == "taubin":
            nu = self.taubin_nu if self.taubin_nu is not None else taubin_mu(self.lam, self.k_pb)
            new = self._explicit(self._explicit(x, self.lam), nu)
        else:
            new = self._implicit(x)
        if self.preserve_volume:
            new = self._rescale_volume(new)
        elapsed = time.perf_counter() - t0
        if not np.abs(new).max(initial=0.0) <= self._blowup:  # also catches NaN
            self.diverged = True
            return self.V
        old = self._V
        self._V = new
        self.iteration += 1
        if self.track_history:
            self.history.append(self._metrics(new, old, elapsed))
            if self.history_limit is not None and len(self.history) > self.history_limit:
                del self.history[1]  # keep the input's entry and the latest ones
        return self.V

    def run(self, n: int) -> FloatArray:
        """Do ``n`` iterations (stops early if the iteration diverges); return the positions."""
        n = check_iters(n, "n")
        for _ in range(n):
            self.step()
            if self.diverged:
                break
        return self.V

    # ---------------------------------------------------------------- internals

    def _nu_for(self, lam: float) -> float | None:
        """Taubin's ``ν`` for ``λ`` (``None`` for the other methods), with a useful message."""
        try:
            return _resolve_nu(self.method, lam, self._nu_given, self.k_pb)
        except MeshError as exc:
            if exc.source != "pass_band":
                raise
            raise MeshError(
                f"Taubin's pass band k_PB = pass_band x mean(-L_ii) = {self.pass_band:g} x "
                f"{self.k_pb / self.pass_band:.3g} = {self.k_pb:.3g} must be below 1/lam = "
                f"{1.0 / lam:.3g}; use lam below {1.0 / self.k_pb:.3g} or a smaller pass band",
                "pass_band",
            ) from None

    def _warn_if_unstable(self) -> None:
        """Warn about an unstable explicit/Taubin λ; cheap (Gershgorin) unless near the limit."""
        active = self._W0 > 0
        bound = _gershgorin_mu_min(self._W0, self._K, active)
        quick = _stability_from_mu(
            self.method, self.laplacian, self.lam, self.taubin_nu, bound, False, self.k_pb
        )
        if quick.stable:
            return
        msg = self.stability.message()
        if msg:
            warnings.warn(MeshWarning(msg), stacklevel=3)

    def _explicit_operator(self, lam: float) -> sp.csr_matrix:
        """``S = I + λ P W⁻¹K`` (``P`` zeroes pinned rows) for the frozen mass, cached per λ."""
        S = self._explicit_cache.get(lam)
        if S is None:
            scale = np.zeros(self.n)
            scale[self._free] = lam / self._W0[self._free]
            S = (sp.identity(self.n, format="csr") + sp.diags(scale) @ self._K).tocsr()
            S.sort_indices()
            if len(self._explicit_cache) >= 4:
                self._explicit_cache.clear()
            self._explicit_cache[lam] = S
        return S

    def _explicit(self, x: FloatArray, lam: float) -> FloatArray:
        if not self._recompute_mass:
            return self._explicit_operator(lam) @ x  # one sparse product per step
        new = x.copy()
        if len(self._free):
            Kx = self._K_free_rows @ x
            new[self._free] += (lam / self._W[self._free])[:, None] * Kx
        return new

    def _implicit(self, x: FloatArray) -> FloatArray:
        free = self._free
        if len(free) == 0:
            return x.copy()
        key = (self.lam, self.iteration if self._recompute_mass else -1)
        if self._solver is None or self._solver_key != key:
            Wf = self._W[free]
            A = (sp.diags(Wf) - self.lam * self._K_ff).tocsr()
            try:
                self._solver = _SPDSolver(A)
            except MeshError:
                stiff = float(np.max(-self._K_ff.diagonal() / Wf)) if len(free) else 0.0
                raise MeshError(
                    f"the implicit system W - lam K cannot be factorized: lam = {self.lam:g} "
                    f"times the stiffest vertex's -L_ii = {stiff:.3g} is {self.lam * stiff:.3g}, "
                    "beyond double precision (use a smaller lam, or rescale the mesh; the cotan "
                    "lam is in units of length²)",
                    "lam",
                ) from None
            self._solver_key = key
            self.n_factorizations += 1
            self._rhs_fixed = self.lam * (self._K_fp @ x[self._fixed]) if len(self._fixed) else None
        if len(self._fixed) == 0:  # nothing pinned: no gathers or scatters
            return self._solver.solve(self._W[:, None] * x)
        rhs = self._W[free][:, None] * x[free]
        if self._rhs_fixed is not None:
            rhs = rhs + self._rhs_fixed
        new = x.copy()
        new[free] = self._solver.solve(rhs)
        return new

    def _rescale_volume(self, x: FloatArray) -> FloatArray:
        vol = _signed_volume_unchecked(x, self.F, self._FT)
        v0 = self.volume0 or 0.0  # preserve_volume requires a closed mesh with volume != 0
        if vol == 0.0 or not math.isfinite(vol) or (vol > 0) != (v0 > 0):
            return x  # an inverted or flat mesh cannot be rescaled; leave it
        s = (v0 / vol) ** (1.0 / 3.0)
        free = self._free
        c = x[free].mean(axis=0)
        out = x.copy()
        out[free] = c + s * (x[free] - c)
        return out

    def _metrics(self, x: FloatArray, old: FloatArray | None, elapsed: float) -> dict[str, Any]:
        entry: dict[str, Any] = {"iteration": self.iteration, "time_ms": 1e3 * elapsed}
        if old is None:
            entry["step_rms"] = entry["step_max"] = 0.0
        else:
            d = x - old
            d2 = np.einsum("ij,ij->i", d, d)
            entry["step_rms"] = float(np.sqrt(d2.mean())) if d2.size else 0.0
            entry["step_max"] = float(np.sqrt(d2.max())) if d2.size else 0.0
        d0 = x - self.V0
        entry["drift_rms"] = float(np.sqrt(np.einsum("ij,ij->", d0, d0) / max(self.n, 1)))
        if self.closed and self.volume0 is not None:
            vol = _signed_volume_unchecked(x, self.F, self._FT)
            entry["volume"] = vol
            entry["volume_change_pct"] = percent_volume_change(vol, self.volume0)
        else:
            entry["volume"] = None
            entry["volume_change_pct"] = None
        if self.reference is not None:
            dr = x - self.reference
            entry["rmse"] = float(np.sqrt(np.einsum("ij,ij->", dr, dr) / max(self.n, 1)))
        return entry


def smooth(
    V: FloatArray,
    F: IntArray,
    method: Method = "explicit",
    laplacian: LaplacianKind = "uniform",
    lam: float = 0.5,
    iters: int = 10,
    **options: Any,
) -> FloatArray:
    """One-shot smoothing: ``Smoother(V, F, method, laplacian, lam, **options).run(iters)``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    method : {"explicit", "implicit", "taubin"}
    laplacian : {"uniform", "cotan"}
        Negative semidefinite ``L = W⁻¹K`` (see :class:`Smoother`).
    lam : float
        ``> 0``.
    iters : int
        ``>= 0``.
    **options
        Keyword options of :class:`Smoother` (``fix_boundary``, ``preserve_volume``, ``mass``, ...).

    Returns
    -------
    V_smooth : (n,3) float
        A new array.

    Raises
    ------
    MeshError
        On bad arguments, or if explicit smoothing diverged (non-finite coordinates).
    """
    iters = check_iters(iters)
    s = Smoother(V, F, method, laplacian, lam, track_history=False, **options)
    s.run(iters)
    if s.diverged:
        raise MeshError(
            f"{method} smoothing diverged after {s.iteration} iterations; "
            f"the largest stable lam is {s.stability.max_stable_lam}",
            "lam",
        )
    return s.V.copy()


# --------------------------------------------------------------------------- denoising sweep


def denoise_sweep(
    V_clean: FloatArray,
    F: IntArray,
    *,
    V_noisy: FloatArray | None = None,
    noise_levels: Sequence[float] = (0.005, 0.02, 0.05),
    methods: Sequence[str] = ("explicit", "implicit"),
    laplacians: Sequence[str] = ("uniform",),
    lams: Sequence[float] = (0.1, 0.5, 1.0),
    iters: Sequence[int] = (10,),
    seed: int = 0,
    noise_mode: str = "isotropic",
    area: AreaKind = MASS_AREA,
    progress: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """Denoising table: noise levels × Laplacians × methods × λ × iteration counts.

    Parameters
    ----------
    V_clean : (n,3) float
        Clean reference.
    F : (m,3) int
        Shared connectivity.
    V_noisy : (n,3) float, optional
        A given noisy version (same vertex order); then ``noise_levels`` is ignored and the
        row's ``noise`` is the measured level ``RMS(offset per coordinate) / bbox diagonal``.
    noise_levels : sequence of float
        ``α`` values; noise is :func:`meshlap_core.noise.add_noise` with ``seed`` (the same seed
        for every level, so levels differ only in amplitude).
    methods : sequence of {"explicit", "implicit", "taubin"}
    laplacians : sequence of {"uniform", "cotan"}
        Negative semidefinite ``L = W⁻¹K`` (see :class:`Smoother`); built on the noisy mesh.
    lams : sequence of float
    iters : sequence of int
        Checkpoints; each (noise, Laplacian, method, λ) runs once to ``max(iters)``.
    seed : int
    noise_mode : {"isotropic", "normal"}
    area : {"voronoi", "barycentric"}
    progress : callable, optional
        Called with a short progress line per run.

    Returns
    -------
    rows : list of dict
        ``noise``, ``method``, ``laplacian``, ``lam``, ``iters``, ``rmse``, ``rmse_noisy``,
        ``max_error``, ``volume_change_pct`` (vs the clean volume; ``None`` on open meshes),
        ``volume_change_noisy_pct``, ``dihedral_mae_deg``, ``dihedral_mae_noisy_deg``,
        ``normal_dev_deg``, ``normal_dev_noisy_deg``, ``stable``, ``diverged``, ``failed``
        (``None``, or why this combination could not run, e.g. a Taubin pass band above
        ``1/λ`` or an implicit system beyond double precision), ``seconds`` (smoothing time up
        to this checkpoint). Metrics of a diverged or failed run are NaN.
    """
    V_clean, F = as_mesh(V_clean, F)
    for m in methods:
        _check_choice(m, METHODS, "method")
    for lap in laplacians:
        _check_choice(lap, LAPLACIANS, "laplacian")
    _check_choice(noise_mode, NOISE_MODES, "noise_mode")
    lam_list = [check_lam(v) for v in lams]
    iter_list = sorted({check_iters(v) for v in iters})
    if not lam_list or not iter_list or not methods or not laplacians:
        raise MeshError("methods, laplacians, lams and iters must not be empty", "sweep")
    ref = Reference(V_clean, F)
    if V_noisy is not None:
        Vn = as_vertices(V_noisy, "V_noisy")
        if Vn.shape != V_clean.shape:
            raise MeshError(
                f"has {len(Vn)} vertices but the clean mesh has {len(V_clean)}", "V_noisy"
            )
        diag = bbox_diagonal(V_clean)
        level = float(np.sqrt(np.mean((Vn - V_clean) ** 2)) / diag) if diag > 0 else float("nan")
        cases = [(level, Vn)]
    else:
        cases = []
        for a in noise_levels:
            cases.append((float(a), add_noise(V_clean, F, a, mode=noise_mode, seed=seed)))  # type: ignore[arg-type]

    rows: list[dict[str, Any]] = []
    for level, Vn in cases:
        base = ref.compare(Vn)
        for lap in laplacians:
            for method in methods:
                for lam in lam_list:
                    failed: str | None = None
                    try:
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore", MeshWarning)
                            s = Smoother(
                                Vn,
                                F,
                                method,
                                lap,
                                lam,  # type: ignore[arg-type]
                                area=area,
                                track_history=False,
                                warn=False,
                            )
                        stable = _quick_stable(s)
                    except MeshError as exc:
                        failed, stable = exc.problem, False
                    elapsed = 0.0
                    for k in iter_list:
                        if failed is None:
                            t0 = time.perf_counter()
                            try:
                                s.run(k - s.iteration)
                            except MeshError as exc:
                                failed = exc.problem
                            elapsed += time.perf_counter() - t0
                        if failed is not None or s.diverged:
                            got: dict[str, Any] = {
                                key: float("nan")
                                for key in (
                                    "rmse",
                                    "max_error",
                                    "volume_change_pct",
                                    "dihedral_mae_deg",
                                    "normal_dev_deg",
                                )
                            }
                        else:
                            got = ref.compare(s.V)
                        rows.append(
                            {
                                "noise": level,
                                "method": method,
                                "laplacian": lap,
                                "lam": lam,
                                "iters": k,
                                "rmse": got["rmse"],
                                "rmse_noisy": base["rmse"],
                                "max_error": got["max_error"],
                                "volume_change_pct": got["volume_change_pct"],
                                "volume_change_noisy_pct": base["volume_change_pct"],
                                "dihedral_mae_deg": got["dihedral_mae_deg"],
                                "dihedral_mae_noisy_deg": base["dihedral_mae_deg"],
                                "normal_dev_deg": got["normal_dev_deg"],
                                "normal_dev_noisy_deg": base["normal_dev_deg"],
                                "stable": stable,
                                "diverged": failed is None and bool(s.diverged),
                                "failed": failed,
                                "seconds": elapsed,
                            }
                        )
                    if progress is not None:
                        progress(
                            f"noise {level:g} {lap} {method} lam={lam:g}: "
                            + (
                                f"failed: {failed}"
                                if failed is not None
                                else f"{s.iteration} iterations in {elapsed:.3f} s"
                            )
                        )
    return rows


def _quick_stable(s: Smoother) -> bool:
    """Stability of a smoother, from the Gershgorin bound when that settles it (no eigensolve)."""
    if s.method == "implicit":
        return True
    bound = _gershgorin_mu_min(s._W0, s._K, s._W0 > 0)
    quick = _stability_from_mu(s.method, s.laplacian, s.lam, s.taubin_nu, bound, False, s.k_pb)
    return True if quick.stable else s.stability.stable


def best_rows(rows: Sequence[dict[str, Any]], key: str = "rmse") -> list[dict[str, Any]]:
    """The row with the smallest finite ``key`` for each noise level, in noise order.

    Parameters
    ----------
    rows : sequence of dict
        From :func:`denoise_sweep`.
    key : str
        A numeric column, e.g. ``"rmse"`` or ``"dihedral_mae_deg"``.

    Returns
    -------
    list of dict
    """
    best: dict[float, dict[str, Any]] = {}
    for r in rows:
        v = r.get(key)
        if v is None or not math.isfinite(v):
            continue
        cur = best.get(r["noise"])
        if cur is None or v < cur[key]:
            best[r["noise"]] = r
    return [best[k] for k in sorted(best)]
