"""Parametric surfaces ``p(u, v)``: exact differential geometry and the bridge to the meshes.

A :class:`ParametricSurface` is a map ``p`` on a parameter rectangle ``[u0,u1] × [v0,v1]``.
At any ``(u, v)`` this module computes the partial derivatives, the unit normal
``n = (p_u × p_v) / |p_u × p_v|`` (always this orientation), the first fundamental form
``I = [[E, F], [F, G]]``, the second fundamental form ``II = [[e, f], [f, g]]`` with
``e = p_uu · n, f = p_uv · n, g = p_vv · n``, the Gaussian curvature
``K = (eg − f²)/(EG − F²)``, the mean curvature ``H = (eG − 2fF + gE) / (2(EG − F²))``, the
principal curvatures ``κ₁ ≥ κ₂`` and directions, the normal curvature
``κₙ(θ) = II(w, w) / I(w, w)`` for ``w = (cos θ, sin θ)`` and the point classification.
It also triangulates the parameter rectangle (:func:`mesh_surface`) and measures how the
discrete estimators of :mod:`meshlap_core.curvature` converge to the exact values
(:func:`convergence_study`).

Sign conventions. ``II`` is measured against ``n = p_u × p_v / |…|``: ``κₙ < 0`` where the
surface bends away from ``n``. Every shipped closed surface has ``n`` pointing outwards, so the
unit sphere has ``κ₁ = κ₂ = H = −1`` here (the textbook sign of do Carmo). The discrete core uses
``Δx = −2 H n`` (negative semidefinite Laplacian), whose ``H`` is **minus** this one for the
same normal (``+1`` on the unit sphere). :func:`convergence_study` therefore compares the core's
``H`` with ``−H``; ``K`` does not depend on the sign.

Derivatives. A surface may carry its exact derivatives; otherwise (and in the tests, to check
them) they are computed numerically: first derivatives by the complex step
``p_u ≈ Im p(u + ih, v) / h`` (exact to rounding, needs ``p`` written with numpy functions that
accept complex input and are analytic: no ``abs``, ``maximum``, ``real``), second derivatives by
a 6th-order central difference of the complex-step first derivatives. A ``p`` that does not
return complex values for complex input falls back to 6th-order central differences.

References
----------
M. do Carmo, *Differential Geometry of Curves and Surfaces*, 1976, ch. 3.
Squire & Trapp, "Using complex variables to estimate derivatives of real functions", SIAM
Review 40, 1998 (the complex step).
Meyer, Desbrun, Schröder & Barr, "Discrete differential-geometry operators for triangulated
2-manifolds", 2003 (the estimators being tested).
Xu, "Convergence of the discrete Laplace–Beltrami operator", 2004; Hildebrandt, Polthier &
Wardetzky, "On the convergence of metric and geometric properties of polyhedral surfaces", 2006.
"""

from __future__ import annotations

import inspect
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from .curvature import gaussian_curvature, mean_curvature_cotan, mean_curvature_uniform
from .errors import MeshError
from .primitives import _grid_faces, icosphere
from .topology import boundary_vertex_mask, edges
from .types import BoolArray, FloatArray, IntArray

