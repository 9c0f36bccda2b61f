"""Smoothing's argument checks: ``λ``, iteration counts, Taubin's ``ν`` (the methods and mass
updates are named in :mod:`meshlap_core.options`).

Sign convention: every Laplacian is negative semidefinite (``L = W⁻¹K``, see
:mod:`meshlap_core.smoothing`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import MeshError

DEFAULT_PASS_BAND = 0.1  # Taubin's k_PB, in the units of the Laplacian's eigenvalues

MAX_ITERS = 10_000_000
"""The most iterations one call may ask for (``smooth --iters``, ``denoise-eval --iters``,
:func:`smooth`, :meth:`Smoother.run`): 10⁷ steps take minutes on a 42-vertex icosphere and
about six hours on a 43k-vertex mesh (2 ms per explicit step); more is refused rather than left
running. An interactive stepper calls :meth:`Smoother.step` without this bound."""


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


def check_iters(iters: Any, name: str = "iters", maximum: int | None = MAX_ITERS) -> int:
    """Return ``iters`` as an int; MeshError naming ``name`` unless it is an integer >= 0 and,
    when ``maximum`` is given, at most ``maximum`` (default :data:`MAX_ITERS`)."""
    if isinstance(iters, bool) or not isinstance(iters, int | np.integer):
        if isinstance(iters, float) and iters.is_integer():
            iters = int(iters)
        else:
            raise MeshError(f"must be an integer >= 0, got {iters!r}", name)
    if iters < 0:
        raise MeshError(f"must be an integer >= 0, got {_show_int(iters)}", name)
    if maximum is not None and iters > maximum:
        shown = _show_int(iters)
        raise MeshError(
            f"must be at most {maximum} (the limit of one run: 10^7 steps take hours on a mesh of "
            f"10^4 vertices), got {shown}; run a longer smoothing in several parts",
            name,
        )
    return int(iters)


def _show_int(value: int) -> str:
    """``value`` in full, or its number of digits when it is longer than 40 digits (``str`` of
    an int over 4300 digits raises)."""
    if abs(value) < 10**40:
        return str(int(value))
    return f"a number of about {int(math.log10(abs(value))) + 1} digits"


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


def resolve_nu(method: str, lam: float, nu: float | None, k_pb: float) -> float | None:
    """Taubin's ν: the one given, else from λ and the pass band ``k_pb``; None for the others."""
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
