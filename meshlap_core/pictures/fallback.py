"""A scene (:func:`.scene.build_scene`) drawn by matplotlib, where the viewer's EGL renderer
is not available: the same colour maps and ranges, a colour bar per field, the isolines, the
one-ring of a vertex with its order numbers, arrows and crosses (at most
:data:`MAX_GLYPHS` of each), and a caption saying why matplotlib drew it.

A face takes the mean colour of its three vertices, shaded by the angle between its normal
and the view (matplotlib's 3D axes sort faces by depth, no lighting of their own).
"""

from __future__ import annotations

import math
import textwrap
from typing import Any

import numpy as np

from ..types import FloatArray

MAX_GLYPHS = 400
"""Arrows (and crosses) drawn at most: evenly chosen vertices beyond that."""

DEFAULT_TOWARD_EYE = (0.0, 0.15, -1.0)
"""The window's default view direction (from the mesh towards the eye, y up)."""


def up_rotation(up: str) -> np.ndarray:
    """``R (3,3)`` taking the mesh axis ``up`` to +y (the window's display rule for
    ``--up``: ``"z"`` maps ``(x, y, z)`` to ``(x, z, −y)``, ``"x"`` to ``(−y, x, z)``)."""
    axis = "xyz".index(up[-1])
    sign = -1.0 if up.startswith("-") else 1.0
    R = np.zeros((3, 3))
    R[1, axis] = sign
    if axis == 1:
        R[0, 0], R[2, 2] = sign, 1.0
    elif axis == 2:
        R[0, 0], R[2, 1] = 1.0, -sign
    else:
        R[0, 1], R[2, 2] = -sign, 1.0
    return R


def _to_axes(P: FloatArray, R: np.ndarray) -> FloatArray:
    """Display coordinates (y up) of mesh points, as matplotlib's (z up): ``(z, x, y)``."""
    D = np.asarray(P, dtype=np.float64) @ R.T
    return D[:, [2, 0, 1]]


def draw(scene: dict[str, Any], reason: str) -> list[np.ndarray]:
    """One ``(h, w, 3) uint8`` image per turn of ``scene``, the ``reason`` matplotlib drew
    it written along the bottom (nothing when it is "")."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    w, h = scene["size"]
    frames = []
    for turn in scene["turns"]:
        fig = Figure(figsize=(w / 100.0, h / 100.0), dpi=100)
        panes = scene["panes"]
        bottom = 0.1 if reason else 0.02
        for k, pane in enumerate(panes):
            width = 1.0 / len(panes)
            ax = fig.add_axes((k * width, bottom, width * 0.8, 0.96 - bottom), projection="3d")
            _draw_pane(fig, ax, scene, pane, k, float(turn))
            if pane.get("field") is not None:
                _colour_bar(fig, pane, (k * width + width * 0.8, bottom + 0.1, 0.02, 0.6))
        if reason:
            text = textwrap.fill("drawn by matplotlib: " + reason, width=int(w / 6.5))
            fig.text(0.01, 0.01, text, fontsize=7, color="#57606a", va="bottom")
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        frames.append(np.asarray(canvas.buffer_rgba())[..., :3].copy())
    return frames


def _draw_pane(
    fig: Any, ax: Any, scene: dict[str, Any], pane: dict[str, Any], k: int, turn: float
) -> None:
    """The mesh of ``pane`` with its field, isolines, glyphs and (first pane) one-ring; a
    vertex's picture without a camera is framed on its one-ring, seen along its normal."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    R = up_rotation(scene["up"])
    V, F = pane["V"], pane["F"]
    P = _to_axes(V, R)
    vertex = scene["options"].get("vertex") if k == 0 else None
    ring = _ring_of(F, len(V), vertex) if vertex is not None else None
    eye = np.asarray(scene["camera"] or DEFAULT_TOWARD_EYE, dtype=np.float64)
    if ring is not None and scene["camera"] is None:
        eye = _ring_view(V, F, vertex, R)
    a = math.radians(turn)
    eye = np.array(
        [math.cos(a) * eye[0] + math.sin(a) * eye[2], eye[1],
         -math.sin(a) * eye[0] + math.cos(a) * eye[2]]
    )  # fmt: skip
    eye_axes = eye[[2, 0, 1]] / np.linalg.norm(eye)
    lo, hi = P.min(axis=0), P.max(axis=0)
    c, r = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo)) or 1.0
    faces = F
    if ring is not None and scene["camera"] is None:
        c = P[vertex]
        r = 1.3 * float(np.linalg.norm(P[ring[0]] - c, axis=1).max()) if ring[0].size else r
        faces = F[np.linalg.norm(P[F].mean(axis=1) - c, axis=1) < 2.0 * r]
    tris = P[faces]
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    shade = 0.55 + 0.45 * np.abs(n @ eye_axes)
    colours = np.tile([0.82, 0.82, 0.82, 1.0], (len(faces), 1))
    if pane.get("field") is not None:
        colours = _colours(pane, pane["field"][faces].mean(axis=1))
    colours[:, :3] *= shade[:, None]
    ax.computed_zorder = False  # what is drawn after the mesh stays in front of it
    edges = ("#262626", 0.3) if pane.get("edges") else ("none", 0.0)
    ax.add_collection3d(
        Poly3DCollection(tris, facecolors=colours, edgecolors=edges[0], linewidths=edges[1])
    )
    if pane.get("isolines"):
        _isolines(ax, V, F, pane, R)
    if "arrows" in pane:
        _arrows(ax, P, pane["arrows"] @ R.T)
    if "crosses" in pane:
        _crosses(ax, P, pane["crosses"], R)
    if ring is not None:
        _ring(ax, P, ring, vertex)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    elev = math.degrees(math.asin(float(np.clip(eye_axes[2], -1, 1))))
    ax.view_init(elev=elev, azim=math.degrees(math.atan2(eye_axes[1], eye_axes[0])))
    ax.set_axis_off()
    if pane.get("title"):
        ax.set_title(pane["title"], fontsize=9)


