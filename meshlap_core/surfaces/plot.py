"""The normal-curvature figure ``κₙ(θ)`` of one point, ``θ`` the angle in the tangent plane
(matplotlib imported lazily)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError
from ..options import DEFAULT_SURFACE_SIGNS, SurfaceSigns
from .catalogue import ParametricSurface
from .geometry import PointGeometry, normal_curvature_curve, point_geometry


def _num(x: float) -> str:
    """Compact number for labels: 4 significant digits, no ``-0``, tiny values as 0."""
    x = float(x)
    return "0" if abs(x) < 1e-12 else f"{x:.4g}"


KN_AXIS_LABEL = "θ: direction angle in the tangent plane, from p_u towards n × p_u (rad)"
"""The x axis of the ``κₙ`` figure: the tangent-plane angle (:mod:`.angles`), not ``θ_uv``."""


def normal_curvature_figure(
    surface: ParametricSurface | str,
    u: float | None,
    v: float | None,
    n: int = 721,
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS,
) -> tuple[Any, PointGeometry]:
    """The figure of ``κₙ(θ)`` over ``θ ∈ [0, 2π]``, ``θ`` the direction's angle in the tangent
    plane from the unit ``p_u`` towards ``n × p_u`` (the x axis says so: :data:`KN_AXIS_LABEL`),
    with ``κ₁, κ₂`` and their angles marked (90° apart), the forms and the sign of ``II``.

    matplotlib is imported here (Agg canvas, no pyplot, no GUI), so importing this module stays
    light.

    Parameters
    ----------
    surface : ParametricSurface or str
    u, v : float or None
        The point (``None``: the surface's default point).
    n : int
        Samples of ``θ``.
    signs : {"outward", "do-carmo"}
        The sign of ``II`` (:func:`~.geometry.point_geometry`), named on the figure.

    Returns
    -------
    figure : matplotlib.figure.Figure
    point : PointGeometry
        The point the figure shows.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    geo = point_geometry(surface, u, v, signs=signs)
    theta, kn = normal_curvature_curve(surface, geo.u, geo.v, n, angle="tangent", signs=signs)
    fig = Figure(figsize=(8.6, 4.6), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.1, 0.14, 0.6, 0.7))
    ax.plot(theta, kn, color="black", lw=1.8, label=r"$\kappa_n(\theta)$")
    ax.axhline(geo.k1, color="tab:red", lw=1, ls="--", label=rf"$\kappa_1 = {_num(geo.k1)}$")
    ax.axhline(geo.k2, color="tab:blue", lw=1, ls="--", label=rf"$\kappa_2 = {_num(geo.k2)}$")
    ax.axhline(0.0, color="0.6", lw=0.6)
    _mark_principal_directions(ax, geo)
    ticks = np.arange(0, 2 * np.pi + 1e-9, np.pi / 4)
    labels = ["0", "π/4", "π/2", "3π/4", "π", "5π/4", "3π/2", "7π/4", "2π"]
    ax.set_xticks(ticks, labels)
    ax.set_xlim(0, 2 * np.pi)
    span = max(geo.k1 - geo.k2, 0.25 * max(abs(geo.k1), abs(geo.k2)), 1e-3)
    ax.set_ylim(geo.k2 - 0.2 * span, geo.k1 + 0.2 * span)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_xlabel(KN_AXIS_LABEL)
    ax.set_ylabel(r"normal curvature $\kappa_n$")
    ax.set_title(
        f"{geo.surface} at (u, v) = ({geo.u:.4g}, {geo.v:.4g}): "
        f"K = {_num(geo.K)}, H = {_num(geo.H)}, {geo.classification}\n"
        f"signs: {geo.signs} ({_SIGNS_FORMULA[geo.signs]})",
        fontsize=10,
    )
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, framealpha=0.9)
    fig.text(
        0.72,
        0.14,
        "$\\kappa_n = \\dfrac{e a^2 + 2 f ab + g b^2}{E a^2 + 2 F ab + G b^2}$\n"
        "for the tangent $a\\,p_u + b\\,p_v$ at angle $\\theta$\n"
        "$= \\kappa_1 \\cos^2(\\theta - \\theta_1) + \\kappa_2 \\sin^2(\\theta - \\theta_1)$\n\n"
        f"E = {_num(geo.E)}, F = {_num(geo.F)}, G = {_num(geo.G)}\n"
        f"e = {_num(geo.e)}, f = {_num(geo.f)}, g = {_num(geo.g)}",
        fontsize=8,
        va="bottom",
    )
    return fig, geo


_SIGNS_FORMULA = {
    "outward": "e = −p_uu · n, meshlap's: H > 0 on spheres",
    "do-carmo": "e = p_uu · n, do Carmo's: meshlap's II, H, κ negated",
}


def plot_normal_curvature(
    surface: ParametricSurface | str,
    u: float | None,
    v: float | None,
    path: str | os.PathLike,
    n: int = 721,
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS,
) -> PointGeometry:
    """Save a PNG of :func:`normal_curvature_figure` (``κₙ`` against the tangent-plane angle).

    The file is written atomically; its text chunks name what is drawn (``Title``, and
    ``Description``: the x axis label, the y axis and the signs) so that a reader of the PNG
    alone knows which angle the axis is.

    Returns
    -------
    PointGeometry
        The point the figure shows.
    """
    from ..io import atomic_write

    path = Path(path)
    if path.suffix.lower() != ".png":
        raise MeshError(f"the plot is written as PNG; got {path.suffix or 'no suffix'!r}", path)
    fig, geo = normal_curvature_figure(surface, u, v, n, signs)
    ax = fig.axes[0]
    metadata = {
        "Title": f"normal curvature of the {geo.surface} at (u, v) = ({geo.u:.6g}, {geo.v:.6g})",
        "Description": f"x: {ax.get_xlabel()}; y: normal curvature k_n; signs: {geo.signs}",
    }
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png", metadata=metadata)
    return geo


def _mark_principal_directions(ax: Any, geo: PointGeometry) -> None:
    """Dotted lines and dots where ``κₙ`` reaches ``κ₁`` and ``κ₂`` (or a note at an umbilic),
    at the tangent-plane angles ``theta_max``, ``theta_min`` (the parameter angles in the
    legend)."""
    if geo.classification in ("umbilic", "planar"):
        ax.plot([], [], " ", label="κn is constant: every\ndirection is principal")
        return
    for t in (geo.theta_max, geo.theta_max + np.pi):
        ax.axvline(t, color="tab:red", lw=0.8, ls=":")
        ax.plot([t], [geo.k1], "o", color="tab:red", zorder=3)
    for t in (geo.theta_min, geo.theta_min + np.pi):
        ax.axvline(t, color="tab:blue", lw=0.8, ls=":")
        ax.plot([t], [geo.k2], "o", color="tab:blue", zorder=3)
    for color, what, i, t, t_uv in (
        ("tab:red", "max", 1, geo.theta_max, geo.theta_uv_max),
        ("tab:blue", "min", 2, geo.theta_min, geo.theta_uv_min),
    ):
        ax.plot(
            [],
            [],
            "o:",
            color=color,
            label=rf"{what} at $\theta_{i}$ = {np.degrees(t):.4g}° (and +180°)"
            "\n"
            rf"  $\theta_{{uv}}$ = {np.degrees(t_uv):.4g}° in the (u, v) plane",
        )
