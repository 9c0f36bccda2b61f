"""Meshes of a parametric surface under refinement, the exact curvature at their vertices and
the order of an error: the one machinery of the convergence studies, shared by
:mod:`.convergence` (``meshlap surface --convergence``, the course's estimators) and
:mod:`.study` (``meshlap curvature-study``, the principal-curvature estimators).

A :class:`Level` is one mesh of the sequence: the positions the estimators see, its faces, its
mean edge length ``h`` (:func:`~meshlap_core.laplacian.mean_edge_length`, each edge once) and the
exact curvature at its vertices with the vertices where errors are measured
(:class:`ExactPrincipal`). The exact values come from the surface's own fundamental forms
(:func:`~meshlap_core.surfaces.surface_curvature_fields`), in the project's sign convention
(``H > 0`` on a sphere with outward normals, ``κ₁ ≥ κ₂``), the same as the meshes'.

If an error behaves like ``e(h) ≈ C hᵖ``, its order ``p`` is measured two ways:
:func:`observed_orders` between consecutive levels, ``p = log(e₀/e₁) / log(h₀/h₁)`` (2 means
the error shrinks 4× when ``h`` halves, 0 that it stalls), and :func:`fitted_order`, the slope
of the least-squares line through every ``(log h, log e)``.

References
----------
Meyer, Desbrun, Schröder & Barr, "Discrete differential-geometry operators for triangulated
2-manifolds", 2003; Xu, "Convergence of the discrete Laplace–Beltrami operator", 2004;
Hildebrandt, Polthier & Wardetzky, "On the convergence of metric and geometric properties of
polyhedral surfaces", 2006.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..laplacian import mean_edge_length
from ..primitives import icosphere
from ..surfaces.catalogue import EDGES, ParametricSurface, get_surface
from ..surfaces.derivatives import surface_derivatives
from ..surfaces.geometry import surface_curvature_fields
from ..surfaces.meshing import SurfaceMesh
from ..types import BoolArray, FloatArray, IntArray

POLE_INSET = 1e-6
"""A pole vertex's exact values, when asked for, are the limits: evaluated this fraction of the
domain's width inside the parameter rectangle."""


@dataclass(frozen=True)
class ExactPrincipal:
    """Exact curvature at the vertices of a surface mesh (NaN at singular points).

    Attributes
    ----------
    k1, k2, H, K : (n,) float
    d1, d2 : (n,3) float or None
        Unit 3-D principal directions (NaN where the surface has none: a sphere's umbilics);
        ``None`` when not asked for (a study of ``H`` and ``K`` alone keeps every level).
    compared : (n,) bool
        The vertices where errors are measured.
    """

    k1: FloatArray
    k2: FloatArray
    H: FloatArray
    K: FloatArray
    d1: FloatArray | None
    d2: FloatArray | None
    compared: BoolArray


@dataclass(frozen=True)
class Level:
    """One mesh of a refinement sequence and the exact curvature at its vertices.

    Attributes
    ----------
    res : int
        Cells per direction (a grid) or subdivision level (an icosphere).
    V : (n,3) float
        The positions the estimators are given (with the noise, if any).
    F : (m,3) int
    h : float
        Mean edge length of the clean mesh, each edge once.
    exact : ExactPrincipal
        The exact values at the clean vertices, and the vertices compared.
    uv : (n,2) float or None
        The vertices' parameters (``None`` for an icosphere).
    pole : (n,) bool
    """

    res: int
    V: FloatArray
    F: IntArray
    h: float
    exact: ExactPrincipal
    uv: FloatArray | None
    pole: BoolArray


def compared_vertices(m: SurfaceMesh, surface: ParametricSurface, margin: float = 0.1) -> BoolArray:
    """Vertices at least ``margin`` of the domain from an open edge or a pole, ``(n,)`` bool."""
    u, v = m.uv[:, 0], m.uv[:, 1]
    u0, u1, v0, v1 = surface.domain
    keep = ~m.pole & ~m.boundary
    if not surface.closed_u or {"u0", "u1"} & set(surface.poles):
        keep &= np.minimum(u - u0, u1 - u) > margin * (u1 - u0)
    if not surface.closed_v or {"v0", "v1"} & set(surface.poles):
        keep &= np.minimum(v - v0, v1 - v) > margin * (v1 - v0)
    return keep


def _off_the_poles(surface: ParametricSurface, uv: FloatArray, pole: Any) -> FloatArray:
    """``uv`` (a new array) with the pole vertices moved :data:`POLE_INSET` of the domain's
    width inside the rectangle, where the curvature is the pole's limit."""
    uv = np.array(uv, dtype=np.float64).reshape(-1, 2)
    if pole is None or not np.any(pole):
        return uv
    pole = np.asarray(pole, dtype=bool)
    u0, u1, v0, v1 = surface.domain
    eps_u, eps_v = POLE_INSET * (u1 - u0), POLE_INSET * (v1 - v0)
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
    return uv


