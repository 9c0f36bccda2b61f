"""Pictures drawn without the viewer: matplotlib figures on the Agg canvas (imported lazily), a
painter's-algorithm mesh rasterizer for colour maps, and the autocrop of viewer screenshots."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .. import metrics
from ..io import atomic_write
from ..types import FloatArray, IntArray


def new_figure(w: float, h: float) -> Any:
    """A matplotlib ``Figure`` of ``w`` × ``h`` inches on the Agg canvas (no pyplot, no GUI)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h))
    FigureCanvasAgg(fig)
    return fig


def camera(direction: Sequence[float], up: Sequence[float] = (0.0, 1.0, 0.0)) -> FloatArray:
    """Rows: screen right, screen up, towards the camera (``direction`` points at the eye)."""
    c = np.asarray(direction, dtype=float)
    c = c / np.linalg.norm(c)
    r = np.cross(np.asarray(up, dtype=float), c)
    if np.linalg.norm(r) < 1e-8:
        r = np.cross(np.array([0.0, 0.0, 1.0]), c)
    r /= np.linalg.norm(r)
    return np.stack([r, np.cross(c, r), c])


def view_dir(elev: float, azim: float) -> FloatArray:
    """Eye direction, y up, like the viewer: ``azim`` degrees around y from the front (−z),
    ``elev`` degrees above."""
    a, e = math.radians(azim), math.radians(elev)
    return np.array([-math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e)])


def draw_mesh(
    ax: Any,
    V: FloatArray,
    F: IntArray,
    values: FloatArray | None = None,
    *,
    cam: FloatArray | None = None,
    cmap: str = "coolwarm",
    symmetric: bool = True,
    vmin: float | None = None,
    vmax: float | None = None,
    edges: bool = False,
    log: bool = False,
) -> Any:
    """Draw a shaded mesh with the painter's algorithm (2-D polygons, orthographic camera).

    Returns the ``ScalarMappable`` of the colour map (``None`` without ``values``).
    """
    import matplotlib as mpl
    from matplotlib.collections import PolyCollection

    R = camera(view_dir(15.0, -25.0)) if cam is None else cam
    P = V @ R.T
    T = P[F]
    nrm = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    ln = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.divide(nrm, ln, out=np.zeros_like(nrm), where=ln > 0)
    closed = metrics.is_closed(F) if len(F) else False
    keep = nrm[:, 2] > 0 if closed else np.ones(len(F), dtype=bool)
    light = np.array([0.35, 0.55, 1.0])
    light /= np.linalg.norm(light)
    shade = 0.3 + 0.7 * np.abs(nrm @ light)
    sm = None
    if values is None:
        base = np.tile(np.array([0.86, 0.80, 0.72, 1.0]), (len(F), 1))
    else:
        vals = np.asarray(values, dtype=float)
        fv = vals[F].mean(axis=1)
        finite = vals[np.isfinite(vals)]
        if vmin is None or vmax is None:
            if symmetric:
                r = float(np.percentile(np.abs(finite), 98)) if finite.size else 1.0
                lo, hi = -(r or 1.0), (r or 1.0)
            else:
                lo, hi = np.percentile(finite, [1, 99]) if finite.size else (0.0, 1.0)
                lo, hi = float(lo), float(hi)
                if hi <= lo:
                    hi = lo + 1.0
        else:
            lo, hi = vmin, vmax
        norm = (
            mpl.colors.LogNorm(max(lo, 1e-300), hi, clip=True)
            if log
            else mpl.colors.Normalize(lo, hi)
        )
        cm = mpl.colormaps[cmap]
        base = cm(norm(np.nan_to_num(np.maximum(fv, lo) if log else fv)))
        sm = mpl.cm.ScalarMappable(norm=norm, cmap=cm)
    col = base.copy()
    col[:, :3] *= shade[:, None]
    idx = np.flatnonzero(keep)
    order = idx[np.argsort(T[idx, :, 2].mean(axis=1))]
    pc = PolyCollection(
        T[order][:, :, :2],
        facecolors=col[order],
        edgecolors=(0.1, 0.1, 0.1, 0.6) if edges else col[order],
        linewidths=0.6 if edges else 0.25,
    )
    ax.add_collection(pc)
    lo2, hi2 = P[:, :2].min(axis=0), P[:, :2].max(axis=0)
    pad = 0.04 * float(max(hi2 - lo2))
    ax.set_xlim(lo2[0] - pad, hi2[0] + pad)
    ax.set_ylim(lo2[1] - pad, hi2[1] + pad)
    ax.set_aspect("equal")
    ax.axis("off")
    return sm


