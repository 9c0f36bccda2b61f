"""Seeded, reproducible Gaussian noise for denoising experiments.

The noise level is given relative to the mesh size: ``σ = α × (bounding-box diagonal)``, so the
same ``α`` means the same visual roughness on a mesh of any scale. Noise is either isotropic
(every coordinate gets an independent ``N(0, σ²)`` offset) or along the vertex normal (one
``N(0, σ²)`` offset per vertex, times the unit normal).

No Laplacian is used here (the sign convention of the project, Δ negative semidefinite, does
not enter).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .curvature import vertex_normals
from .errors import MeshError
from .options import MAX_COORDINATE, NOISE_MODES, NoiseMode, check_choice
from .types import FloatArray, IntArray, as_faces, as_vertices

MAX_SEED = 2**31 - 1
"""The largest noise seed: what every place a seed is typed can hold (the viewer's integer
field is a C ``int``; a session or ``--seed`` beyond it would pass here and break there)."""

NOISE_TAIL = 10.0
"""No standard normal sample numpy draws in practice exceeds this many σ (the largest of 10¹²
draws is about 7σ): the bound :func:`check_noise` uses for the largest displacement."""


def check_seed(seed: Any, name: str = "seed") -> int:
    """Return ``seed`` as an int, or raise :class:`MeshError` naming ``name`` unless it is an
    integer in ``0..MAX_SEED`` (booleans and integral floats are refused too: a seed is typed
    as an integer).

    Parameters
    ----------
    seed : Any
    name : str
        The option, e.g. ``"--seed"`` or ``'"smoothing.seed"'``.

    Returns
    -------
    int
    """
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise MeshError(f"must be an integer 0 to {MAX_SEED}, got {seed!r}", name)
    if not 0 <= seed <= MAX_SEED:
        digits = int(int(seed).bit_length() * math.log10(2)) + 1
        shown = str(int(seed)) if abs(seed) < 10**40 else f"a number of about {digits} digits"
        raise MeshError(f"must be an integer 0 to {MAX_SEED}, got {shown}", name)
    return int(seed)


def check_noise(V: Any, alpha: Any, name: str = "alpha") -> float:
    """Return ``σ = alpha × bbox_diagonal(V)`` after checking that noise of that size keeps
    every coordinate finite and within ``±MAX_COORDINATE`` (1e75, the limit the loader and
    every entry point enforce): ``max|x| + NOISE_TAIL·σ ≤ MAX_COORDINATE``.

    Without this check, ``alpha = 1e308`` would make the noisy coordinates infinite and the
    next function would blame the mesh ("vertex 0 has a NaN or infinite coordinate").

    Parameters
    ----------
    V : (n,3) float
    alpha : float
        The relative noise level, ``>= 0``.
    name : str
        The option named in messages (``"--noise"``, ``'"smoothing.noise_alpha"'``).

    Returns
    -------
    sigma : float

    Raises
    ------
    MeshError
        ``alpha`` negative, NaN or infinite, or so large that the noise would push
        coordinates beyond ``±MAX_COORDINATE`` (the message gives the largest usable alpha).
    """
    V = as_vertices(V)
    try:
        a = _check_alpha(alpha)
    except MeshError as exc:
        raise MeshError(exc.problem, name) from None
    diag = bbox_diagonal(V)
    with np.errstate(over="ignore"):
        sigma = a * diag
    reach = float(np.abs(V).max()) if len(V) else 0.0
    if not math.isfinite(sigma) or reach + NOISE_TAIL * sigma > MAX_COORDINATE:
        largest = (MAX_COORDINATE - reach) / (NOISE_TAIL * diag) if diag > 0 else math.inf
        raise MeshError(
            f"noise alpha {a:.3g} would move vertices by up to {NOISE_TAIL * sigma:.3g}, beyond "
            f"the coordinate limit ±{MAX_COORDINATE:.0e}; use alpha <= {largest:.3g}",
            name,
        )
    return sigma


def bbox_diagonal(V: FloatArray) -> float:
    """Length of the axis-aligned bounding-box diagonal (0 for fewer than two vertices).

    Parameters
    ----------
    V : (n,3) float

    Returns
    -------
    float
    """
    V = as_vertices(V)
    if len(V) == 0:
        return 0.0
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def _check_alpha(alpha: float) -> float:
    try:
        a = float(alpha)
    except (TypeError, ValueError):
        raise MeshError(f"must be a number, got {alpha!r}", "alpha") from None
    if not math.isfinite(a) or a < 0:
        raise MeshError(f"must be a finite number >= 0, got {alpha!r}", "alpha")
    return a


def noise_sigma(V: FloatArray, alpha: float) -> float:
    """``σ = α × bbox_diagonal(V)``.

    Parameters
    ----------
    V : (n,3) float
    alpha : float
        Relative noise level, ``>= 0``.

    Returns
    -------
    float
    """
    return _check_alpha(alpha) * bbox_diagonal(V)


def add_noise(
    V: FloatArray,
    F: IntArray | None = None,
    alpha: float = 0.01,
    *,
    mode: NoiseMode = "isotropic",
    seed: int | None = 0,
) -> FloatArray:
    """Return ``V`` plus seeded Gaussian noise of standard deviation ``σ = α × bbox diagonal``.

    Parameters
    ----------
    V : (n,3) float
        Clean positions (not modified).
    F : (m,3) int, optional
        Faces; required for ``mode="normal"``.
    alpha : float
        Relative noise level ``>= 0`` (0 returns a copy).
    mode : {"isotropic", "normal"}
        ``isotropic``: ``V + σ Z`` with ``Z`` an ``(n,3)`` standard normal array (every coordinate
        has standard deviation σ). ``normal``: ``V + σ z_i n_i`` with one standard normal ``z_i``
        per vertex and ``n_i`` the unit angle-weighted vertex normal of
        :func:`meshlap_core.curvature.vertex_normals` (unreferenced vertices do not move).
    seed : int or None
        Seed of ``numpy.random.default_rng``, 0 to :data:`MAX_SEED`; the same seed gives the
        same noise. ``None`` draws fresh entropy.

    Raises
    ------
    MeshError
        A bad mesh; ``alpha`` negative or so large that coordinates would leave
        ``±MAX_COORDINATE`` (:func:`check_noise`); a bad seed (:func:`check_seed`).

    Returns
    -------
    V_noisy : (n,3) float

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core import add_noise, icosphere, rmse
    >>> V, F = icosphere(3)
    >>> noisy = add_noise(V, alpha=0.01, seed=3)
    >>> np.array_equal(noisy, add_noise(V, alpha=0.01, seed=3))  # seeded: reproducible
    True
    >>> sigma = 0.01 * np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    >>> round(float(rmse(noisy, V) / (np.sqrt(3) * sigma)), 1)  # |σZ| has RMS √3 σ
    1.0
    """
    V = as_vertices(V)
    sigma = check_noise(V, alpha)
    check_choice(mode, NOISE_MODES, "noise mode", "mode")
    if seed is not None:
        check_seed(seed)
    rng = np.random.default_rng(seed)
    if mode == "isotropic":
        return V + sigma * rng.standard_normal(V.shape)
    if F is None:
        raise MeshError("noise along the normal needs the faces", "F")
    F = as_faces(F, len(V))
    N = vertex_normals(V, F)
    return V + (sigma * rng.standard_normal(len(V)))[:, None] * N