SurfaceMap = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""``p(u, v)``: ``u, v`` broadcastable arrays of shape ``S`` → points of shape ``S + (3,)``."""
DerivativeMap = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, ...]]
"""``(u, v) → (p_u, p_v, p_uu, p_uv, p_vv)``, each of shape ``S + (3,)``."""
DerivativeMethod = Literal["auto", "exact", "complex-step", "central"]
DERIVATIVE_METHODS: tuple[str, ...] = ("auto", "exact", "complex-step", "central")
EDGES: tuple[str, ...] = ("u0", "u1", "v0", "v1")
CLASSIFICATIONS: tuple[str, ...] = ("elliptic", "hyperbolic", "parabolic", "planar", "umbilic")

# A point is singular when |p_u x p_v| <= _SINGULAR_REL * |p_u| |p_v| (or p_u or p_v vanishes).
_SINGULAR_REL = 1e-10


def _xyz(x: Any, y: Any, z: Any) -> np.ndarray:
    """Stack three coordinate arrays (or scalars) into ``S + (3,)`` after broadcasting."""
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1)


# --------------------------------------------------------------------------------------------
# the surface type and the catalogue
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class ParametricSurface:
    """A parametric surface ``p(u, v)`` on the rectangle ``domain = (u0, u1, v0, v1)``.

    Attributes
    ----------
    name : str
    p : callable
        ``p(u, v) -> (..., 3)``; ``u`` and ``v`` are broadcastable arrays. Written with numpy
        ufuncs it also accepts complex input, which the complex-step derivatives use.
    domain : (u0, u1, v0, v1)
    closed_u, closed_v : bool
        ``p(u0, v) = p(u1, v)`` (resp. in ``v``): meshes wrap around and weld the seam.
    poles : tuple of {"u0", "u1", "v0", "v1"}
        Edges of the rectangle that ``p`` maps to a single point (the sphere's poles). Meshes
        collapse them to one vertex; the parameterization is singular there.
    derivatives : callable, optional
        Exact ``(u, v) -> (p_u, p_v, p_uu, p_uv, p_vv)``; numeric derivatives are used without it.
    default_uv : (u, v)
        The point the CLI reports when no ``--u/--v`` is given.
    description : str
        One line, shown by ``meshlap surface --list``.
    params : mapping
        The shape parameters the surface was built with (e.g. ``{"r": 1.0}``).

    Notes
    -----
    Compared by identity (it holds callables). Example of a new surface, an elliptic
    paraboloid, with numeric derivatives::

        ParametricSurface("paraboloid",
                          lambda u, v: np.stack(np.broadcast_arrays(u, v, u*u + v*v/2), -1),
                          (-1, 1, -1, 1))
    """

    name: str
    p: SurfaceMap
    domain: tuple[float, float, float, float]
    closed_u: bool = False
    closed_v: bool = False
    poles: tuple[str, ...] = ()
    derivatives: DerivativeMap | None = None
    default_uv: tuple[float, float] = (0.0, 0.0)
    description: str = ""
    params: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        u0, u1, v0, v1 = (float(x) for x in self.domain)
        if not all(math.isfinite(x) for x in (u0, u1, v0, v1)) or not (u0 < u1 and v0 < v1):
            raise MeshError(
                f"domain must be finite with u0 < u1 and v0 < v1, got {self.domain}", self.name
            )
        bad = [e for e in self.poles if e not in EDGES]
        if bad:
            raise MeshError(
                f"unknown pole edge(s) {bad}; choose among {', '.join(EDGES)}", self.name
            )
        object.__setattr__(self, "domain", (u0, u1, v0, v1))

    def __call__(self, u: Any, v: Any) -> FloatArray:
        """Points ``p(u, v)`` as real ``S + (3,)`` arrays (no domain check)."""
        uu, vv = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
        return np.real(_evaluate(self, uu, vv))


def _evaluate(surface: ParametricSurface, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    u, v = np.broadcast_arrays(u, v)
    P = np.asarray(surface.p(u, v))
    if P.shape != (*u.shape, 3):
        raise MeshError(
            f"p(u, v) returned shape {P.shape}; expected {(*u.shape, 3)} for u of shape {u.shape}",
            surface.name,
        )
    return P


def helicoid(c: float = 1.0) -> ParametricSurface:
    """Helicoid ``p(u,v) = (u cos v, u sin v, c v)``, ``u ∈ [0,1]``, ``v ∈ [0,2π]``.

    A minimal surface (``H = 0``) with ``K = −c²/(c² + u²)²``. For ``c = 1``: ``E = 1, F = 0,
    G = 1 + u², e = g = 0, f = −1/√(1+u²)``, ``κ = ±1/(1+u²)``, and at the origin
    ``κₙ(θ) = −sin 2θ``.
    """
    c = float(c)

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return _xyz(u * np.cos(v), u * np.sin(v), c * v)

    def d(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        cv, sv, z = np.cos(v), np.sin(v), np.zeros_like(u)
        return (
            _xyz(cv, sv, z),
            _xyz(-u * sv, u * cv, c + z),
            _xyz(z, z, z),
            _xyz(-sv, cv, z),
            _xyz(-u * cv, -u * sv, z),
        )

    return ParametricSurface(
        "helicoid",
        p,
        (0.0, 1.0, 0.0, 2 * np.pi),
        derivatives=d,
        default_uv=(0.0, 0.0),
        description="minimal surface (u cos v, u sin v, c v); hyperbolic, H = 0",
        params={"c": c},
    )


def sphere(r: float = 1.0) -> ParametricSurface:
    """Sphere ``p(u,v) = r (sin u cos v, sin u sin v, cos u)``, polar angle ``u ∈ [0,π]``,
    azimuth ``v ∈ [0,2π]`` (closed in ``v``, poles at ``u = 0`` and ``u = π``).

    ``n`` points outwards; ``K = 1/r²`` and every point is umbilic with ``κ₁ = κ₂ = −1/r``.
    """
    r = _positive(r, "r")

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return r * _xyz(np.sin(u) * np.cos(v), np.sin(u) * np.sin(v), np.cos(u))

    def d(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        su, cu, sv, cv = np.sin(u), np.cos(u), np.sin(v), np.cos(v)
        z = np.zeros_like(u * v)
        return (
            r * _xyz(cu * cv, cu * sv, -su),
            r * _xyz(-su * sv, su * cv, z),
            r * _xyz(-su * cv, -su * sv, -cu),
            r * _xyz(-cu * sv, cu * cv, z),
            r * _xyz(-su * cv, -su * sv, z),
        )

    return ParametricSurface(
        "sphere",
        p,
        (0.0, np.pi, 0.0, 2 * np.pi),
        closed_v=True,
        poles=("u0", "u1"),
        derivatives=d,
        default_uv=(np.pi / 3, np.pi / 4),
        description="sphere of radius r (polar angle u, azimuth v); umbilic, K = 1/r²",
        params={"r": r},
    )


def torus(R: float = 3.0, r: float = 1.0) -> ParametricSurface:
    """Torus ``p(u,v) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v)`` on ``[0,2π]²``.

    The parameterization of :func:`meshlap_core.primitives.torus` (same defaults, outward ``n``).
    ``K = cos v / (r (R + r cos v))``: elliptic outside (``cos v > 0``), hyperbolic inside,
    parabolic on the top and bottom circles ``v = ±π/2``.
    """
    R, r = _positive(R, "R"), _positive(r, "r")
    if r >= R:
        raise MeshError(f"needs r < R (a ring torus), got R={R}, r={r}", "torus")

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        w = R + r * np.cos(v)
        return _xyz(w * np.cos(u), w * np.sin(u), r * np.sin(v))

    def d(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        su, cu, sv, cv = np.sin(u), np.cos(u), np.sin(v), np.cos(v)
        w = R + r * cv
        z = np.zeros_like(u * v)
        return (
            _xyz(-w * su, w * cu, z),
            _xyz(-r * sv * cu, -r * sv * su, r * cv),
            _xyz(-w * cu, -w * su, z),
            _xyz(r * sv * su, -r * sv * cu, z),
            _xyz(-r * cv * cu, -r * cv * su, -r * sv),
        )

    return ParametricSurface(
        "torus",
        p,
        (0.0, 2 * np.pi, 0.0, 2 * np.pi),
        closed_u=True,
        closed_v=True,
        derivatives=d,
        default_uv=(0.0, 0.0),
        description="ring torus, radii R > r; K > 0 outside, < 0 inside",
        params={"R": R, "r": r},
    )


def catenoid(c: float = 1.0) -> ParametricSurface:
    """Catenoid ``p(u,v) = (c cosh(v/c) cos u, c cosh(v/c) sin u, v)``, ``u ∈ [0,2π]`` (closed),
    ``v ∈ [−1,1]``. Minimal (``H = 0``), ``K = −1/(c² cosh⁴(v/c))``, ``n`` points away from the
    axis. No exact derivatives are given: it exercises the numeric ones.
    """
    c = _positive(c, "c")

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        w = c * np.cosh(v / c)
        return _xyz(w * np.cos(u), w * np.sin(u), v)

    return ParametricSurface(
        "catenoid",
        p,
        (0.0, 2 * np.pi, -1.0, 1.0),
        closed_u=True,
        default_uv=(0.0, 0.0),
        description="minimal surface of revolution c cosh(z/c); hyperbolic, H = 0",
        params={"c": c},
    )


def saddle(a: float = 1.0) -> ParametricSurface:
    """Hyperbolic paraboloid ``p(u,v) = (u, v, a (u² − v²))`` on ``[−1,1]²`` (``n`` upwards).

    At the origin ``κ₁ = 2a, κ₂ = −2a`` along the axes, ``K = −4a²``.
    """
    a = float(a)

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return _xyz(u, v, a * (u * u - v * v))

    def d(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        o, z = np.ones_like(u * v), np.zeros_like(u * v)
        return (
            _xyz(o, z, 2 * a * u),
            _xyz(z, o, -2 * a * v),
            _xyz(z, z, 2 * a * o),
            _xyz(z, z, z),
            _xyz(z, z, -2 * a * o),
        )

    return ParametricSurface(
        "saddle",
        p,
        (-1.0, 1.0, -1.0, 1.0),
        derivatives=d,
        default_uv=(0.0, 0.0),
        description="hyperbolic paraboloid z = a(u² − v²); hyperbolic everywhere",
        params={"a": a},
    )


def monkey_saddle(a: float = 1.0) -> ParametricSurface:
    """Monkey saddle ``p(u,v) = (u, v, a (u³ − 3uv²))`` on ``[−1,1]²`` (``n`` upwards).

    The origin is a planar point (``II = 0``); everywhere else the surface is hyperbolic.
    """
    a = float(a)

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return _xyz(u, v, a * (u**3 - 3 * u * v * v))

    def d(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        o, z = np.ones_like(u * v), np.zeros_like(u * v)
        return (
            _xyz(o, z, a * (3 * u * u - 3 * v * v)),
            _xyz(z, o, -6 * a * u * v),
            _xyz(z, z, 6 * a * u),
            _xyz(z, z, -6 * a * v),
            _xyz(z, z, -6 * a * u),
        )

    return ParametricSurface(
        "monkey_saddle",
        p,
        (-1.0, 1.0, -1.0, 1.0),
        derivatives=d,
        default_uv=(0.0, 0.0),
        description="z = a(u³ − 3uv²); planar point at the origin, hyperbolic elsewhere",
        params={"a": a},
    )


def cylinder(r: float = 1.0, height: float = 2.0) -> ParametricSurface:
    """Cylinder ``p(u,v) = (r cos u, r sin u, v)``, ``u ∈ [0,2π]`` (closed), ``v ∈ [0,height]``.

    ``n`` points outwards; ``K = 0``, ``κ₁ = 0`` (along the axis), ``κ₂ = −1/r``: parabolic.
    """
    r, height = _positive(r, "r"), _positive(height, "height")

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return _xyz(r * np.cos(u), r * np.sin(u), v)

    def d(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        su, cu = np.sin(u), np.cos(u)
        o, z = np.ones_like(u * v), np.zeros_like(u * v)
        return (
            _xyz(-r * su, r * cu, z),
            _xyz(z, z, o),
            _xyz(-r * cu, -r * su, z),
            _xyz(z, z, z),
            _xyz(z, z, z),
        )

    return ParametricSurface(
        "cylinder",
        p,
        (0.0, 2 * np.pi, 0.0, height),
        closed_u=True,
        derivatives=d,
        default_uv=(0.0, height / 2),
        description="circular cylinder of radius r; parabolic, K = 0",
        params={"r": r, "height": height},
    )


def _positive(x: float, name: str) -> float:
    x = float(x)
    if not (math.isfinite(x) and x > 0):
        raise MeshError(f"must be a positive number, got {x}", name)
    return x


SURFACES: Mapping[str, Callable[..., ParametricSurface]] = {
    "helicoid": helicoid,
    "sphere": sphere,
    "torus": torus,
    "catenoid": catenoid,
    "saddle": saddle,
    "monkey_saddle": monkey_saddle,
    "cylinder": cylinder,
}
"""Factories of the shipped surfaces by name; ``helicoid`` is the default."""


def get_surface(name: str | ParametricSurface, **params: float) -> ParametricSurface:
    """The shipped surface called ``name`` (``-`` and ``_`` are interchangeable), built with
    ``params`` (e.g. ``get_surface("torus", R=2, r=0.5)``); a surface passes through.

    Raises
    ------
    MeshError
        For an unknown name (the message lists the known ones) or an unknown parameter.
    """
    if isinstance(name, ParametricSurface):
        if params:
            raise MeshError("parameters can only be given with a surface name", "params")
        return name
    key = str(name).strip().lower().replace("-", "_")
    if key not in SURFACES:
        raise MeshError(
            f"unknown surface {name!r}; known surfaces: {', '.join(SURFACES)}", "surface"
        )
    factory = SURFACES[key]
    known = list(inspect.signature(factory).parameters)
    bad = [k for k in params if k not in known]
    if bad:
        raise MeshError(
            f"{key} has no parameter {', '.join(bad)}; "
            f"its parameters: {', '.join(known) or 'none'}",
            "params",
        )
    return factory(**params)


def check_uv(
    surface: ParametricSurface, u: Any, v: Any, names: tuple[str, str] = ("u", "v")
) -> tuple[FloatArray, FloatArray]:
    """Coerce ``u, v`` to float arrays and check they lie in the surface's domain.

    Raises
    ------
    MeshError
        Naming ``names[0]`` or ``names[1]`` when a value is not finite or outside the domain
        (a relative slack of 1e-12 of the domain width is allowed).
    """
    u0, u1, v0, v1 = surface.domain
    out = []
    for x, lo, hi, nm in ((u, u0, u1, names[0]), (v, v0, v1, names[1])):
        try:
            arr = np.asarray(x, dtype=np.float64)
        except (TypeError, ValueError):
            raise MeshError(f"expected a number, got {x!r}", nm) from None
        slack = 1e-12 * (hi - lo)
        bad = ~np.isfinite(arr) | (arr < lo - slack) | (arr > hi + slack)
        if bad.any():
            val = arr.ravel()[int(np.flatnonzero(bad.ravel())[0])]
            raise MeshError(f"{val:g} is outside the {surface.name}'s domain [{lo:g}, {hi:g}]", nm)
        out.append(np.clip(arr, lo, hi))
    return out[0], out[1]


# --------------------------------------------------------------------------------------------
# derivatives
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Derivatives:
    """``p`` and its partial derivatives at a batch of points, each ``S + (3,) float``."""

    p: FloatArray
    p_u: FloatArray
    p_v: FloatArray
    p_uu: FloatArray
    p_uv: FloatArray
    p_vv: FloatArray


# 6th-order central differences: first derivative (offsets ±1..±3) and second derivative
_D1 = (np.array([-3, -2, -1, 1, 2, 3]), np.array([-1, 9, -45, 45, -9, 1]) / 60.0)
_D2 = (np.array([-3, -2, -1, 0, 1, 2, 3]), np.array([2, -27, 270, -490, 270, -27, 2]) / 180.0)
_CS_H = 1e-20  # complex step


def _supports_complex(surface: ParametricSurface) -> bool:
    """Whether ``p`` returns complex values for a complex ``u`` (tried at the domain centre)."""
    u0, u1, v0, v1 = surface.domain
    try:
        P = surface.p(np.array([0.5 * (u0 + u1) + 1j * _CS_H]), np.array([0.5 * (v0 + v1)]))
    except (TypeError, ValueError):
        return False
    return bool(np.iscomplexobj(P))


def _stencil(
    fun: Callable[[np.ndarray, np.ndarray], np.ndarray],
    u: np.ndarray,
    v: np.ndarray,
    axis: int,
    offsets: np.ndarray,
    weights: np.ndarray,
    step: float,
) -> np.ndarray:
    """``Σ_k w_k fun(x + o_k step) `` along ``axis`` (0 = u, 1 = v), all offsets in one call."""
    o = offsets.reshape((-1,) + (1,) * u.ndim) * step
    uu = u[None] + (o if axis == 0 else 0.0)
    vv = v[None] + (o if axis == 1 else 0.0)
    vals = fun(*np.broadcast_arrays(uu, vv))
    return np.tensordot(weights, vals, axes=(0, 0))


def surface_derivatives(
    surface: ParametricSurface | str, u: Any, v: Any, method: DerivativeMethod = "auto"
) -> Derivatives:
    """``p, p_u, p_v, p_uu, p_uv, p_vv`` at ``(u, v)`` (no domain check: ``p`` is analytic).

    Parameters
    ----------
    surface : ParametricSurface or str
    u, v : array_like, broadcastable to a shape ``S``
    method : {"auto", "exact", "complex-step", "central"}
        ``auto``: the surface's exact derivatives when it has them, otherwise complex-step when
        ``p`` returns complex values for complex input, otherwise central differences.

    Returns
    -------
    Derivatives
        Each field ``S + (3,) float``.

    Notes
    -----
    ``complex-step``: ``p_u = Im p(u + ih, v) / h`` with ``h = 1e-20`` (no cancellation, exact to
    rounding); ``p_uu, p_uv, p_vv`` are 6th-order central differences of the complex-step
    ``p_u, p_v`` with step ``2·10⁻³`` times the domain width (error ~1e-13 for the shipped
    surfaces). ``central``: 6th-order central differences of ``p`` itself (steps ``2·10⁻³`` and
    ``5·10⁻³`` times the width for first and second derivatives, error ~1e-11).
    """
    surface = get_surface(surface)
    if method not in DERIVATIVE_METHODS:
        raise MeshError(
            f"unknown method {method!r}; choose one of {', '.join(DERIVATIVE_METHODS)}", "method"
        )
    u, v = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    P = np.real(_evaluate(surface, u, v)).astype(np.float64)
    if method == "exact" and surface.derivatives is None:
        raise MeshError(f"the {surface.name} has no exact derivatives", "method")
    if method in ("auto", "exact") and surface.derivatives is not None:
        parts = surface.derivatives(u, v)
        shape = (*u.shape, 3)
        out = [np.broadcast_to(np.asarray(x, dtype=np.float64), shape).copy() for x in parts]
        return Derivatives(P, *out)
    if method == "auto":
        method = "complex-step" if _supports_complex(surface) else "central"
    u0, u1, v0, v1 = surface.domain
    wu, wv = u1 - u0, v1 - v0
    p = surface.p
    if method == "complex-step":
        if not _supports_complex(surface):
            raise MeshError(f"the {surface.name}'s p does not accept complex input", "method")

        def pu(a: np.ndarray, b: np.ndarray) -> np.ndarray:
            return np.imag(p(a + 1j * _CS_H, b)) / _CS_H

        def pv(a: np.ndarray, b: np.ndarray) -> np.ndarray:
            return np.imag(p(a, b + 1j * _CS_H)) / _CS_H

        hu, hv = 2e-3 * wu, 2e-3 * wv
        Pu, Pv = pu(u, v), pv(u, v)
        Puu = _stencil(pu, u, v, 0, *_D1, hu) / hu
        Puv = _stencil(pu, u, v, 1, *_D1, hv) / hv
        Pvv = _stencil(pv, u, v, 1, *_D1, hv) / hv
    else:

        def preal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
            return np.real(p(a, b))

        hu, hv = 2e-3 * wu, 2e-3 * wv
        Pu = _stencil(preal, u, v, 0, *_D1, hu) / hu
        Pv = _stencil(preal, u, v, 1, *_D1, hv) / hv
        ku, kv = 5e-3 * wu, 5e-3 * wv
        Puu = _stencil(preal, u, v, 0, *_D2, ku) / ku**2
        Pvv = _stencil(preal, u, v, 1, *_D2, kv) / kv**2

        def dv(a: np.ndarray, b: np.ndarray) -> np.ndarray:
            return _stencil(preal, a, b, 1, *_D1, kv) / kv

        Puv = _stencil(dv, u, v, 0, *_D1, ku) / ku
    return Derivatives(P, *(np.asarray(x, dtype=np.float64) for x in (Pu, Pv, Puu, Puv, Pvv)))


# --------------------------------------------------------------------------------------------
# fundamental forms and curvature
# --------------------------------------------------------------------------------------------


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


@dataclass(frozen=True)
class CurvatureFields:
    """Fundamental forms and curvatures at a batch of points (every field has shape ``S``
    unless noted). ``singular`` marks points where ``p_u × p_v = 0`` (all values NaN there)."""

    n: FloatArray  # S + (3,)
    E: FloatArray
    F: FloatArray
    G: FloatArray
    e: FloatArray
    f: FloatArray
    g: FloatArray
    K: FloatArray
    H: FloatArray
    k1: FloatArray
    k2: FloatArray
    w1: FloatArray  # S + (2,): parameter direction of k1, unit in the metric (w·I·w = 1)
    w2: FloatArray  # S + (2,)
    singular: BoolArray


def curvature_fields(
    surface: ParametricSurface | str, u: Any, v: Any, method: DerivativeMethod = "auto"
) -> CurvatureFields:
    """Vectorized fundamental forms and curvatures at ``(u, v)`` (no domain check).

    Parameters
    ----------
    surface : ParametricSurface or str
    u, v : array_like, broadcastable to a shape ``S``
    method : see :func:`surface_derivatives`

    Returns
    -------
    CurvatureFields

    Notes
    -----
    ``K = (eg − f²)/(EG − F²)`` and ``H = (eG − 2fF + gE)/(2(EG − F²))`` as in do Carmo. The
    principal curvatures are the eigenvalues of the shape operator ``I⁻¹II``, computed stably
    as those of the symmetric ``L⁻¹ II L⁻ᵀ`` (``I = LLᵀ``, Cholesky), so that ``κ₁ − κ₂`` is
    accurate to rounding even at umbilics; the principal parameter directions are
    ``w = L⁻ᵀ y`` for its unit eigenvectors ``y`` (so ``wᵀ I w = 1``).
    """
    surface = get_surface(surface)
    D = surface_derivatives(surface, u, v, method)
    N = np.cross(D.p_u, D.p_v)
    nn = np.linalg.norm(N, axis=-1)
    ref = np.linalg.norm(D.p_u, axis=-1) * np.linalg.norm(D.p_v, axis=-1)
    singular = (nn <= _SINGULAR_REL * ref) | (ref == 0)
    n = np.divide(N, nn[..., None], out=np.full_like(N, np.nan), where=~singular[..., None])
    E, F, G = _dot(D.p_u, D.p_u), _dot(D.p_u, D.p_v), _dot(D.p_v, D.p_v)
    e, f, g = _dot(D.p_uu, n), _dot(D.p_uv, n), _dot(D.p_vv, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        det = np.where(singular, np.nan, E * G - F * F)
        K = (e * g - f * f) / det
        H = (e * G - 2 * f * F + g * E) / (2 * det)
        l11 = np.sqrt(E)
        l21 = F / l11
        l22 = np.sqrt(det / E)
        # M = L^{-1} = [[m11, 0], [m21, m22]]
        m11, m21, m22 = 1 / l11, -l21 / (l11 * l22), 1 / l22
        a = m11 * m11 * e
        b = m11 * (m21 * e + m22 * f)
        c = m21 * m21 * e + 2 * m21 * m22 * f + m22 * m22 * g
    S = np.stack([np.stack([a, b], -1), np.stack([b, c], -1)], -2)
    S = np.where(singular[..., None, None], 0.0, S)
    lam, Y = np.linalg.eigh(S)  # ascending
    k2, k1 = lam[..., 0], lam[..., 1]
    # at umbilics every direction is principal: report u (k1) and its metric-orthogonal (k2)
    umb = np.abs(k1 - k2) <= 1e-12 * np.maximum(1.0, np.maximum(np.abs(k1), np.abs(k2)))
    Y = np.where(umb[..., None, None], np.eye(2), Y[..., ::-1])  # columns: y1 (k1), y2 (k2)
    Mt = np.zeros(S.shape)  # L^{-T} = M^T = [[m11, m21], [0, m22]]
    Mt[..., 0, 0], Mt[..., 0, 1], Mt[..., 1, 1] = m11, m21, m22
    W = Mt @ Y
    w1, w2 = W[..., :, 0], W[..., :, 1]
    nan = np.where(singular, np.nan, 1.0)
    return CurvatureFields(
        n=n,
        E=E,
        F=F,
        G=G,
        e=e,
        f=f,
        g=g,
        K=K,
        H=H,
        k1=k1 * nan,
        k2=k2 * nan,
        w1=w1 * nan[..., None],
        w2=w2 * nan[..., None],
        singular=singular,
    )


def normal_curvature(
    surface: ParametricSurface | str,
    u: float,
    v: float,
    theta: Any,
    method: DerivativeMethod = "auto",
) -> FloatArray:
    """Normal curvature ``κₙ(θ) = (e c² + 2f cs + g s²) / (E c² + 2F cs + G s²)`` at ``(u, v)``,
    ``c = cos θ``, ``s = sin θ``, θ the angle of the direction in the ``(u, v)`` plane.

    Returns
    -------
    kn : float array of the shape of ``theta``
    """
    surface = get_surface(surface)
    uu, vv = check_uv(surface, u, v)
    cf = curvature_fields(surface, uu, vv, method)
    _require_regular(surface, cf, float(uu), float(vv))
    th = np.asarray(theta, dtype=np.float64)
    c, s = np.cos(th), np.sin(th)
    second = cf.e * c * c + 2 * cf.f * c * s + cf.g * s * s
    first = cf.E * c * c + 2 * cf.F * c * s + cf.G * s * s
    return second / first


def normal_curvature_curve(
    surface: ParametricSurface | str, u: float, v: float, n: int = 361
) -> tuple[FloatArray, FloatArray]:
    """``κₙ(θ)`` sampled at ``n`` equally spaced angles ``θ ∈ [0, 2π]`` (both ends, so that a
    plot closes; the default 361 is a 1° step).

    Returns
    -------
    theta : (n,) float
    kn : (n,) float
    """
    if int(n) < 2:
        raise MeshError(f"needs at least 2 samples, got {n}", "n")
    theta = np.linspace(0.0, 2 * np.pi, int(n))
    return theta, normal_curvature(surface, u, v, theta)


def classify(k1: float, k2: float, tol: float = 1e-8) -> str:
    """Classify a point from its principal curvatures ``κ₁ ≥ κ₂``.

    ``planar``: both ≈ 0; ``umbilic``: ``κ₁ ≈ κ₂ ≠ 0`` (a spherical point); ``parabolic``: one
    ≈ 0; ``elliptic``: same sign (``K > 0``); ``hyperbolic``: opposite signs (``K < 0``).
    "≈ 0" means ``|κ| ≤ tol`` and "≈" means ``|κ₁ − κ₂| ≤ tol·max(1, |κ₁|, |κ₂|)`` (curvatures in
    units of 1/length of ``p``).
    """
    a1, a2 = abs(k1) <= tol, abs(k2) <= tol
    if a1 and a2:
        return "planar"
    if abs(k1 - k2) <= tol * max(1.0, abs(k1), abs(k2)):
        return "umbilic"
    if a1 or a2:
        return "parabolic"
    return "elliptic" if k1 * k2 > 0 else "hyperbolic"


@dataclass(frozen=True)
class PointGeometry:
    """Everything at one point ``(u, v)`` of a surface (see the module notes for the signs).

    Attributes
    ----------
    surface : str
    u, v : float
    p, p_u, p_v, p_uu, p_uv, p_vv : (3,) float
    n : (3,) float
        ``(p_u × p_v) / |p_u × p_v|``.
    E, F, G, e, f, g : float
        First and second fundamental forms.
    K, H, k1, k2 : float
        Gaussian, mean and principal curvatures (``k1 ≥ k2``, ``H = (k1 + k2)/2``).
    dir1_uv, dir2_uv : (2,) float
        Principal directions in the parameter plane, unit Euclidean vectors ``(cos θ, sin θ)``.
    dir1, dir2 : (3,) float
        The same as unit 3-D tangent vectors ``(p_u cos θ + p_v sin θ) / |…|``.
    theta_max, theta_min : float
        Angles in ``[0, π)`` where ``κₙ`` is largest (``= k1``) and smallest (``= k2``); the
        extremes repeat at ``+π``. At an umbilic ``κₙ`` is constant and ``theta_max = 0``.
    classification : str
        One of ``elliptic, hyperbolic, parabolic, planar, umbilic`` (see :func:`classify`).
    """

    surface: str
    u: float
    v: float
    p: FloatArray
    p_u: FloatArray
    p_v: FloatArray
    p_uu: FloatArray
    p_uv: FloatArray
    p_vv: FloatArray
    n: FloatArray
    E: float
    F: float
    G: float
    e: float
    f: float
    g: float
    K: float
    H: float
    k1: float
    k2: float
    dir1_uv: FloatArray
    dir2_uv: FloatArray
    dir1: FloatArray
    dir2: FloatArray
    theta_max: float
    theta_min: float
    classification: str

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dict (lists for vectors); keys are the attribute names."""
        out: dict[str, Any] = {}
        for k in self.__dataclass_fields__:
            x = getattr(self, k)
            out[k] = x.tolist() if isinstance(x, np.ndarray) else x
        return out