def map_row(
    items: Sequence[tuple[str, FloatArray]],
    V: FloatArray,
    F: IntArray,
    vmax: float,
    label: str,
    vmin: float = 0.0,
    log: bool = False,
) -> Any:
    """One row of meshes coloured by per-vertex values on a shared vmin..vmax scale."""
    n = len(items)
    fig = new_figure(3.4 * n + 0.9, 3.9)
    w = 0.94 / n * (3.4 * n) / (3.4 * n + 0.9)
    sm = None
    for i, (title, vals) in enumerate(items):
        ax = fig.add_axes((0.005 + i * w, 0.0, w, 0.86))
        sm = draw_mesh(ax, V, F, vals, cmap="magma", symmetric=False, vmin=vmin, vmax=vmax, log=log)
        ax.set_title(title, fontsize=8)
    cax = fig.add_axes((0.005 + n * w + 0.01, 0.12, 0.012, 0.66))
    fig.colorbar(sm, cax=cax, label=label)
    return fig


def _bbox(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    """``(row0, row1, col0, col1)`` (end exclusive) of the ``True`` pixels, ``None`` if none."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return None
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1


def autocrop(path: Path, margin: int = 12) -> bool:
    """Compact a viewer screenshot: the mesh cut out of the empty background, with the viewer's
    panel (top right) placed beside it. ``False`` if the image is blank."""
    import io

    import matplotlib.image as mpimg

    from ..io.reader import read_input

    img = mpimg.imread(io.BytesIO(read_input(path, what="image file")), format="png")
    if img.ndim != 3 or img.shape[0] < 2 or img.shape[1] < 2:
        return False
    if img.shape[2] == 3:
        img = np.concatenate([img, np.ones((*img.shape[:2], 1), img.dtype)], axis=2)
    rgb = img[..., :3]
    bg = rgb[-1, 0]
    diff = np.abs(rgb - bg).max(axis=2) > 0.02
    if not diff.any():
        return False
    h, w = diff.shape
    # the panel: the non-background run in the top rows that touches the right part
    panel = None
    top = diff[: max(h // 20, 4)]
    cols = np.flatnonzero(top.any(axis=0))
    if len(cols) and cols[0] > w // 3:
        c0 = int(cols[0])
        col = diff[:, min(c0 + 4, w - 1)]
        r1 = int(np.flatnonzero(col)[-1]) + 1 if col.any() else h
        panel = (0, r1, c0, w)
    scene = diff.copy()
    if panel is not None:
        scene[panel[0] : panel[1], panel[2] : panel[3]] = False
    sb = _bbox(scene)
    pieces = []
    if sb is not None:
        r0, r1, c0, c1 = sb
        pieces.append(
            img[
                max(r0 - margin, 0) : min(r1 + margin, h), max(c0 - margin, 0) : min(c1 + margin, w)
            ]
        )
    if panel is not None:
        pieces.append(img[panel[0] : panel[1], panel[2] : panel[3]])
    if not pieces:
        return False
    H = max(p.shape[0] for p in pieces)
    gap = margin
    W = sum(p.shape[1] for p in pieces) + gap * (len(pieces) - 1)
    out = np.ones((H, W, 4), dtype=np.float32)
    out[..., :3] = bg
    x = 0
    for p in pieces:
        y = (H - p.shape[0]) // 2 if p is pieces[0] and len(pieces) > 1 else 0
        out[y : y + p.shape[0], x : x + p.shape[1]] = p
        x += p.shape[1] + gap
    with atomic_write(path, "wb") as fh:
        mpimg.imsave(fh, np.clip(out, 0, 1), format="png")
    return True
