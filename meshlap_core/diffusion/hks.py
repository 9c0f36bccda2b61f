"""The heat kernel signature (Sun, Ovsjanikov & Guibas, "A concise and provably informative
multi-scale signature based on heat diffusion", SGP 2009).

``HKS(x, t) = k_t(x, x) = Σ_i e^{−λ_i t} φ_i(x)²`` over the computed eigenpairs
(``M``-orthonormal ``φ``, frequencies ``λ ≥ 0`` of ``−Δ``). The paper samples ``t``
logarithmically between ``4 ln 10 / λ_max`` and ``4 ln 10 / λ_1`` (:func:`hks_times`) and
compares points by the signature scaled by the heat trace ``Σ_i e^{−λ_i t}`` (the integral of
``HKS(·, t)``, so every scale weighs alike; :func:`hks_distance`).
"""

from __future__ import annotations

import numpy as np

from ..errors import MeshError
from ..spectral.basis import SpectralBasis
from ..types import FloatArray, as_count, as_field, as_index, real_array
from .heat import check_eigenvalues, check_modes

MAX_HKS_TIMES = 1000
"""Most times of one signature (columns of ``H``): a plot or a descriptor shows far fewer."""


def hks_times(eigenvalues: FloatArray, count: int = 16) -> FloatArray:
    """``count`` times log-spaced over ``[4 ln10 / λ_max, 4 ln10 / λ_1]`` (``λ_1`` the first
    non-zero frequency), ``(count,)``."""
    lam = check_eigenvalues(eigenvalues)
    count = as_count(count, "count", 1, MAX_HKS_TIMES)
    positive = lam[lam > 1e-10 * max(float(lam.max(initial=0.0)), 1e-300)]
    if len(positive) < 2:
        raise MeshError("needs at least two non-zero eigenvalues", "eigenvalues")
    lo, hi = 4 * np.log(10) / positive.max(), 4 * np.log(10) / positive.min()
    return np.geomspace(lo, hi, count)


def heat_kernel_signature(
    basis: SpectralBasis, times: FloatArray, k: int | None = None, scaled: bool = False
) -> FloatArray:
    """``HKS(x, t)`` for every vertex and time.

    Parameters
    ----------
    basis : SpectralBasis
    times : (s,) float
        Positive times.
    k : int, optional
        Modes used (default all).
    scaled : bool
        Divide each time's column by the heat trace ``Σ_i e^{−λ_i t}``.

    Returns
    -------
    H : (n,s) float

    Examples
    --------
    Integrated over the surface, ``HKS(·, t)`` is the heat trace ``Σ_i e^{−λ_i t}`` (the
    eigenvectors are ``M``-orthonormal):

    >>> import numpy as np
    >>> from meshlap_core import SpectralBasis, heat_kernel_signature, icosphere
    >>> V, F = icosphere(2)
    >>> basis = SpectralBasis.compute(V, F, 40, cache=False)
    >>> times = np.array([0.1, 1.0])
    >>> hks = heat_kernel_signature(basis, times)
    >>> hks.shape
    (162, 2)
    >>> trace = np.exp(-np.outer(times, basis.eigenvalues)).sum(axis=1)
    >>> bool(np.allclose(basis.mass @ hks, trace))
    True
    """
    k = check_modes(basis, k)
    t = np.atleast_1d(real_array(times, "times", "times"))
    if t.ndim != 1 or t.size == 0 or t.size > MAX_HKS_TIMES:
        raise MeshError(
            f"should have shape (s,), 1 <= s <= {MAX_HKS_TIMES}; shape is {t.shape}", "times"
        )
    t = t.astype(np.float64)
    if not np.all(np.isfinite(t) & (t > 0)):
        raise MeshError("times must be positive and finite", "times")
    U = basis.vectors[:, :k]
    W = np.exp(-np.outer(basis.eigenvalues[:k], t))  # (k,s)
    H = (U * U) @ W
    return H / W.sum(axis=0)[None, :] if scaled else H


def hks_distance(H: FloatArray, vertex: int) -> FloatArray:
    """Distance of every vertex's signature to ``vertex``'s: ``‖log H(x,·) − log H(v,·)‖₂ /
    √s`` over the ``s`` scales (relative differences; points with similar signatures near 0),
    ``(n,)``."""
    raw = real_array(H, "H", "signatures")
    if raw.ndim != 2 or raw.shape[0] == 0 or raw.shape[1] == 0:
        raise MeshError(f"should have shape (n,s) (vertices, times); shape is {raw.shape}", "H")
    Hf = as_field(raw, raw.shape[0], "H")
    v = as_index(vertex, len(Hf), "vertex")
    logH = np.log(np.maximum(Hf, 1e-300))
    diff = logH - logH[v][None, :]
    return np.sqrt(np.mean(diff * diff, axis=1))