def _require_regular(surface: ParametricSurface, cf: CurvatureFields, u: float, v: float) -> None:
    if bool(np.any(cf.singular)):
        raise MeshError(
            f"the parameterization of the {surface.name} is singular at (u, v) = ({u:g}, {v:g}) "
            "(p_u × p_v = 0, e.g. a pole): the normal and the forms are undefined there",
            "u, v",
        )


def _direction_angle(w: np.ndarray) -> float:
    """Angle in ``[0, π)`` of the line spanned by the parameter vector ``w``."""
    t = math.atan2(float(w[1]), float(w[0])) % np.pi
    return 0.0 if t >= np.pi - 1e-15 else t


def point_geometry(
    surface: ParametricSurface | str,
    u: float | None = None,
    v: float | None = None,
    method: DerivativeMethod = "auto",
    tol: float = 1e-8,
) -> PointGeometry:
    """Everything about the surface at one point ``(u, v)`` (default: ``surface.default_uv``).

    Raises
    ------
    MeshError
        ``(u, v)`` outside the domain (naming ``u`` or ``v``) or a singular point of the
        parameterization (a pole).

    Examples
    --------
    >>> g = point_geometry("helicoid", 0.0, 0.0)
    >>> round(g.f, 12), round(g.K, 12), g.classification
    (-1.0, -1.0, 'hyperbolic')
    """
    surface = get_surface(surface)
    u = surface.default_uv[0] if u is None else u
    v = surface.default_uv[1] if v is None else v
    uu, vv = check_uv(surface, u, v)
    if uu.ndim or vv.ndim:
        raise MeshError("expected a single number", "u" if uu.ndim else "v")
    uf, vf = float(uu), float(vv)
    D = surface_derivatives(surface, uf, vf, method)
    cf = curvature_fields(surface, uf, vf, method)
    _require_regular(surface, cf, uf, vf)
    dirs_uv, dirs_3d, angles = [], [], []
    for w in (cf.w1, cf.w2):
        t = _direction_angle(w)
        d_uv = np.array([math.cos(t), math.sin(t)])
        d3 = d_uv[0] * D.p_u + d_uv[1] * D.p_v
        dirs_uv.append(d_uv)
        dirs_3d.append(d3 / np.linalg.norm(d3))
        angles.append(t)
    k1, k2 = float(cf.k1), float(cf.k2)
    return PointGeometry(
        surface=surface.name,
        u=uf,
        v=vf,
        p=D.p,
        p_u=D.p_u,
        p_v=D.p_v,
        p_uu=D.p_uu,
        p_uv=D.p_uv,
        p_vv=D.p_vv,
        n=np.asarray(cf.n),
        E=float(cf.E),
        F=float(cf.F),
        G=float(cf.G),
        e=float(cf.e),
        f=float(cf.f),
        g=float(cf.g),
        K=float(cf.K),
        H=float(cf.H),
        k1=k1,
        k2=k2,
        dir1_uv=dirs_uv[0],
        dir2_uv=dirs_uv[1],
        dir1=dirs_3d[0],
        dir2=dirs_3d[1],
        theta_max=angles[0],
        theta_min=angles[1],
        classification=classify(k1, k2, tol),
    )


