"""Convergence of the course's curvature estimators (:mod:`.fields`: uniform and cotangent
``H``, angle-deficit ``K``, each vertex area) to the exact curvature of a parametric surface
under refinement: the tables of ``meshlap surface --convergence`` and of the course report.

The levels, the exact values and the observed orders are the one machinery of
:mod:`.refinement` (shared with :mod:`.study`); this module chooses the estimators, the meshes
(the surface's grid, or icospheres for the sphere), the statistics (max and mean error, where
the max is) and prints the table. References: see :mod:`.refinement`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import MeshError
from ..options import MESHERS, Mesher, check_choice
from ..surfaces.catalogue import ParametricSurface, get_surface
from ..surfaces.meshing import (
    MAX_MESH_BYTES,
    STUDY_BYTES_PER_CELL,
    STUDY_KEPT_BYTES_PER_CELL,
    check_mesh_res,
    mesh_surface,
)
from ..types import FloatArray, IntArray
from .fields import gaussian_curvature, mean_curvature_cotan, mean_curvature_uniform
from .refinement import Level, observed_orders, sphere_level, surface_level

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
            f"(H > 0 on spheres, Δx = −2Hn; max|H| = {self.ref_scale['H']:.4g}, "
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


def _study(
    surface: str, mesher: str, levels: Sequence[int], exclude_poles: bool, meshes: Sequence[Level]
) -> ConvergenceStudy:
    keys = ("max", "mean", "worst_uv", "worst_is_pole")
    errs: dict[str, dict[str, list[Any]]] = {e: {k: [] for k in keys} for e in ESTIMATORS}
    n_v, n_c, hs = [], [], []
    scale = {"H": 0.0, "K": 0.0}
    for lev in meshes:
        est = _discrete_estimates(lev.V, lev.F)
        idx = np.flatnonzero(lev.exact.compared)
        if len(idx) == 0:
            raise MeshError("the mesh has no interior vertex to compare; use a finer res", "res")
        n_v.append(len(lev.V))
        n_c.append(len(idx))
        hs.append(lev.h)
        for name in ESTIMATORS:
            ref = lev.exact.H if name.startswith("H") else lev.exact.K
            err = np.abs(est[name][idx] - ref[idx])
            w = idx[int(np.argmax(err))]
            errs[name]["max"].append(float(err.max()))
            errs[name]["mean"].append(float(err.mean()))
            errs[name]["worst_uv"].append(None if lev.uv is None else lev.uv[w].tolist())
            errs[name]["worst_is_pole"].append(bool(lev.pole[w]))
        H, K = lev.exact.H[idx], lev.exact.K[idx]
        scale = {"H": float(np.abs(H).max()), "K": float(np.abs(K).max())}
    # rounding level: 1e-10 of the curvature scale (K in its square), so that an estimator that
    # is exact on this mesh (the cylinder, the level-1 icosphere) gets no meaningless order
    kappa = max(scale["H"], math.sqrt(scale["K"]), 1e-300)
    for name, d in errs.items():
        floor = 1e-10 * (kappa if name.startswith("H") else kappa * kappa)
        d["order_max"] = observed_orders(hs, d["max"], floor)
        d["order_mean"] = observed_orders(hs, d["mean"], floor)
    return ConvergenceStudy(surface, mesher, list(levels), exclude_poles, n_v, n_c, hs, scale, errs)


def convergence_study(
    surface: ParametricSurface | str,
    resolutions: Sequence[int] = (8, 16, 32, 64, 128),
    mesher: Mesher = "grid",
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
    have one-sided stencils); the exact ``H`` has the core's sign (positive on spheres). The
    observed order is the slope of ``log(error)`` against ``log(h)``, ``h`` the mean edge
    length: 2 means the error shrinks 4× when ``h`` halves, 0 that it stalls.

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
    levels = _check_levels(surface, mesher, resolutions, exclude_poles)
    meshes = []
    for lev in levels:
        meshes.append(_make_level(surface, mesher, lev, exclude_poles))
        if progress is not None:
            progress(f"{surface.name}: {mesher} level {lev}, {len(meshes[-1].V)} vertices")
    return _study(surface.name, mesher, levels, exclude_poles, meshes)


def _check_levels(
    surface: ParametricSurface, mesher: str, resolutions: Sequence[int], exclude_poles: bool
) -> list[int]:
    """The levels as ints, every one checked before the first (slow) one is meshed: its
    resolution, its memory (the levels kept plus the largest one's estimators, against
    :data:`~meshlap_core.surfaces.meshing.MAX_MESH_BYTES`) and that it has a vertex to compare."""
    check_choice(mesher, MESHERS, "mesher")
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
    if mesher == "icosphere":
        for lev in levels:
            if not 0 <= lev <= 7:
                raise MeshError(f"icosphere subdivision levels must be in 0..7, got {lev}", "res")
        return levels
    cells = []
    for lev in levels:
        nu, nv = check_mesh_res(surface, lev, "res", STUDY_BYTES_PER_CELL)
        _check_has_interior(surface, lev, nu, nv, exclude_poles)
        cells.append(nu * nv)
    need = STUDY_KEPT_BYTES_PER_CELL * sum(cells) + STUDY_BYTES_PER_CELL * max(cells)
    if need > MAX_MESH_BYTES:
        raise MeshError(
            f"the {len(levels)} levels together would need about {need / 1024**3:.2f} GiB of "
            f"memory, more than the {MAX_MESH_BYTES / 1024**3:.2f} GiB limit: use fewer or "
            "smaller levels",
            "res",
        )
    return levels


def _check_has_interior(
    surface: ParametricSurface, lev: int, nu: int, nv: int, exclude_poles: bool
) -> None:
    """Refuse a grid level without an interior vertex to compare, from a mesh of at most 3 × 3
    cells: whether a vertex is interior (and not a pole) depends only on whether each
    direction has 1, 2 or at least 3 cells, on its closedness and on the poles."""
    m = mesh_surface(surface, (min(nu, 3), min(nv, 3)))
    if not np.any(~m.boundary & ~(m.pole if exclude_poles else False)):
        raise MeshError(
            f"level {lev}: the mesh has no interior vertex to compare; use a finer res", "res"
        )


def _make_level(surface: ParametricSurface, mesher: str, lev: int, exclude_poles: bool) -> Level:
    """One level of the study: the mesh, the vertices compared (every interior one, the poles
    too unless ``exclude_poles``) and the exact values there (the limits at the poles)."""
    if mesher == "icosphere":
        return sphere_level(float(surface.params.get("r", 1.0)), lev)
    m = mesh_surface(surface, lev)
    compare = ~m.boundary & ~(m.pole if exclude_poles else False)
    return surface_level(surface, lev, m, compared=compare, pole_limits=True, directions=False)
