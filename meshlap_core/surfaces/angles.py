"""Angles of tangent directions at a point of a parametric surface: the angle ``θ_uv`` in the
``(u, v)`` parameter plane and the true angle ``θ`` in the tangent plane, and the map between
them (both from the first fundamental form alone).

A tangent direction is ``d = a p_u + b p_v``. Its **parameter angle** is
``θ_uv = atan2(b, a)``, measured in the ``(u, v)`` plane from the ``u`` axis towards ``v``. Its
**tangent angle** ``θ`` is measured in the tangent plane from the reference direction
``t₁ = p_u / |p_u|`` towards ``t₂ = n × t₁`` (``n = p_u × p_v / |…|``, so ``t₂`` lies on the
side of ``p_v``): ``d ∝ cos θ t₁ + sin θ t₂``. The two agree only where ``I`` is the identity
(``E = G = 1, F = 0``, e.g. the helicoid's axis ``u = 0``); principal directions are always
90° apart in ``θ`` but not in ``θ_uv`` (104° on the helicoid at ``(0.8, 0.3)``).

Both angles come from the Cholesky factor ``I = L Lᵀ``,
``L = [[√E, 0], [F/√E, √(det/E)]]``, ``det = EG − F²``: the coordinates of ``d`` in the
orthonormal frame ``(t₁, t₂)`` are ``Lᵀ (a, b)`` (``t₁ ↔ L⁻ᵀ(1, 0)``, ``t₂ ↔ L⁻ᵀ(0, 1)``), which
is why :func:`~meshlap_core.surfaces.surface_curvature_fields` needs no 3-D vector to turn
one angle into the other.

References
----------
M. do Carmo, *Differential Geometry of Curves and Surfaces*, 1976, sec. 2-5 (the angle between
two tangent vectors from ``I``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..types import FloatArray

TANGENT_ANGLE_REFERENCE = "the unit p_u direction, towards n × p_u (the side of p_v)"
"""Where the tangent-plane angle ``θ`` starts and which way it turns (shown in outputs)."""
PARAMETER_ANGLE_REFERENCE = "the (u, v) plane, from the u axis towards v"
"""Where the parameter angle ``θ_uv`` is measured."""


def _cholesky(forms: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(l11, l21, l22)`` of ``I = L Lᵀ`` from ``forms.E, F, G`` (broadcast arrays)."""
    E = np.asarray(forms.E, dtype=np.float64)
    F = np.asarray(forms.F, dtype=np.float64)
    G = np.asarray(forms.G, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        l11 = np.sqrt(E)
        return l11, F / l11, np.sqrt((E * G - F * F) / E)


def tangent_angle(forms: Any, theta_uv: Any) -> FloatArray:
    """The tangent-plane angle ``θ ∈ [0, 2π)`` of the direction whose parameter angle is
    ``theta_uv``.

    Parameters
    ----------
    forms : object with ``E, F, G``
        The first fundamental form (a :class:`~.geometry.PointGeometry` or
        :class:`~.geometry.CurvatureFields`), broadcast against ``theta_uv``.
    theta_uv : array_like
        Radians in the ``(u, v)`` plane from the ``u`` axis: the direction
        ``p_u cos θ_uv + p_v sin θ_uv``.

    Returns
    -------
    theta : float array of the broadcast shape
        Radians in ``[0, 2π)`` from ``p_u / |p_u|`` towards ``n × p_u`` (module notes):
        ``atan2(√(det/E) s, √E c + F s/√E)``, ``c = cos θ_uv``, ``s = sin θ_uv``. A direction
        with ``θ_uv ∈ [0, π)`` keeps ``θ ∈ [0, π)``.

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core.surfaces import point_geometry, tangent_angle
    >>> g = point_geometry("helicoid", 0.8, 0.3)  # E = 1, F = 0, G = 1.64
    >>> round(float(np.degrees(tangent_angle(g, np.radians(45.0)))), 4)  # atan(√1.64)
    52.0148
    """
    th = np.asarray(theta_uv, dtype=np.float64)
    l11, l21, l22 = _cholesky(forms)
    c, s = np.cos(th), np.sin(th)
    out = np.arctan2(l22 * s, l11 * c + l21 * s) % (2 * np.pi)
    return np.where(out >= 2 * np.pi, 0.0, out)


def parameter_angle(forms: Any, theta: Any) -> FloatArray:
    """The parameter angle ``θ_uv ∈ [0, 2π)`` of the direction whose tangent-plane angle is
    ``theta`` (the inverse of :func:`tangent_angle`).

    Parameters
    ----------
    forms : object with ``E, F, G``
    theta : array_like
        Radians in the tangent plane from ``p_u / |p_u|`` towards ``n × p_u``.

    Returns
    -------
    theta_uv : float array of the broadcast shape
        ``atan2(b, a)`` for ``(a, b) = L⁻ᵀ (cos θ, sin θ)``, the parameter components of the
        unit tangent ``t = a p_u + b p_v`` (``I(t, t) = 1``).
    """
    a, b = tangent_components(forms, theta)
    out = np.arctan2(b, a) % (2 * np.pi)
    return np.where(out >= 2 * np.pi, 0.0, out)


def tangent_components(forms: Any, theta: Any) -> tuple[FloatArray, FloatArray]:
    """Parameter components ``(a, b)`` of the unit tangent at tangent-plane angle ``theta``:
    ``cos θ t₁ + sin θ t₂ = a p_u + b p_v``, i.e. ``(a, b) = L⁻ᵀ (cos θ, sin θ)``.

    Returns
    -------
    a, b : float arrays of the broadcast shape (``E a² + 2F ab + G b² = 1``)
    """
    th = np.asarray(theta, dtype=np.float64)
    l11, l21, l22 = _cholesky(forms)
    c, s = np.cos(th), np.sin(th)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = s / l22
        a = (c - l21 * b) / l11
    return a, b