# --------------------------------------------------------------------------------------------
# meshing
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SurfaceMesh:
    """A triangulated parametric surface.

    Attributes
    ----------
    V : (n,3) float
    F : (m,3) int
        Counter-clockwise in ``(u, v)``, so face normals agree with ``n = p_u × p_v``.
    uv : (n,2) float
        Parameters of every vertex (a pole vertex gets the pole's ``u`` (or ``v``) and the
        domain's start in the other parameter).
    pole : (n,) bool
        Vertices where an edge of the rectangle collapsed (singular parameterization).
    boundary : (n,) bool
        Vertices on a boundary edge of the mesh.
    surface : str
    res : (nu, nv)
        Number of cells along ``u`` and ``v``.
    """

    V: FloatArray
    F: IntArray
    uv: FloatArray
    pole: BoolArray
    boundary: BoolArray
    surface: str
    res: tuple[int, int]


# largest grid :func:`mesh_surface` builds (2^24 cells: 33.5 M triangles, about 1.3 GB of arrays)
MAX_CELLS = 2**24


def _parse_res(res: int | Sequence[int], name: str = "res") -> tuple[int, int]:
    try:
        if isinstance(res, int | np.integer):
            nu = nv = int(res)
        else:
            nu, nv = (int(x) for x in res)
    except (TypeError, ValueError):
        raise MeshError(f"expected an int or a pair (nu, nv), got {res!r}", name) from None
    if nu < 1 or nv < 1:
        raise MeshError(f"needs at least 1 cell in each direction, got {nu} x {nv}", name)
    if nu * nv > MAX_CELLS:
        raise MeshError(
            f"{nu} x {nv} cells is more than the {MAX_CELLS:,} meshlap meshes a surface with "
            f"(about {2 * MAX_CELLS:,} triangles)",
            name,
        )
    return nu, nv


