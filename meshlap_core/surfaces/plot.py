"""The normal-curvature figure ``κₙ(θ)`` of one point (matplotlib imported lazily)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError
from .catalogue import ParametricSurface
from .geometry import PointGeometry, normal_curvature_curve, point_geometry


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

    from ..io import atomic_write

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
    _mark_principal_directions(ax, geo)
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


def _mark_principal_directions(ax: Any, geo: PointGeometry) -> None:
    """Dotted lines and dots where ``κₙ`` reaches ``κ₁`` and ``κ₂`` (or a note at an umbilic)."""
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
