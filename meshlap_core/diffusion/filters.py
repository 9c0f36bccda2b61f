"""Spectral filters: a transfer function ``h(λ)`` applied in the eigenbasis, and the transfer
functions of the smoothing methods.

The filtered geometry is ``X̃ = U h(Λ) Uᵀ M X`` over the ``k`` computed modes (Taubin 1995;
Vallet & Lévy, "Spectral geometry processing with manifold harmonics", 2008), plus, when
``residual`` is set, the part of ``X`` the modes do not represent (``X − U Uᵀ M X``), so that a
band exaggeration keeps the fine detail. With the full basis and ``h ≡ 1`` it returns ``X``.

The smoothers of :mod:`meshlap_core.smoothing` with the cotangent Laplacian ``L = M⁻¹C`` and a
frozen operator are linear maps with the eigenvectors ``φ_i`` (``Lφ_i = −λ_i φ_i``), so ``n``
steps multiply mode ``i`` by exactly

* explicit ``x' = x + s L x``: ``(1 − sλ)ⁿ``;
* implicit ``(I − sL) x' = x``: ``(1 + sλ)^{−n}``;
* Taubin (``s`` then ``ν < 0``): ``((1 − sλ)(1 − νλ))ⁿ``

(:func:`transfer`); :func:`measured_amplification` runs the smoother and projects, which
agrees with them to the accuracy of the eigenvectors.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import MeshError
from ..options import FILTER_KINDS, FilterKind, check_choice
from ..smoothing.params import MAX_ITERS
from ..spectral.basis import SpectralBasis
from ..types import FloatArray, as_count, as_field, as_real, real_array
from .heat import check_eigenvalues, check_modes


def low_pass(eigenvalues: FloatArray, keep: int) -> FloatArray:
    """``h = 1`` on the ``keep`` lowest modes (``0 ≤ keep ≤ k``), 0 above (an ideal low-pass),
    ``(k,)``."""
    lam = check_eigenvalues(eigenvalues)
    h = np.zeros(len(lam))
    h[: as_count(keep, "keep", 0, len(lam))] = 1.0
    return h


def band_gain(eigenvalues: FloatArray, lo: int, hi: int, gain: float) -> FloatArray:
    """``h = gain`` on modes ``lo … hi−1`` and 1 elsewhere (band exaggeration for ``gain > 1``,
    attenuation below 1), ``(k,)``; ``0 ≤ lo ≤ hi ≤ k`` and a finite gain, else refused."""
    lam = check_eigenvalues(eigenvalues)
    a = as_count(lo, "lo", 0, len(lam))
    b = as_count(hi, "hi", a, len(lam))
    h = np.ones(len(lam))
    h[a:b] = as_real(gain, "gain")
    return h


def curve_gain(eigenvalues: FloatArray, knots: Any) -> FloatArray:
    """A drawn transfer function: ``h(λ)`` linear between control points ``(λ_j, h_j)`` and
    constant beyond the first and the last (``np.interp``).

    Parameters
    ----------
    eigenvalues : (k,) float
    knots : (p,2) float
        Control points, ``p ≥ 2``, ``λ_j`` non-decreasing, all finite.

    Returns
    -------
    h : (k,) float

    Raises
    ------
    MeshError
        Fewer than two points, a non-finite value or ``λ_j`` out of order.
    """
    P = np.asarray(knots, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 2 or len(P) < 2:
        raise MeshError(f"needs two or more (lambda, h) points, got shape {P.shape}", "curve")
    if not np.all(np.isfinite(P)) or np.any(np.diff(P[:, 0]) < 0):
        raise MeshError("the points must be finite, lambda non-decreasing", "curve")
    return np.interp(np.asarray(eigenvalues, dtype=np.float64), P[:, 0], P[:, 1])


def transfer(
    kind: FilterKind,
    eigenvalues: FloatArray,
    *,
    step: float = 0.0,
    iters: int = 1,
    nu: float = 0.0,
    keep: int = 0,
    band: tuple[int, int] = (0, 0),
    gain: float = 1.0,
) -> FloatArray:
    """The gain ``h(λ_i)`` of each mode for a filter ``kind``.

    Parameters
    ----------
    kind : {"low-pass", "band", "explicit", "implicit", "taubin"}
    eigenvalues : (k,) float
        Frequencies ``λ ≥ 0`` of ``−Δ``.
    step, iters, nu : float, int, float
        The smoother's ``s > 0``, number of steps and Taubin's ``ν < 0``.
    keep : int
        Modes a low-pass keeps.
    band, gain : (int, int), float
        Band ``[lo, hi)`` of mode indices and its gain.

    Returns
    -------
    h : (k,) float

    Raises
    ------
    MeshError
        An unknown kind; eigenvalues that are not a finite real ``(k,)`` array; a step that
        is not a positive number, a count of steps that is not an integer in ``0 … MAX_ITERS``,
        a Taubin ``ν`` not below ``−step``; a band or a ``keep`` out of range; or gains that
        overflow (each named).

    Examples
    --------
    Two explicit steps of ``s = ¼`` scale mode ``λ`` by ``(1 − sλ)²``:

    >>> import numpy as np
    >>> from meshlap_core import transfer_function
    >>> transfer_function("explicit", np.array([0.0, 1.0, 2.0]), step=0.25, iters=2).tolist()
    [1.0, 0.5625, 0.25]
    >>> transfer_function("low-pass", np.array([0.0, 2.0, 2.0, 6.0]), keep=2).tolist()
    [1.0, 1.0, 0.0, 0.0]
    """
    check_choice(kind, FILTER_KINDS, "filter")
    lam = check_eigenvalues(eigenvalues)
    if kind == "low-pass":
        return low_pass(lam, keep)
    if kind == "band":
        if np.ndim(band) != 1 or np.size(band) != 2:
            raise MeshError(f"should be (lo, hi), got {band!r}", "band")
        return band_gain(lam, band[0], band[1], gain)
    s = as_real(step, "step", positive=True)
    n = as_count(iters, "iters", 0, MAX_ITERS)
    with np.errstate(over="ignore"):
        if kind == "explicit":
            h = (1.0 - s * lam) ** n
        elif kind == "implicit":
            h = (1.0 + s * lam) ** (-n)
        else:
            v = as_real(nu, "nu")
            if not v < -s:
                raise MeshError(f"Taubin's nu must be below -step = {-s:g}, got {v!r}", "nu")
            h = ((1.0 - s * lam) * (1.0 - v * lam)) ** n
    if not np.all(np.isfinite(h)):
        bad = int(np.flatnonzero(~np.isfinite(h))[0])
        raise MeshError(
            f"the gain overflows at mode {bad} (lambda = {lam[bad]:.4g}): fewer steps or a "
            "smaller step",
            "iters",
        )
    return h


class SpectralFilter:
    """Filtered geometry ``U h(Λ) Uᵀ M X``, with the coefficients projected once.

    Parameters
    ----------
    basis : SpectralBasis
    X : (n,c) float, optional
        The signal (default the basis's vertex positions).
    k : int, optional
        Modes used (default all of the basis).

    Notes
    -----
    A full :meth:`apply` is one ``(n,k)·(k,c)`` product, which reads all of ``U`` (100 MB at
    43k vertices and ``k = 300``: memory-bound). A drag of a transfer-function editor changes a
    few gains at a time, so :meth:`apply` updates the previous result with the changed modes
    only, ``X̃ += U_J diag(Δh_J) C_J``, when fewer than a quarter of the gains changed (and
    recomputes in full every :data:`RESYNC` incremental updates, so round-off cannot build up).

    Examples
    --------
    A gain of 1 on every mode gives the reconstruction from all the basis's modes; a low-pass
    keeps the first ones:

    >>> import numpy as np
    >>> from meshlap_core import SpectralBasis, SpectralFilter, icosphere, transfer_function
    >>> V, F = icosphere(2)
    >>> basis = SpectralBasis.compute(V, F, 30, cache=False)
    >>> filt = SpectralFilter(basis)
    >>> bool(np.allclose(filt.apply(np.ones(30)), basis.reconstruct(30)))
    True
    >>> h = transfer_function("low-pass", basis.eigenvalues, keep=4)
    >>> bool(np.allclose(filt.apply(h), basis.reconstruct(4)))
    True
    """

    RESYNC = 64

    def __init__(self, basis: SpectralBasis, X: FloatArray | None = None, k: int | None = None):
        self.basis = basis
        self.k = check_modes(basis, k)
        X = basis.V if X is None else as_field(X, len(basis.mass), "X")
        self.X = X.reshape(len(X), -1)
        self.U = basis.vectors[:, : self.k]
        self.eigenvalues = basis.eigenvalues[: self.k]
        self.coefficients = self.U.T @ (basis.mass[:, None] * self.X)  # (k,c)
        self._residual: FloatArray | None = None
        self._last: tuple[FloatArray, FloatArray] | None = None  # (h, U h C) of the last apply
        self._updates = 0

    @property
    def residual(self) -> FloatArray:
        """``X − U Uᵀ M X``: what the ``k`` modes do not represent, ``(n,c)``."""
        if self._residual is None:
            self._residual = self.X - self.U @ self.coefficients
        return self._residual

    def apply(self, h: FloatArray, residual: bool = False) -> FloatArray:
        """``U diag(h) Uᵀ M X`` (``+ X − U Uᵀ M X`` with ``residual``), ``(n,c)``."""
        raw = real_array(h, "h", "gains")
        if raw.shape != (self.k,):
            raise MeshError(f"needs one gain per mode ({self.k}), got shape {raw.shape}", "h")
        h = as_field(raw, self.k, "h", columns=False)
        out = self._filtered(h)
        return out + self.residual if residual else out

    def pieces(self, lam_knots: Any) -> FloatArray:
        """The filtered geometry of each hat of a drawn curve with control points at
        ``lam_knots (p,)``: ``G_j = U diag(b_j(Λ)) C``, ``b_j`` the piecewise-linear hat that is 1
        at ``λ_j`` and 0 at the other points (``np.interp``'s, constant beyond the ends), so
        the curve through gains ``y`` filters to ``Σ_j y_j G_j`` (:func:`curve_gain` is linear
        in ``y``): a drag of a gain is ``p`` axpys of ``(n,c)``, not a product over ``U``.

        Returns
        -------
        G : (p, n, c) float
        """
        xs = np.asarray(lam_knots, dtype=np.float64)
        curve_gain(self.eigenvalues, np.column_stack([xs, np.zeros_like(xs)]))  # checks them
        eye = np.eye(len(xs))
        B = np.stack([np.interp(self.eigenvalues, xs, e) for e in eye])  # (p, k)
        W = B[:, :, None] * self.coefficients[None]  # (p, k, c): each hat's coefficients
        p, k, c = W.shape
        G = self.U @ W.transpose(1, 0, 2).reshape(k, p * c)  # one pass over U: (n, p·c)
        return np.ascontiguousarray(G.reshape(len(G), p, c).transpose(1, 0, 2))

    def _filtered(self, h: FloatArray) -> FloatArray:
        """``U diag(h) C``, from the last result when only a few gains changed."""
        last = self._last
        if last is not None and self._updates < self.RESYNC:
            changed = np.flatnonzero(h != last[0])
            if len(changed) < self.k // 4:
                self._updates += 1
                out = last[1].copy()
                if len(changed):
                    dh = (h - last[0])[changed]
                    out += self.U[:, changed] @ (dh[:, None] * self.coefficients[changed])
                self._last = (h.copy(), out)
                return out.copy()
        out = self.U @ (h[:, None] * self.coefficients)
        self._last, self._updates = (h.copy(), out), 0
        return out.copy()


def measured_amplification(
    basis: SpectralBasis, X_before: FloatArray, X_after: FloatArray, k: int | None = None
) -> FloatArray:
    """Per-mode amplification measured by projection: ``c_after_i / c_before_i`` with
    ``c = Uᵀ M X`` taken in the coordinate where ``|c_before_i|`` is largest.

    Parameters
    ----------
    basis : SpectralBasis
    X_before, X_after : (n,c) float
        A signal before and after a linear filter (e.g. a smoother's positions).
    k : int, optional

    Returns
    -------
    g : (k,) float
        ``NaN`` for modes the signal does not contain (``|c_before| ≤ 1e-12 · max|c_before|``).
    """
    k = check_modes(basis, k)
    n = len(basis.mass)
    Xb = as_field(X_before, n, "X_before").reshape(n, -1)
    Xa = as_field(X_after, n, "X_after").reshape(n, -1)
    if Xa.shape != Xb.shape:
        raise MeshError(
            f"should have the shape of X_before {Xb.shape}; shape is {Xa.shape}", "X_after"
        )
    U = basis.vectors[:, :k]
    m = basis.mass[:, None]
    before = U.T @ (m * Xb)
    after = U.T @ (m * Xa)
    j = np.argmax(np.abs(before), axis=1)
    rows = np.arange(k)
    b, a = before[rows, j], after[rows, j]
    ok = np.abs(b) > 1e-12 * np.abs(before).max()
    return np.where(ok, a / np.where(ok, b, 1.0), np.nan)


def smoother_transfer(
    basis: SpectralBasis, method: str, step: float, iters: int, **options: Any
) -> tuple[FloatArray, FloatArray]:
    """The formula and the measurement side by side for a cotangent smoother run on the
    basis's mesh: ``(h_formula (k,), h_measured (k,))``.

    The smoother uses the basis's Laplacian (cotangent, frozen operator, the basis's mass);
    ``options`` go to :class:`~meshlap_core.smoothing.Smoother` (e.g. ``taubin_nu``).
    """
    from ..smoothing import Smoother

    if not isinstance(basis, SpectralBasis):
        raise MeshError(f"must be a SpectralBasis, got {type(basis).__name__}", "basis")
    step = as_real(step, "step", positive=True)
    iters = as_count(iters, "iters", 0, MAX_ITERS)
    s = Smoother(
        basis.V,
        basis.F,
        method,  # type: ignore[arg-type]
        "cotan",
        step,
        area=basis.options.get("mass", "voronoi"),  # type: ignore[arg-type]
        mass_update="frozen",
        track_history=False,
        warn=False,
        **options,
    )
    after = s.run(int(iters))
    nu = float(s.taubin_nu) if s.taubin_nu is not None else 0.0
    formula = transfer(method, basis.eigenvalues, step=step, iters=iters, nu=nu)  # type: ignore[arg-type]
    return formula, measured_amplification(basis, basis.V, after)