def mesh_surface(surface: ParametricSurface | str, res: int | Sequence[int] = 32) -> SurfaceMesh:
    """Triangulate the parameter rectangle with ``res`` cells per direction (or ``(nu, nv)``).

    Each cell ``(i, j)`` of the regular grid becomes two triangles ``(a, b, c), (a, c, d)`` with
    ``a = (i, j), b = (i+1, j), c = (i+1, j+1), d = (i, j+1)`` (counter-clockwise in ``(u, v)``,
    the grid convention of :mod:`meshlap_core.primitives`). Closed directions wrap their indices
    (the seam is welded: no duplicate vertices); each pole edge collapses to one vertex and the
    triangles that would degenerate there are dropped, leaving a fan.

    Returns
    -------
    SurfaceMesh

    Raises
    ------
    MeshError
        On a bad ``res``, or fewer than 3 cells around a closed direction.
    """
    surface = get_surface(surface)
    nu, nv = _parse_res(res)
    for closed, cnt, nm in ((surface.closed_u, nu, "u"), (surface.closed_v, nv, "v")):
        if closed and cnt < 3:
            raise MeshError(
                f"the {surface.name} is closed in {nm}: needs at least 3 cells there", "res"
            )
    u0, u1, v0, v1 = surface.domain
    # closed directions: the last sample would repeat the first, the seam wraps instead
    us = np.linspace(u0, u1, nu + 1)[:nu] if surface.closed_u else np.linspace(u0, u1, nu + 1)
    vs = np.linspace(v0, v1, nv + 1)[:nv] if surface.closed_v else np.linspace(v0, v1, nv + 1)
    Nu, Nv = len(us), len(vs)
    idx = np.arange(Nu * Nv).reshape(Nu, Nv)
    # collapse each pole edge to one vertex (in this order, so a corner shared by two pole
    # edges, which p maps to one point, joins both)
    if "u0" in surface.poles:
        idx[0, :] = idx[0, 0]
    if "u1" in surface.poles:
        idx[-1, :] = idx[-1, 0]
    if "v0" in surface.poles:
        idx[:, 0] = idx[0, 0]
    if "v1" in surface.poles:
        idx[:, -1] = idx[0, -1]
    F = idx.ravel()[_grid_faces(Nu, Nv, surface.closed_u, surface.closed_v)]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
    used, Fc = np.unique(F, return_inverse=True)
    F = Fc.reshape(-1, 3).astype(np.int64)
    U, W = np.meshgrid(us, vs, indexing="ij")
    uv = np.stack([U.ravel(), W.ravel()], axis=1)[used]
    V = surface(uv[:, 0], uv[:, 1])
    collapsed = np.bincount(idx.ravel(), minlength=Nu * Nv) > 1
    pole = collapsed[used]
    return SurfaceMesh(
        V=np.ascontiguousarray(V, dtype=np.float64),
        F=np.ascontiguousarray(F),
        uv=uv,
        pole=pole,
        boundary=boundary_vertex_mask(F, len(V)),
        surface=surface.name,
        res=(nu, nv),
    )


