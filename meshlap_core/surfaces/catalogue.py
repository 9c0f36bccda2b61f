"""The catalogue of parametric surfaces: :class:`ParametricSurface` and the eight shipped ones.

``meshlap_core.surfaces.torus`` here is the *parametric* torus (a :class:`ParametricSurface`,
exact geometry at any ``(u, v)``); :func:`meshlap_core.primitives.torus_mesh` is the *triangle
mesh* ``(V, F)`` of the same parameterization (equal to ``mesh_surface(torus(), (nu, nv))``).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import MeshError
from ..types import FloatArray

SurfaceMap = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""``p(u, v)``: ``u, v`` broadcastable arrays of shape ``S`` → points of shape ``S + (3,)``."""
DerivativeMap = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, ...]]
"""``(u, v) → (p_u, p_v, p_uu, p_uv, p_vv)``, each of shape ``S + (3,)``."""
EDGES: tuple[str, ...] = ("u0", "u1", "v0", "v1")


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
        return np.real(evaluate_surface(self, uu, vv))


def evaluate_surface(surface: ParametricSurface, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``surface.p(u, v)`` broadcast, with the shape it must have checked: ``(*u.shape, 3)``."""
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
    G = 1 + u², e = g = 0, f = 1/√(1+u²)``, ``κ = ±1/(1+u²)``, and at the origin
    ``κₙ(θ) = sin 2θ``.

    ``c = 0`` degenerates to the flat unit disc in polar coordinates: closed in ``v``, with a
    pole at its centre ``u = 0`` (declared, so meshes collapse it and the point is singular);
    its default point is then ``(0.5, 0)``.
    """
    c = _finite(c, "c")

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
        closed_v=c == 0,
        poles=("u0",) if c == 0 else (),
        derivatives=d,
        default_uv=(0.0, 0.0) if c != 0 else (0.5, 0.0),
        description="minimal surface (u cos v, u sin v, c v); hyperbolic, H = 0",
        params={"c": c},
    )


def sphere(r: float = 1.0) -> ParametricSurface:
    """Sphere ``p(u,v) = r (sin u cos v, sin u sin v, cos u)``, polar angle ``u ∈ [0,π]``,
    azimuth ``v ∈ [0,2π]`` (closed in ``v``, poles at ``u = 0`` and ``u = π``).

    ``n`` points outwards; ``K = 1/r²`` and every point is umbilic with ``κ₁ = κ₂ = 1/r``.
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


def ellipsoid(a: float = 1.5, b: float = 1.0, c: float = 0.75) -> ParametricSurface:
    """Ellipsoid ``p(u,v) = (a sin u cos v, b sin u sin v, c cos u)`` with semi-axes
    ``a, b, c``, polar angle ``u ∈ [0,π]``, azimuth ``v ∈ [0,2π]`` (closed in ``v``, poles at
    ``u = 0`` and ``u = π``, like :func:`sphere`).

    ``n`` points outwards. With ``h = √(x²/a⁴ + y²/b⁴ + z²/c⁴)`` at the point ``(x, y, z)``:
    ``K = 1 / (a²b²c² h⁴)`` and ``H = (a² + b² + c² − x² − y² − z²) / (2 a²b²c² h³)`` (both
    reduce to ``1/r²`` and ``1/r`` on a sphere). With distinct axes it has four umbilics (in
    the plane of the largest and smallest axes); elsewhere ``κ₁ > κ₂ > 0``.
    """
    a, b, c = _positive(a, "a"), _positive(b, "b"), _positive(c, "c")

    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return _xyz(a * np.sin(u) * np.cos(v), b * np.sin(u) * np.sin(v), c * np.cos(u))

    def d(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
        su, cu, sv, cv = np.sin(u), np.cos(u), np.sin(v), np.cos(v)
        z = np.zeros_like(u * v)
        return (
            _xyz(a * cu * cv, b * cu * sv, -c * su),
            _xyz(-a * su * sv, b * su * cv, z),
            _xyz(-a * su * cv, -b * su * sv, -c * cu),
            _xyz(-a * cu * sv, b * cu * cv, z),
            _xyz(-a * su * cv, -b * su * sv, z),
        )

    return ParametricSurface(
        "ellipsoid",
        p,
        (0.0, np.pi, 0.0, 2 * np.pi),
        closed_v=True,
        poles=("u0", "u1"),
        derivatives=d,
        default_uv=(np.pi / 3, np.pi / 4),
        description="ellipsoid with semi-axes a, b, c; elliptic, four umbilics",
        params={"a": a, "b": b, "c": c},
    )


def ellipsoid_curvature(
    a: float, b: float, c: float, X: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The closed-form ``H`` and ``K`` of the ellipsoid ``x²/a² + y²/b² + z²/c² = 1`` at its
    points ``X`` (n,3) (outward normal, ``H > 0``): see :func:`ellipsoid`.

    Returns
    -------
    H, K : (n,) float
    """
    X = np.asarray(X, dtype=np.float64)
    h = np.sqrt((X[:, 0] / a**2) ** 2 + (X[:, 1] / b**2) ** 2 + (X[:, 2] / c**2) ** 2)
    abc2 = (a * b * c) ** 2
    H = (a * a + b * b + c * c - np.einsum("ij,ij->i", X, X)) / (2.0 * abc2 * h**3)
    return H, 1.0 / (abc2 * h**4)


def torus(R: float = 3.0, r: float = 1.0) -> ParametricSurface:
    """Parametric torus ``p(u,v) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v)`` on
    ``[0,2π]²`` (a :class:`ParametricSurface`, not a mesh).

    The parameterization of :func:`meshlap_core.primitives.torus_mesh`, which returns the
    triangle mesh ``(V, F)`` (same defaults, outward ``n``).
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

    At the origin ``κ₁ = 2a`` along ``v`` and ``κ₂ = −2a`` along ``u`` (for ``a > 0``; the
    surface bends towards ``n`` along ``u``), ``K = −4a²``.
    """
    a = _finite(a, "a")

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
    a = _finite(a, "a")

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

    ``n`` points outwards; ``K = 0``, ``κ₁ = 1/r`` (around the axis), ``κ₂ = 0`` (along it):
    parabolic.
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


def _finite(x: float, name: str) -> float:
    x = float(x)
    if not math.isfinite(x):
        raise MeshError(f"must be a finite number, got {x}", name)
    return x


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
    "ellipsoid": ellipsoid,
}
"""Factories of the shipped surfaces by name; ``helicoid`` is the default."""


def get_surface(name: str | ParametricSurface, **params: float) -> ParametricSurface:
    """The shipped surface called ``name`` (``-`` and ``_`` are interchangeable), built with
    ``params`` (e.g. ``get_surface("torus", R=2, r=0.5)``); a surface passes through.

    Raises
    ------
    MeshError
        For an unknown name (the message lists the known ones) or an unknown parameter.

    Examples
    --------
    On the outer equator of a torus (``v = 0``) ``K = 1 / (r (R + r))``:

    >>> from meshlap_core import get_surface, point_geometry
    >>> torus = get_surface("torus", R=2, r=0.5)
    >>> g = point_geometry(torus, 0.0, 0.0)
    >>> round(g.K, 9), round(1 / (0.5 * 2.5), 9)
    (0.8, 0.8)
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