def exact_curvature_at(
    surface: ParametricSurface | str, uv: Any, pole: Any = None
) -> tuple[FloatArray, FloatArray]:
    """Exact ``H`` and ``K`` at mesh vertices (``H > 0`` on a sphere, the core's sign).

    Parameters
    ----------
    surface : ParametricSurface or str
    uv : (n,2) float
        Vertex parameters, as in :attr:`~meshlap_core.surfaces.SurfaceMesh.uv`.
    pole : (n,) bool, optional
        Pole vertices (singular parameterization): their values are the limits, evaluated
        :data:`POLE_INSET` of the domain width inside the rectangle.

    Returns
    -------
    H_core, K : (n,) float
    """
    surface = get_surface(surface)
    uv = _off_the_poles(surface, uv, pole)
    cf = surface_curvature_fields(surface, uv[:, 0], uv[:, 1])
    return cf.H, cf.K


def exact_principal(
    m: SurfaceMesh,
    surface: ParametricSurface | str,
    compared: BoolArray | None = None,
    pole_limits: bool = False,
    directions: bool = True,
) -> ExactPrincipal:
    """The exact ``κ₁ ≥ κ₂``, ``H``, ``K`` and directions at the vertices of ``m``.

    Parameters
    ----------
    m : SurfaceMesh
    surface : ParametricSurface or str
    compared : (n,) bool, optional
        The vertices where errors are measured; by default :func:`compared_vertices`.
    pole_limits : bool
        Give the pole vertices the limits of the values (as :func:`exact_curvature_at`)
        instead of NaN.
    directions : bool
        Compute ``d1``, ``d2`` (else ``None``).
    """
    s = get_surface(surface)
    uv = _off_the_poles(s, m.uv, m.pole) if pole_limits else m.uv
    u, v = uv[:, 0], uv[:, 1]
    D = surface_derivatives(s, u, v)
    cf = surface_curvature_fields(s, u, v, derivatives=D)
    dirs: list[FloatArray | None] = [None, None]
    if directions:
        for k, w in enumerate((cf.w1, cf.w2)):
            d = w[:, :1] * D.p_u + w[:, 1:] * D.p_v
            dirs[k] = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
    keep = compared_vertices(m, s) if compared is None else compared
    return ExactPrincipal(cf.k1, cf.k2, cf.H, cf.K, dirs[0], dirs[1], keep)


def surface_level(
    surface: ParametricSurface | str,
    res: int,
    m: SurfaceMesh,
    V: FloatArray | None = None,
    compared: BoolArray | None = None,
    pole_limits: bool = False,
    directions: bool = True,
) -> Level:
    """The level ``res`` of a refinement: the surface mesh ``m`` and the exact values.

    Parameters
    ----------
    surface : ParametricSurface or str
    res : int
        The level's resolution as the study counts it (cells per direction).
    m : SurfaceMesh
        The clean mesh: its positions give ``h`` and the exact values.
    V : (n,3) float, optional
        The positions the estimators are given (``m.V`` with noise); by default ``m.V``.
    compared, pole_limits, directions : see :func:`exact_principal`
    """
    exact = exact_principal(m, surface, compared, pole_limits, directions)
    h = mean_edge_length(m.V, m.F)
    return Level(int(res), m.V if V is None else V, m.F, h, exact, m.uv, m.pole)


def sphere_level(radius: float, level: int) -> Level:
    """The icosphere of ``level`` subdivisions and radius ``radius``: every vertex compared,
    ``κ₁ = κ₂ = H = 1/r``, ``K = 1/r²`` and no principal direction (an umbilic: ``None``)."""
    V, F = icosphere(level, radius)
    n = len(V)
    k = np.full(n, 1.0 / radius)
    exact = ExactPrincipal(k, k, k, np.full(n, 1.0 / radius**2), None, None, np.ones(n, bool))
    return Level(int(level), V, F, mean_edge_length(V, F), exact, None, np.zeros(n, bool))


def observed_orders(
    h: Sequence[float], err: Sequence[float], floor: float = 0.0
) -> list[float | None]:
    """Observed orders ``log(e_k/e_{k+1}) / log(h_k/h_{k+1})`` between consecutive levels.

    Parameters
    ----------
    h, err : sequences of float
        The levels' mean edge lengths and errors, in the same order.
    floor : float
        Errors at or below it are at rounding level (an estimator exact on this mesh: the
        cylinder, the level-1 icosphere's Voronoi cotangent ``H``): no order.

    Returns
    -------
    list of float or None
        One fewer than the levels; ``None`` where undefined (equal ``h``, an error at or below
        ``floor``, or not finite).
    """
    out: list[float | None] = []
    for k in range(len(h) - 1):
        e0, e1 = err[k], err[k + 1]
        usable = e0 > floor and e1 > floor and math.isfinite(e0) and math.isfinite(e1)
        if usable and h[k] != h[k + 1]:
            out.append(math.log(e0 / e1) / math.log(h[k] / h[k + 1]))
        else:
            out.append(None)
    return out


def fitted_order(h: Sequence[float], err: Sequence[float]) -> float:
    """The order over all the levels: the slope of the least-squares line through
    ``(log h, log e)`` for the positive finite errors; NaN with fewer than two distinct ``h``."""
    hs = np.asarray(h, dtype=np.float64)
    e = np.asarray(err, dtype=np.float64)
    ok = np.isfinite(e) & (e > 0) & (hs > 0)
    if np.unique(hs[ok]).size < 2:
        return math.nan
    return float(np.polyfit(np.log(hs[ok]), np.log(e[ok]), 1)[0])