# --------------------------------------------------------------------------------------------
# convergence of the discrete estimators
# --------------------------------------------------------------------------------------------

ESTIMATORS: tuple[str, ...] = (
    "H uniform",
    "H cotan voronoi",
    "H cotan barycentric",
    "K deficit voronoi",
    "K deficit barycentric",
)


def _discrete_estimates(V: FloatArray, F: IntArray) -> dict[str, FloatArray]:
    return {
        "H uniform": mean_curvature_uniform(V, F),
        "H cotan voronoi": mean_curvature_cotan(V, F, "voronoi"),
        "H cotan barycentric": mean_curvature_cotan(V, F, "barycentric"),
        "K deficit voronoi": gaussian_curvature(V, F, "voronoi"),
        "K deficit barycentric": gaussian_curvature(V, F, "barycentric"),
    }


def _mean_edge_length(V: FloatArray, F: IntArray) -> float:
    E = edges(F)
    return float(np.mean(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)))


def _orders(h: Sequence[float], err: Sequence[float], floor: float = 0.0) -> list[float | None]:
    """Observed orders ``log(e_k/e_{k+1}) / log(h_k/h_{k+1})`` between consecutive levels.

    ``None`` where undefined: equal ``h``, or an error at or below ``floor`` (rounding level,
    e.g. the level-1 icosphere, where the Voronoi cotangent ``H`` is exact by symmetry).
    """
    out: list[float | None] = []
    for k in range(len(h) - 1):
        if err[k] > floor and err[k + 1] > floor and h[k] != h[k + 1]:
            out.append(math.log(err[k] / err[k + 1]) / math.log(h[k] / h[k + 1]))
        else:
            out.append(None)
    return out


