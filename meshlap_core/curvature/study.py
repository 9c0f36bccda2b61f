"""Principal-curvature estimators against the exact curvature of parametric surfaces: the
error at every vertex (the lab's error map) and the table of errors and observed orders under
refinement (``meshlap curvature-study``).

The meshes are :func:`meshlap_core.surfaces.mesh_surface` grids, optionally made irregular
(``jitter``: every interior vertex moves in the parameter plane by up to ``jitter`` of a cell,
and is evaluated on the surface there, so the exact values stay exact; ``flips``: a fraction of
the edges flipped) and noisy (``noise``:
Gaussian displacement along the normal of standard deviation ``noise × bounding-box
diagonal``, the exact values being those of the clean point). Errors are measured at the
vertices away from the boundary and the poles (one-sided stencils and sliver cells there), in
the project's sign convention (``H > 0`` on a sphere, ``κ₁ ≥ κ₂``). The levels, the exact values
and the orders are those of :mod:`.refinement`, the machinery :mod:`.convergence` uses too.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import MeshError
from ..noise import add_noise, check_noise
from ..options import CURVATURE_ESTIMATORS, PRINCIPAL_FIELDS, check_choice
from ..surfaces import ParametricSurface, SurfaceMesh, get_surface, mesh_surface
from ..types import FloatArray, IntArray, as_real
from .estimators import estimate_curvature
from .principal import PrincipalCurvatures
from .refinement import (
    ExactPrincipal,
    Level,
    fitted_order,
    observed_orders,
    surface_level,
)

STUDY_COLUMNS: tuple[str, ...] = (
    "surface",
    "estimator",
    "res",
    "n_vertices",
    "n_compared",
    "h",
    "H_rms",
    "H_rel",
    "H_order",
    "K_rms",
    "K_rel",
    "K_order",
    "k_max_err",
    "angle_median_deg",
    "angle_p95_deg",
)
"""Columns of :func:`curvature_study` rows (``*_rel``: RMS error over the RMS of the exact
``max(|κ₁|, |κ₂|)`` (resp. its square for K); ``*_order``: log-log slope against ``h`` from the
previous resolution, empty at the first; angles: ``d1`` against the exact direction where
``|κ₁ − κ₂| > 10 %`` of ``max |κ|``)."""


H_AND_K: tuple[str, ...] = PRINCIPAL_FIELDS[2:4]
"""The two quantities whose orders are fitted and plotted (mean and Gaussian curvature)."""


def flip_edges(V: FloatArray, F: IntArray, fraction: float, seed: int = 0) -> IntArray:
    """Flip a random ``fraction`` of the interior edges (an irregular triangulation of the same
    vertices), vectorized: candidates whose two faces no other candidate touches, that stay
    convex in their quad (both new triangles keep the orientation of the old normal) and do not
    create an existing edge.

    Returns
    -------
    F2 : (m,3) int
        Same faces count and orientation; ``F`` is not modified.
    """
    if not 0.0 <= float(fraction) <= 1.0:
        raise MeshError(f"must be between 0 and 1, got {fraction!r}", "flips")
    F = np.asarray(F, dtype=np.int64)
    n, m = len(V), len(F)
    A, B = F.ravel(), np.roll(F, -1, axis=1).ravel()
    C = np.roll(F, -2, axis=1).ravel()  # the corner opposite the half-edge A -> B
    fid = np.repeat(np.arange(m), 3)
    key = A * n + B
    order = np.argsort(key)
    sk = key[order]
    pos = np.clip(np.searchsorted(sk, B * n + A), 0, len(sk) - 1)
    twin = np.where(sk[pos] == B * n + A, order[pos], -1)
    cand = np.flatnonzero((twin >= 0) & (A < B))
    rng = np.random.default_rng(seed)
    cand = cand[rng.random(len(cand)) < fraction]
    f1, f2 = fid[cand], fid[twin[cand]]
    used = np.bincount(np.concatenate([f1, f2]), minlength=m)
    keep = (used[f1] == 1) & (used[f2] == 1)
    h, a, b, c, d = cand[keep], A[cand[keep]], B[cand[keep]], C[cand[keep]], C[twin[cand[keep]]]
    # the new edge c-d: refuse if it exists already or a new triangle turns over
    exists = np.isin(c * n + d, key) | np.isin(d * n + c, key)
    nrm = np.cross(V[b] - V[a], V[c] - V[a]) + np.cross(V[a] - V[b], V[d] - V[b])
    # the quad a, d, b, c (counter-clockwise) gets the diagonal d-c: faces (a, d, c), (d, b, c)
    t1 = np.cross(V[d] - V[a], V[c] - V[a])
    t2 = np.cross(V[b] - V[d], V[c] - V[d])
    ok = ~exists & (np.einsum("ij,ij->i", t1, nrm) > 0) & (np.einsum("ij,ij->i", t2, nrm) > 0)
    F2 = F.copy()
    F2[fid[h[ok]]] = np.stack([a[ok], d[ok], c[ok]], axis=1)
    F2[fid[twin[h[ok]]]] = np.stack([d[ok], b[ok], c[ok]], axis=1)
    return F2


def jittered_mesh(
    surface: ParametricSurface | str, res: int | Sequence[int], jitter: float = 0.0, seed: int = 0
) -> SurfaceMesh:
    """The surface's grid mesh with every interior vertex moved in the parameter plane by up to
    ``jitter`` of a cell (uniform, ``seed``) and evaluated on the surface there: the vertices
    stay on the surface, so the exact values at them are exact (see :func:`perturbed_mesh`)."""
    s = get_surface(surface)
    jitter = as_real(jitter, "jitter")
    if not (0.0 <= jitter <= 0.45):
        raise MeshError(f"must be between 0 and 0.45 of a cell, got {jitter!r}", "jitter")
    m = mesh_surface(s, res)
    if jitter > 0:
        rng = np.random.default_rng(seed)
        u0, u1, v0, v1 = s.domain
        cell = np.array([(u1 - u0) / m.res[0], (v1 - v0) / m.res[1]])
        free = ~m.pole & ~m.boundary
        uv = m.uv.copy()
        uv[free] += jitter * cell * rng.uniform(-1.0, 1.0, (int(free.sum()), 2))
        uv[:, 0] = np.clip(uv[:, 0], u0, u1)
        uv[:, 1] = np.clip(uv[:, 1], v0, v1)
        V = m.V.copy()
        V[free] = s(uv[free, 0], uv[free, 1])
        m = SurfaceMesh(V, m.F, uv, m.pole, m.boundary, m.surface, m.res)
    return m


def flipped_and_noisy(
    m: SurfaceMesh,
    noise: float = 0.0,
    seed: int = 0,
    flips: float = 0.0,
    normals: FloatArray | None = None,
) -> tuple[SurfaceMesh, FloatArray]:
    """``m`` with a fraction ``flips`` of its interior edges flipped (:func:`flip_edges`) and
    its positions displaced along the normal by Gaussian noise of standard deviation
    ``noise × bbox diagonal`` (the last two steps of :func:`perturbed_mesh`; ``m`` unchanged).

    ``normals`` : (n,3) float, optional
        The unit vertex normals of ``m`` (:func:`meshlap_core.curvature.vertex_normals`) when
        already known (the lab caches them): used when no edge is flipped, the same noise as
        :func:`meshlap_core.noise.add_noise` with ``mode="normal"`` without recomputing them.

    Returns
    -------
    mesh : SurfaceMesh
        The flipped faces, the clean ``V`` and ``uv``.
    V : (n,3) float
        The positions with the noise.
    """
    flips = as_real(flips, "flips")
    if not 0.0 <= flips <= 1.0:  # (checked here: a negative or NaN fraction is not "none")
        raise MeshError(f"must be between 0 and 1, got {flips!r}", "flips")
    noise = as_real(noise, "noise")
    if noise < 0:
        raise MeshError(f"must be 0 or more, got {noise!r}", "noise")
    if flips > 0:
        m = SurfaceMesh(
            m.V, flip_edges(m.V, m.F, flips, seed), m.uv, m.pole, m.boundary, m.surface, m.res
        )
    if noise > 0 and normals is not None and not flips > 0:
        sigma = check_noise(m.V, noise)
        z = np.random.default_rng(seed).standard_normal(len(m.V))
        return m, m.V + (sigma * z)[:, None] * normals
    V = add_noise(m.V, m.F, noise, mode="normal", seed=seed) if noise > 0 else m.V
    return m, V


def perturbed_mesh(
    surface: ParametricSurface | str,
    res: int | Sequence[int],
    noise: float = 0.0,
    jitter: float = 0.0,
    seed: int = 0,
    flips: float = 0.0,
) -> tuple[SurfaceMesh, FloatArray]:
    """A surface mesh made irregular and noisy (see the module notes):
    :func:`jittered_mesh` then :func:`flipped_and_noisy`.

    Parameters
    ----------
    surface : ParametricSurface or str
    res : int or (nu, nv)
    noise : float
        Standard deviation of the normal displacement, a fraction of the bbox diagonal.
    jitter : float
        Largest parameter displacement of an interior vertex, a fraction of a cell (0 to 0.45).
    seed : int
    flips : float
        Fraction of the interior edges to flip (:func:`flip_edges`), 0 to 1.

    Returns
    -------
    mesh : SurfaceMesh
        With the jittered ``uv`` (and clean ``V`` on the surface).
    V : (n,3) float
        The positions with the noise.
    """
    return flipped_and_noisy(jittered_mesh(surface, res, jitter, seed), noise, seed, flips)


def vertex_errors(result: PrincipalCurvatures, exact: ExactPrincipal) -> dict[str, FloatArray]:
    """Per-vertex errors of an estimate (the error maps), each ``(n,)``, NaN where not compared:
    ``H``, ``K``, ``k1``, ``k2`` (signed, estimate − exact) and ``angle`` (degrees between
    ``d1`` and the exact direction, NaN near umbilics and without exact directions)."""
    keep = exact.compared
    gap = np.abs(exact.k1 - exact.k2) > 0.1 * np.maximum(np.abs(exact.k1), np.abs(exact.k2))
    if exact.d1 is None:
        gap = np.zeros(len(gap), dtype=bool)
        cos = np.ones(len(gap))
    else:
        cos = np.abs(np.sum(result.d1 * exact.d1, axis=1))
    out = {
        "H": result.H - exact.H,
        "K": result.K - exact.K,
        "k1": result.k1 - exact.k1,
        "k2": result.k2 - exact.k2,
        "angle": np.where(gap, np.degrees(np.arccos(np.clip(cos, 0.0, 1.0))), np.nan),
    }
    return {k: np.where(keep, v, np.nan) for k, v in out.items()}


def _rms(x: FloatArray) -> float:
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x * x))) if x.size else math.nan


def curvature_study(
    surfaces: Sequence[str] = ("sphere", "torus", "saddle", "helicoid"),
    estimators: Sequence[str] = CURVATURE_ESTIMATORS,
    levels: Sequence[int] = (16, 32, 64),
    noise: float = 0.0,
    jitter: float = 0.0,
    seed: int = 0,
    options: dict[str, dict[str, Any]] | None = None,
    flips: float = 0.0,
    progress: Any = None,
) -> list[dict[str, Any]]:
    """Errors of every estimator on every surface at every resolution, with observed orders.

    Parameters
    ----------
    surfaces : names of :data:`meshlap_core.surfaces.SURFACES`
    estimators : names of :data:`~meshlap_core.options.CURVATURE_ESTIMATORS`
    levels : cells per direction (the torus gets twice as many around its axis)
    noise, jitter, seed, flips : see :func:`perturbed_mesh`
    options : estimator name -> its keyword options (e.g. ``{"jet": {"radius": 0.2}}``)
    progress : callable, optional
        ``progress(fraction, message)`` before each estimate (a viewer job's reporter, which
        stops the study when it is cancelled).

    Returns
    -------
    rows : list of dict
        One per (surface, estimator, level), keys :data:`STUDY_COLUMNS`.
    """
    for e in estimators:
        check_choice(e, CURVATURE_ESTIMATORS, "estimator")
    if not levels or any(int(n) < 3 for n in levels):
        raise MeshError(f"levels must be at least 3 cells, got {list(levels)}", "levels")
    options = options or {}
    rows: list[dict[str, Any]] = []
    total, done = len(surfaces) * len(estimators) * len(levels), 0
    for name in surfaces:
        s = get_surface(name)
        meshes = [_level(s, int(n), noise, jitter, seed, flips) for n in levels]
        for est in estimators:
            group = []
            for lev in meshes:
                if progress is not None:
                    progress(done / total, f"{s.name}, {est}, {lev.res} cells")
                done += 1
                r = estimate_curvature(lev.V, lev.F, est, **options.get(est, {}))  # type: ignore[arg-type]
                group.append(_row(s.name, est, lev, r))
            h = [row["h"] for row in group]
            for q in H_AND_K:
                orders = observed_orders(h, [row[f"{q}_rms"] for row in group])
                for row, order in zip(group, [None, *orders], strict=True):
                    row[f"{q}_order"] = order
            rows.extend({c: row[c] for c in STUDY_COLUMNS} for row in group)
    return rows


def _level(
    s: ParametricSurface, n: int, noise: float, jitter: float, seed: int, flips: float
) -> Level:
    """The study's level of ``n`` cells (the torus twice as many around its axis): the
    :func:`perturbed_mesh`, the noisy positions estimated, the exact values at the clean ones."""
    res = (2 * n, n) if s.name == "torus" else (n, n)
    m, V = perturbed_mesh(s, res, noise, jitter, seed, flips)
    return surface_level(s, n, m, V)


def _row(surface: str, estimator: str, lev: Level, r: PrincipalCurvatures) -> dict[str, Any]:
    """One row of :data:`STUDY_COLUMNS` but the orders: the errors of ``r`` at ``lev``."""
    ex = lev.exact
    err = vertex_errors(r, ex)
    scale = _rms(np.maximum(np.abs(ex.k1), np.abs(ex.k2))[ex.compared])
    angle = err["angle"]
    some = bool(np.isfinite(angle).any())
    row: dict[str, Any] = {
        "surface": surface,
        "estimator": estimator,
        "res": lev.res,
        "n_vertices": len(lev.V),
        "n_compared": int(ex.compared.sum()),
        "h": lev.h,
        "H_rms": _rms(err["H"]),
        "K_rms": _rms(err["K"]),
        "k_max_err": float(np.nanmax(np.abs(np.concatenate([err["k1"], err["k2"]])))),
        "angle_median_deg": float(np.nanmedian(angle)) if some else math.nan,
        "angle_p95_deg": float(np.nanpercentile(angle, 95)) if some else math.nan,
    }
    row["H_rel"] = row["H_rms"] / scale if scale > 0 else math.nan
    row["K_rel"] = row["K_rms"] / scale**2 if scale > 0 else math.nan
    return row


def fitted_orders(rows: Sequence[dict[str, Any]]) -> dict[tuple[str, str], dict[str, float]]:
    """The order of every (surface, estimator) of :func:`curvature_study` rows: the slope of
    the least-squares line through ``(log h, log RMS error)`` over all its resolutions (for
    ``H`` and ``K``; NaN with fewer than two positive finite errors).

    Returns
    -------
    dict
        ``(surface, estimator) -> {"H": order, "K": order}``.
    """
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault((r["surface"], r["estimator"]), []).append(r)
    return {
        key: {
            q: fitted_order([r["h"] for r in group], [r[f"{q}_rms"] for r in group])
            for q in H_AND_K
        }
        for key, group in groups.items()
    }


def write_study_figure(rows: Sequence[dict[str, Any]], path: Any) -> None:
    """The log-log plot of the relative RMS error against the mean edge length ``h``, one line
    per (surface, estimator), ``H`` left and ``K`` right, the :func:`fitted_orders` in the
    legend; a PNG written atomically (matplotlib's Agg canvas, no pyplot).

    Raises
    ------
    MeshError
        ``path`` does not end in ``.png``, or no row to plot.
    """
    from pathlib import Path

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullFormatter

    from ..io import atomic_write

    path = Path(path)
    if path.suffix.lower() != ".png":
        raise MeshError(f"the figure is written as PNG; got {path.suffix or 'no suffix'!r}", path)
    if not rows:
        raise MeshError("no rows to plot", path)
    orders = fitted_orders(rows)
    fig = Figure(figsize=(11.0, 4.8), dpi=110)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2)
    for ax, q in zip(axes, H_AND_K, strict=True):
        for (surface, est), order in orders.items():
            group = [r for r in rows if (r["surface"], r["estimator"]) == (surface, est)]
            h = np.array([r["h"] for r in group], dtype=np.float64)
            e = np.array([r[f"{q}_rel"] for r in group], dtype=np.float64)
            ok = np.isfinite(e) & (e > 0)
            if ok.any():
                tag = f"{order[q]:.2f}" if math.isfinite(order[q]) else "-"
                ax.loglog(h[ok], e[ok], "o-", ms=3, lw=1.2, label=f"{surface} {est}: {tag}")
        ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels overlap on short spans
        ax.set_xlabel("mean edge length h")
        ax.set_ylabel(f"relative RMS error of {q}")
        ax.set_title(f"{q}: error against h (fitted order in the legend)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, framealpha=0.9)
    fig.tight_layout()
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png")