def _colours(pane: dict[str, Any], values: FloatArray) -> np.ndarray:
    from matplotlib import colormaps

    lo, hi = pane["range"]
    t = np.clip((values - lo) / (hi - lo), 0.0, 1.0)
    return colormaps[pane["cmap"]](t)


def _colour_bar(fig: Any, pane: dict[str, Any], box: tuple[float, ...]) -> None:
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    cax = fig.add_axes(box)
    mappable = ScalarMappable(Normalize(*pane["range"]), colormaps[pane["cmap"]])
    bar = fig.colorbar(mappable, cax=cax)
    bar.set_label(pane["label"], fontsize=7)
    bar.ax.tick_params(labelsize=6)


def _isolines(ax: Any, V: FloatArray, F: Any, pane: dict[str, Any], R: np.ndarray) -> None:
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    from ..diffusion import isolines

    f = pane["field"]
    levels = np.linspace(f.min(), f.max(), pane["isolines"] + 2)[1:-1]
    P, E, _ = isolines(V, F, f, levels)
    if len(E):
        Q = _to_axes(P, R)
        ax.add_collection3d(Line3DCollection(Q[E], colors="#222222", linewidths=0.6))


def _glyph_vertices(n: int) -> np.ndarray:
    return np.unique(np.linspace(0, n - 1, min(n, MAX_GLYPHS)).astype(np.int64))


def _arrows(ax: Any, P: FloatArray, D: FloatArray) -> None:
    idx = _glyph_vertices(len(P))
    D = D[:, [2, 0, 1]][idx]
    top = float(np.linalg.norm(D, axis=1).max()) or 1.0
    scale = 0.06 * float(np.ptp(P, axis=0).max()) / top
    X = P[idx]
    ax.quiver(X[:, 0], X[:, 1], X[:, 2], *(scale * D).T, color="#1a1a1a", linewidth=0.6)


def _crosses(ax: Any, P: FloatArray, c: dict[str, FloatArray], R: np.ndarray) -> None:
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    idx = _glyph_vertices(len(P))
    arm = 0.02 * float(np.ptp(P, axis=0).max())
    top = max(float(np.abs(c["k1"]).max()), float(np.abs(c["k2"]).max())) or 1.0
    for d, k, colour in ((c["d1"], c["k1"], "#0d0d0d"), (c["d2"], c["k2"], "#00994d")):
        Da = (d @ R.T)[:, [2, 0, 1]][idx]
        s = arm * np.clip(np.abs(k[idx]) / top, 0.2, 1.0)[:, None]
        X = P[idx]
        ax.add_collection3d(
            Line3DCollection(np.stack([X - s * Da, X + s * Da], axis=1), colors=colour,
                             linewidths=0.8)
        )  # fmt: skip


def _ring_of(F: Any, n: int, vertex: int) -> tuple[np.ndarray, bool]:
    """The ordered neighbours of ``vertex`` and whether it is on the boundary."""
    from ..topology import one_ring

    ring = one_ring(F, n)
    return np.asarray(ring[vertex], dtype=np.int64), bool(ring.boundary[vertex])


def _ring_view(V: FloatArray, F: Any, vertex: int, R: np.ndarray) -> np.ndarray:
    """The window's view of a one-ring (display coordinates): about 40° off the vertex's
    normal, tilted towards the up axis."""
    from .. import vertex_normals  # the public name (wherever the curvature code lives)

    around = F[(F == vertex).any(axis=1)]
    normal = R @ vertex_normals(V, around)[vertex]
    if not np.linalg.norm(normal) > 0:
        normal = np.array([0.0, 0.0, -1.0])
    tilt = np.array([0.0, 1.0, 0.0]) - normal[1] * normal
    if np.linalg.norm(tilt) < 1e-6:
        tilt = np.array([1.0, 0.0, 0.0]) - normal[0] * normal
    return 2.4 * normal + 2.0 * tilt / np.linalg.norm(tilt)


def _ring(ax: Any, P: FloatArray, ring: tuple[np.ndarray, bool], vertex: int) -> None:
    """The vertex (red), its neighbours joined in order (an open fan on the boundary),
    numbered from 0."""
    order, boundary = ring
    if order.size == 0:
        return
    path = order if boundary else np.append(order, order[0])
    ax.plot(*P[path].T, color="#111111", linewidth=1.5, zorder=5)
    ax.scatter(*P[[vertex]].T, color="#e61a1a", s=40, depthshade=False, zorder=6)
    ax.scatter(*P[order].T, c=np.linspace(0, 1, order.size), cmap="viridis", s=25,
               depthshade=False, zorder=6)  # fmt: skip
    for k, j in enumerate(order):
        ax.text(*P[j], f" {k}", fontsize=8, zorder=7)