@dataclass(frozen=True)
class ConvergenceStudy:
    """Errors of the discrete curvature estimators against the exact values, per resolution.

    Attributes
    ----------
    surface : str
    mesher : str
        ``grid`` (:func:`mesh_surface`) or ``icosphere``
        (:func:`meshlap_core.primitives.icosphere`).
    resolutions : list of int
        Cells per direction (grid) or subdivision levels (icosphere), one per level.
    exclude_poles : bool
        Whether pole vertices were left out of the comparison.
    n_vertices, n_compared : list of int
        All vertices, and the interior vertices compared, per level.
    h : list of float
        Mean edge length per level.
    ref_scale : dict
        ``max |H|`` and ``max |K|`` of the exact values over the compared vertices of the
        finest level (to read the absolute errors as relative ones).
    errors : dict
        ``errors[estimator]`` with lists over the levels: ``max`` and ``mean`` of
        ``|estimate − exact|`` over the compared vertices, ``order_max`` and ``order_mean``
        (log-log slopes against ``h`` between consecutive levels, one fewer entry, ``None``
        when undefined or an error is at rounding level), ``worst_uv`` (``(u, v)`` of the
        vertex with the max error, ``None`` for the icosphere) and ``worst_is_pole``.
    """

    surface: str
    mesher: str
    resolutions: list[int]
    exclude_poles: bool
    n_vertices: list[int]
    n_compared: list[int]
    h: list[float]
    ref_scale: dict[str, float]
    errors: dict[str, dict[str, list[Any]]]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict with the attribute names as keys."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    def table(self) -> str:
        """The study as a plain-text table (one block per estimator)."""
        where = "interior vertices" + (" except poles" if self.exclude_poles else "")
        lines = [
            f"{self.surface}, {self.mesher} meshes: |discrete - exact| at {where}",
            f"(exact H in the core's sign, Δx = −2Hn; max|H| = {self.ref_scale['H']:.4g}, "
            f"max|K| = {self.ref_scale['K']:.4g}; order = log-log slope against h)",
            f"{'estimator':<22}{'res':>5}{'vertices':>10}{'h':>11}{'max err':>12}{'order':>7}"
            f"{'mean err':>12}{'order':>7}",
        ]

        def fmt(x: float | None) -> str:
            return "     -" if x is None else f"{x:6.2f}"

        for name, d in self.errors.items():
            for k, res in enumerate(self.resolutions):
                om = fmt(d["order_max"][k - 1]) if k else "     -"
                oa = fmt(d["order_mean"][k - 1]) if k else "     -"
                lines.append(
                    f"{name if k == 0 else '':<22}{res:>5}{self.n_vertices[k]:>10}"
                    f"{self.h[k]:>11.4g}{d['max'][k]:>12.4g} {om}{d['mean'][k]:>12.4g} {oa}"
                )
            if d["worst_uv"][-1] is not None:
                wu, wv = d["worst_uv"][-1]
                pole = " (a pole)" if d["worst_is_pole"][-1] else ""
                lines.append(f"{'':<27}max at (u, v) = ({wu:.4g}, {wv:.4g}){pole}")
        return "\n".join(lines)


@dataclass(frozen=True)
class _Level:
    V: FloatArray
    F: IntArray
    compare: BoolArray  # vertices compared
    H: FloatArray  # exact H, core sign
    K: FloatArray
    uv: FloatArray | None
    pole: BoolArray


def _study(
    surface: str, mesher: str, levels: Sequence[int], exclude_poles: bool, meshes: Sequence[_Level]
) -> ConvergenceStudy:
    keys = ("max", "mean", "worst_uv", "worst_is_pole")
    errs: dict[str, dict[str, list[Any]]] = {e: {k: [] for k in keys} for e in ESTIMATORS}
    n_v, n_c, hs = [], [], []
    scale = {"H": 0.0, "K": 0.0}
    for lev in meshes:
        est = _discrete_estimates(lev.V, lev.F)
        idx = np.flatnonzero(lev.compare)
        if len(idx) == 0:
            raise MeshError("the mesh has no interior vertex to compare; use a finer res", "res")
        n_v.append(len(lev.V))
        n_c.append(len(idx))
        hs.append(_mean_edge_length(lev.V, lev.F))
        for name in ESTIMATORS:
            ref = lev.H if name.startswith("H") else lev.K
            err = np.abs(est[name][idx] - ref[idx])
            w = idx[int(np.argmax(err))]
            errs[name]["max"].append(float(err.max()))
            errs[name]["mean"].append(float(err.mean()))
            errs[name]["worst_uv"].append(None if lev.uv is None else lev.uv[w].tolist())
            errs[name]["worst_is_pole"].append(bool(lev.pole[w]))
        scale = {"H": float(np.abs(lev.H[idx]).max()), "K": float(np.abs(lev.K[idx]).max())}
    # rounding level: 1e-10 of the curvature scale (K in its square), so that an estimator that
    # is exact on this mesh (the cylinder, the level-1 icosphere) gets no meaningless order
    kappa = max(scale["H"], math.sqrt(scale["K"]), 1e-300)
    for name, d in errs.items():
        floor = 1e-10 * (kappa if name.startswith("H") else kappa * kappa)
        d["order_max"] = _orders(hs, d["max"], floor)
        d["order_mean"] = _orders(hs, d["mean"], floor)
    return ConvergenceStudy(surface, mesher, list(levels), exclude_poles, n_v, n_c, hs, scale, errs)


def exact_curvature_at(
    surface: ParametricSurface | str, uv: Any, pole: Any = None
) -> tuple[FloatArray, FloatArray]:
    """Exact ``H`` (in the **core's** sign, i.e. ``−H`` of this module) and ``K`` at mesh vertices.

    Parameters
    ----------
    surface : ParametricSurface or str
    uv : (n,2) float
        Vertex parameters, as in :attr:`SurfaceMesh.uv`.
    pole : (n,) bool, optional
        Pole vertices (singular parameterization): their values are the limits, evaluated
        ``10⁻⁶`` of the domain width inside the rectangle.

    Returns
    -------
    H_core, K : (n,) float
    """
    surface = get_surface(surface)
    uv = np.array(uv, dtype=np.float64).reshape(-1, 2)
    if pole is not None and np.any(pole):
        pole = np.asarray(pole, dtype=bool)
        u0, u1, v0, v1 = surface.domain
        eps_u, eps_v = 1e-6 * (u1 - u0), 1e-6 * (v1 - v0)
        tol = 1e-9 * (u1 - u0 + v1 - v0)
        for edge, col, inside in (
            ("u0", 0, u0 + eps_u),
            ("u1", 0, u1 - eps_u),
            ("v0", 1, v0 + eps_v),
            ("v1", 1, v1 - eps_v),
        ):
            if edge in surface.poles:
                at = pole & (np.abs(uv[:, col] - surface.domain[EDGES.index(edge)]) <= tol)
                uv[at, col] = inside
    cf = curvature_fields(surface, uv[:, 0], uv[:, 1])
    return -cf.H, cf.K


