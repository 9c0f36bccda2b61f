"""Singular points of a parameterization: where ``p_u × p_v`` vanishes (a pole, an apex).

A point ``(u, v)`` is singular when

* it lies on an edge the surface declares a pole (:attr:`ParametricSurface.poles`, within
  ``10⁻¹²`` of the domain width, the slack of :func:`check_uv`), or
* ``|p_u × p_v| ≤ 10⁻¹⁰ · A``, with ``A`` the surface's own area scale
  (:func:`surface_scale`: the mean of ``|p_u × p_v|`` over the domain, i.e. its area per unit of
  parameter area), or ``p_u × p_v`` is not finite.

The reference ``A`` is one number per surface, so the test is scale-aware (a sphere of radius
``10⁻⁶`` or ``10⁶`` has its singular points at the same ``(u, v)``) and does not shrink with the
point's own derivatives: relative to ``|p_u||p_v|`` (the former test) the sphere's south pole
``u = π`` is regular in floating point, because ``sin(π) = 1.2·10⁻¹⁶ ≠ 0`` makes
``|p_u × p_v| = |p_u||p_v|`` there, while the north pole ``u = 0`` has ``sin(0) = 0`` exactly.
"""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np

from ..types import BoolArray, FloatArray
from .catalogue import EDGES, ParametricSurface, get_surface
from .derivatives import DerivativeMethod, surface_derivatives

SINGULAR_REL = 1e-10
"""``(u, v)`` is singular when ``|p_u × p_v| ≤ SINGULAR_REL · surface_scale(surface)``."""
POLE_SLACK = 1e-12
"""A point within ``POLE_SLACK`` × (domain width) of a declared pole edge is on the pole."""
_SCALE_SAMPLES = 33  # midpoints of a 33 × 33 grid of cells: no sample on an edge (a pole)
_scales: weakref.WeakKeyDictionary[ParametricSurface, float] = weakref.WeakKeyDictionary()


def surface_scale(surface: ParametricSurface | str) -> float:
    """The surface's area scale ``A``: the mean of ``|p_u × p_v|`` over the domain.

    ``A = area / ((u1 − u0)(v1 − v0))`` by the midpoint rule on a ``33 × 33`` grid of cells
    (the unit sphere: ``4π / 2π² = 2/π``; the default helicoid ``≈ 1.148``). Computed once per
    surface object.

    Returns
    -------
    float
        ``A ≥ 0``; ``0`` when ``p_u × p_v`` vanishes (or is not finite) at every sample.
    """
    surface = get_surface(surface)
    cached = _scales.get(surface)
    if cached is not None:
        return cached
    u0, u1, v0, v1 = surface.domain
    k = (np.arange(_SCALE_SAMPLES) + 0.5) / _SCALE_SAMPLES
    U, V = np.meshgrid(u0 + k * (u1 - u0), v0 + k * (v1 - v0), indexing="ij")
    D = surface_derivatives(surface, U, V)
    nn = np.linalg.norm(np.cross(D.p_u, D.p_v), axis=-1)
    nn = nn[np.isfinite(nn)]
    scale = float(nn.mean()) if nn.size else 0.0
    _scales[surface] = scale
    return scale


def on_pole(surface: ParametricSurface, u: Any, v: Any) -> BoolArray:
    """Whether ``(u, v)`` lies on one of the surface's declared pole edges (broadcast shape)."""
    uu, vv = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    out = np.zeros(uu.shape, dtype=bool)
    u0, u1, v0, v1 = surface.domain
    for edge in surface.poles:
        x, width = (uu, u1 - u0) if edge[0] == "u" else (vv, v1 - v0)
        out |= np.abs(x - surface.domain[EDGES.index(edge)]) <= POLE_SLACK * width
    return out


def singular_mask(surface: ParametricSurface, u: Any, v: Any, normal: FloatArray) -> BoolArray:
    """The singular points among ``(u, v)``, given ``normal = p_u × p_v`` there (``S + (3,)``)."""
    nn = np.linalg.norm(normal, axis=-1)
    small = ~(nn > SINGULAR_REL * surface_scale(surface))  # NaN counts as singular
    return small | on_pole(surface, u, v)


def is_singular(
    surface: ParametricSurface | str, u: Any, v: Any, method: DerivativeMethod = "auto"
) -> BoolArray:
    """Whether the parameterization is singular at ``(u, v)`` (see the module notes).

    Parameters
    ----------
    surface : ParametricSurface or str
    u, v : array_like, broadcastable to a shape ``S`` (no domain check)
    method : see :func:`surface_derivatives`

    Returns
    -------
    (S,) bool
        True at a declared pole and wherever ``|p_u × p_v| ≤ 10⁻¹⁰ · surface_scale(surface)``.

    Examples
    --------
    >>> bool(is_singular("sphere", np.pi, 0.0)), bool(is_singular("sphere", np.pi / 2, 0.0))
    (True, False)
    """
    surface = get_surface(surface)
    D = surface_derivatives(surface, u, v, method)
    return singular_mask(surface, u, v, np.cross(D.p_u, D.p_v))


def singular_description(surface: ParametricSurface, u: float, v: float, normal: Any) -> str:
    """Why ``(u, v)`` is singular, for an error message."""
    if bool(np.any(on_pole(surface, u, v))):
        return "a declared pole of the surface, where p_u × p_v = 0"
    nn = float(np.linalg.norm(normal))
    return (
        f"|p_u × p_v| = {nn:.3g}, at most {SINGULAR_REL:g} of the surface's area scale "
        f"{surface_scale(surface):.4g}"
    )
