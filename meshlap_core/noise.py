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

import numpy as np

from .curvature import vertex_normals
from .errors import MeshError
from .options import NOISE_MODES, NoiseMode, check_choice
from .types import FloatArray, IntArray, as_faces, as_vertices


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
        Seed of ``numpy.random.default_rng``; the same seed gives the same noise. ``None`` draws
        fresh entropy.

    Returns
    -------
    V_noisy : (n,3) float
    """
    V = as_vertices(V)
    sigma = noise_sigma(V, alpha)
    check_choice(mode, NOISE_MODES, "noise mode", "mode")
    if seed is not None and (not isinstance(seed, int | np.integer) or seed < 0):
        raise MeshError(f"must be a non-negative integer, got {seed!r}", "seed")
    rng = np.random.default_rng(seed)
    if mode == "isotropic":
        return V + sigma * rng.standard_normal(V.shape)
    if F is None:
        raise MeshError("noise along the normal needs the faces", "F")
    F = as_faces(F, len(V))
    N = vertex_normals(V, F)
    return V + (sigma * rng.standard_normal(len(V)))[:, None] * N