def convergence_study(
    surface: ParametricSurface | str,
    resolutions: Sequence[int] = (8, 16, 32, 64, 128),
    mesher: Literal["grid", "icosphere"] = "grid",
    exclude_poles: bool = False,
    progress: Callable[[str], None] | None = None,
) -> ConvergenceStudy:
    """Errors of the discrete estimators of :mod:`meshlap_core.curvature` against the exact
    curvature, over a sequence of refinements.

    Parameters
    ----------
    surface : ParametricSurface or str
    resolutions : sequence of int
        ``grid``: cells per direction of :func:`mesh_surface`. ``icosphere``: subdivision
        levels of :func:`meshlap_core.primitives.icosphere` (only for the sphere, whose radius
        is used), e.g. ``(1, 2, 3, 4, 5)``.
    mesher : {"grid", "icosphere"}
    exclude_poles : bool
        Leave the pole vertices of a grid mesh out (their fan of thin triangles is the one
        place the barycentric area fails on the (u, v) sphere).
    progress : callable, optional
        Called with one line of text per level (the CLI prints it on stderr).

    Returns
    -------
    ConvergenceStudy

    Notes
    -----
    Estimators (:data:`ESTIMATORS`): uniform ``H = −½ L_u x · n``; cotangent
    ``H = −½ M⁻¹C x · n`` and angle-deficit ``K = (2π − Σθ)/A`` with the Voronoi (mixed) and
    the barycentric vertex area ``A``. Only interior vertices are compared (boundary vertices
    have one-sided stencils); the exact ``H`` is taken in the core's sign (``−H`` of this
    module). The observed order is the slope of ``log(error)`` against ``log(h)``, ``h`` the
    mean edge length: 2 means the error shrinks 4× when ``h`` halves, 0 that it stalls.

    What it shows (unit sphere, default torus R = 3, r = 1; max errors):

    - icospheres, levels 1..5: with the Voronoi area the max error of the angle-deficit K
      shrinks 4× per subdivision (0.080 → 0.00036) and so does that of the cotangent H from
      level 2 on (1.2e-4 → 1.9e-6; level 1 is exact by symmetry); with the barycentric area
      both stall near 15 % (0.146) while their *mean* error still shrinks 4×.
    - the (u, v) sphere grid: Voronoi converges (order ≈ 1.9); barycentric stalls at 25 %,
      at the two pole vertices only (their fan of thin triangles gets ⅓ of its area instead
      of ≈ ¼); with ``exclude_poles`` it converges with order 2.
    - the torus grid: every cotangent / deficit estimator converges with order 2, the
      barycentric ones included.
    - the uniform H tends to 0 (it is ``O(h²)``), so its error tends to ``|H|``: it converges
      only on minimal surfaces (helicoid, catenoid), where the answer is 0.
    """
    surface = get_surface(surface)
    if mesher not in ("grid", "icosphere"):
        raise MeshError(f"unknown mesher {mesher!r}; choose grid or icosphere", "mesher")
    try:
        levels = [int(r) for r in resolutions]
    except (TypeError, ValueError):
        raise MeshError(f"expected a list of integers, got {resolutions!r}", "res") from None
    if not levels:
        raise MeshError("needs at least one resolution", "res")
    if mesher == "icosphere" and surface.name != "sphere":
        raise MeshError(
            f"the icosphere mesher only meshes the sphere, not the {surface.name}", "mesher"
        )
    for lev in levels:  # every level checked before the first (slow) one is meshed
        if mesher == "grid":
            _parse_res(lev)
        elif not 0 <= lev <= 7:
            raise MeshError(f"icosphere subdivision levels must be in 0..7, got {lev}", "res")
    meshes = []
    for lev in levels:
        if mesher == "grid":
            m = mesh_surface(surface, lev)
            H_ex, K_ex = exact_curvature_at(surface, m.uv, m.pole)
            compare = ~m.boundary & ~(m.pole if exclude_poles else False)
            meshes.append(_Level(m.V, m.F, compare, H_ex, K_ex, m.uv, m.pole))
        else:
            if not 0 <= lev <= 7:
                raise MeshError(f"icosphere subdivision levels must be in 0..7, got {lev}", "res")
            r = float(surface.params.get("r", 1.0))
            V, F = icosphere(lev, r)
            n = len(V)
            meshes.append(
                _Level(
                    V,
                    F,
                    np.ones(n, bool),
                    np.full(n, 1.0 / r),
                    np.full(n, 1.0 / r**2),
                    None,
                    np.zeros(n, bool),
                )
            )
        if progress is not None:
            progress(f"{surface.name}: {mesher} level {lev}, {len(meshes[-1].V)} vertices")
    return _study(surface.name, mesher, levels, exclude_poles, meshes)


# --------------------------------------------------------------------------------------------
# output: the κn(θ) figure and the mesh file
# --------------------------------------------------------------------------------------------


def _num(x: float) -> str:
    """Compact number for labels: 4 significant digits, no ``-0``, tiny values as 0."""
    x = float(x)
    return "0" if abs(x) < 1e-12 else f"{x:.4g}"


def plot_normal_curvature(
    surface: ParametricSurface | str,
    u: float | None,
    v: float | None,
    path: str | os.PathLike,
    n: int = 721,
) -> PointGeometry:
    """Save a PNG of ``κₙ(θ)`` over ``[0, 2π]`` with ``κ₁, κ₂`` and their angles marked.

    matplotlib is imported here (Agg canvas, no pyplot, no GUI), so importing this module stays
    light. The file is written atomically.

    Returns
    -------
    PointGeometry
        The point the figure shows.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .io import atomic_write

    path = Path(path)
    if path.suffix.lower() != ".png":
        raise MeshError(f"the plot is written as PNG; got {path.suffix or 'no suffix'!r}", path)
    geo = point_geometry(surface, u, v)
    theta, kn = normal_curvature_curve(surface, geo.u, geo.v, n)
    fig = Figure(figsize=(8.6, 4.4), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.1, 0.12, 0.6, 0.74))
    ax.plot(theta, kn, color="black", lw=1.8, label=r"$\kappa_n(\theta)$")
    ax.axhline(geo.k1, color="tab:red", lw=1, ls="--", label=rf"$\kappa_1 = {_num(geo.k1)}$")
    ax.axhline(geo.k2, color="tab:blue", lw=1, ls="--", label=rf"$\kappa_2 = {_num(geo.k2)}$")
    ax.axhline(0.0, color="0.6", lw=0.6)
    if geo.classification in ("umbilic", "planar"):
        ax.plot([], [], " ", label="κn is constant: every\ndirection is principal")
    else:
        for t in (geo.theta_max, geo.theta_max + np.pi):
            ax.axvline(t, color="tab:red", lw=0.8, ls=":")
            ax.plot([t], [geo.k1], "o", color="tab:red", zorder=3)
        for t in (geo.theta_min, geo.theta_min + np.pi):
            ax.axvline(t, color="tab:blue", lw=0.8, ls=":")
            ax.plot([t], [geo.k2], "o", color="tab:blue", zorder=3)
        ax.plot(
            [],
            [],
            "o:",
            color="tab:red",
            label=rf"max at $\theta_1 = {_num(geo.theta_max)}$, $\theta_1 + \pi$",
        )
        ax.plot(
            [],
            [],
            "o:",
            color="tab:blue",
            label=rf"min at $\theta_2 = {_num(geo.theta_min)}$, $\theta_2 + \pi$",
        )
    ticks = np.arange(0, 2 * np.pi + 1e-9, np.pi / 4)
    labels = ["0", "π/4", "π/2", "3π/4", "π", "5π/4", "3π/2", "7π/4", "2π"]
    ax.set_xticks(ticks, labels)
    ax.set_xlim(0, 2 * np.pi)
    span = max(geo.k1 - geo.k2, 0.25 * max(abs(geo.k1), abs(geo.k2)), 1e-3)
    ax.set_ylim(geo.k2 - 0.2 * span, geo.k1 + 0.2 * span)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_xlabel(r"direction angle $\theta$ in the $(u,v)$ plane")
    ax.set_ylabel(r"normal curvature $\kappa_n$")
    ax.set_title(
        f"{geo.surface} at (u, v) = ({geo.u:.4g}, {geo.v:.4g}): "
        f"K = {_num(geo.K)}, H = {_num(geo.H)}, {geo.classification}",
        fontsize=10,
    )
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, framealpha=0.9)
    fig.text(
        0.72,
        0.12,
        "$\\kappa_n(\\theta) = \\frac{e c^2 + 2 f cs + g s^2}{E c^2 + 2 F cs + G s^2}$\n"
        "$c = \\cos\\theta,\\ s = \\sin\\theta$\n\n"
        f"E = {_num(geo.E)}, F = {_num(geo.F)}, G = {_num(geo.G)}\n"
        f"e = {_num(geo.e)}, f = {_num(geo.f)}, g = {_num(geo.g)}",
        fontsize=8,
        va="bottom",
    )
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png")
    return geo
