"""The one-shot :func:`smooth`: build a :class:`~.stepper.Smoother`, run it, return the result."""

from __future__ import annotations

from typing import Any

from ..options import LaplacianKind, SmoothingMethod
from ..types import FloatArray, IntArray
from .params import check_iters
from .stepper import DivergenceError, Smoother


def smooth(
    V: FloatArray,
    F: IntArray,
    method: SmoothingMethod = "explicit",
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
        Keyword options of :class:`Smoother` (``fix_boundary``, ``preserve_volume``,
        ``mass_update``, ...).

    Returns
    -------
    V_smooth : (n,3) float
        A new array.

    Raises
    ------
    MeshError
        On bad arguments (``iters`` above :data:`~.params.MAX_ITERS` too).
    DivergenceError
        If explicit or Taubin smoothing diverged (see :attr:`Smoother.diverged`).

    Examples
    --------
    Smoothing a noisy sphere brings it closer to the clean one:

    >>> from meshlap_core import add_noise, icosphere, rmse, smooth
    >>> V, F = icosphere(3)
    >>> noisy = add_noise(V, alpha=0.005, seed=1)
    >>> smoothed = smooth(noisy, F, "implicit", "cotan", lam=1e-3, iters=2)
    >>> rmse(smoothed, V) < rmse(noisy, V)
    True
    """
    iters = check_iters(iters)
    s = Smoother(V, F, method, laplacian, lam, track_history=False, **options)
    s.run(iters)
    message = s.divergence_message()
    if message is not None:
        raise DivergenceError(message, "lam")
    return s.V.copy()
