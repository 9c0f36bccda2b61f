"""Where a plot's legend goes: a corner of the plot that no data runs through (pure numpy).

ImPlot draws the legend in a fixed corner (north-west by default), over whatever is there: the
smoothing panel's g(μ) curve starts in that corner, the histogram's tallest bars reach it. The
legend must be set up before the items are drawn, so :class:`LegendPlacer` keeps each plot's
items of the last frame and places the next frame's legend in the first free corner of
:data:`CORNERS` (:func:`legend_corner`), or above the plot (``"outside"``) when every corner
holds data. A plot's data moves little from one frame to the next.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

CORNERS = ("NorthEast", "NorthWest", "SouthEast", "SouthWest")
"""The corners tried, in this order (ImPlot's ``ImPlotLocation_<name>``)."""
OUTSIDE = "outside"
PAD = 0.04
"""ImPlot's autofit margin around the data, as a fraction of each axis' range (a little more
than ImPlot's, so a curve along the edge counts as under the legend)."""

Item = tuple[str, Any, Any]  # kind ("line", "bars", "vlines", "hlines"), x, y


def data_limits(items: list[Item]) -> tuple[float, float, float, float] | None:
    """``(x0, x1, y0, y1)`` of the items as ImPlot's autofit shows them (bars from 0, the
    margin :data:`PAD` added); None without finite data."""
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    for kind, x, y in items:
        if x is not None and kind != "hlines":
            xs.append(np.asarray(x, dtype=float).ravel())
        if y is not None and kind != "vlines":
            ys.append(np.asarray(y, dtype=float).ravel())
        if kind == "bars":
            ys.append(np.zeros(1))
    if not xs or not ys:
        return None
    x, y = np.concatenate(xs), np.concatenate(ys)
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    if not len(x) or not len(y):
        return None
    x0, x1, y0, y1 = float(x.min()), float(x.max()), float(y.min()), float(y.max())
    dx, dy = (x1 - x0) or 1.0, (y1 - y0) or 1.0
    return x0 - PAD * dx, x1 + PAD * dx, y0 - PAD * dy, y1 + PAD * dy


def corner_box(
    corner: str, limits: tuple[float, float, float, float], size: tuple[float, float]
) -> tuple[float, float, float, float]:
    """The legend's box ``(x0, x1, y0, y1)`` in data coordinates at ``corner``, ``size`` its
    width and height as fractions of the plot's axes."""
    x0, x1, y0, y1 = limits
    w, h = (x1 - x0) * size[0], (y1 - y0) * size[1]
    bx = (x1 - w, x1) if corner.endswith("East") else (x0, x0 + w)
    by = (y1 - h, y1) if corner.startswith("North") else (y0, y0 + h)
    return bx[0], bx[1], by[0], by[1]


def covers(box: tuple[float, float, float, float], items: list[Item]) -> bool:
    """Whether any item runs through ``box``: a line (its segments, sampled 32 times each), a
    bar (the rectangle from 0 to its height, ``width`` the gap between the first two bars),
    an infinite vertical or horizontal line."""
    bx0, bx1, by0, by1 = box
    for kind, x, y in items:
        if kind == "vlines":
            v = np.asarray(x, dtype=float)
            if np.any((v >= bx0) & (v <= bx1)):
                return True
        elif kind == "hlines":
            v = np.asarray(y, dtype=float)
            if np.any((v >= by0) & (v <= by1)):
                return True
        elif kind == "bars":
            cx, hy = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
            half = 0.5 * (float(np.min(np.diff(np.sort(cx)))) if len(cx) > 1 else 1.0)
            lo, hi = np.minimum(hy, 0.0), np.maximum(hy, 0.0)
            hit = (cx + half >= bx0) & (cx - half <= bx1) & (hi >= by0) & (lo <= by1)
            if np.any(hit & (hy != 0)):
                return True
        else:
            px, py = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
            if len(px) > 1:
                t = np.linspace(0.0, 1.0, 33)[:, None]
                px = (px[:-1] + t * (px[1:] - px[:-1])).ravel()
                py = (py[:-1] + t * (py[1:] - py[:-1])).ravel()
            if np.any((px >= bx0) & (px <= bx1) & (py >= by0) & (py <= by1)):
                return True
    return False


def legend_corner(
    items: list[Item],
    size: tuple[float, float],
    limits: tuple[float, float, float, float] | None = None,
) -> str:
    """The first corner of :data:`CORNERS` where a legend of ``size`` (fractions of the axes)
    covers no item, else :data:`OUTSIDE`; ``limits`` default to :func:`data_limits`."""
    limits = limits or data_limits(items)
    if limits is None:
        return CORNERS[0]
    for corner in CORNERS:
        if not covers(corner_box(corner, limits, size), items):
            return corner
    return OUTSIDE


@dataclass
class LegendPlacer:
    """Each plot's items and y limits of the last frame, by title; :meth:`place` answers
    where the plot's legend goes this frame."""

    items: dict[str, list[Item]] = field(default_factory=dict)
    labels: dict[str, list[str]] = field(default_factory=dict)  # the legend's entries
    sizes: dict[str, tuple[float, float]] = field(default_factory=dict)  # fractions of the axes
    log_y: set[str] = field(default_factory=set)  # plots with a log10 y axis
    y_limits: dict[str, tuple[float, float]] = field(default_factory=dict)
    drawing: str = ""
    _next: list[Item] = field(default_factory=list)
    _labels: list[str] = field(default_factory=list)

    def begin(self, title: str) -> None:
        """Plot ``title`` starts: its items and y limits are recorded afresh."""
        self.drawing, self._next, self._labels = title, [], []
        self.y_limits.pop(title, None)

    def add(self, kind: str, x: Any, y: Any, label: str) -> None:
        """An item of the plot being drawn (``label`` starting ``##``: no legend entry)."""
        self._next.append((kind, x, y))
        if not label.startswith("##"):
            self._labels.append(label.split("##")[0])

    def end(self) -> None:
        self.items[self.drawing], self.labels[self.drawing] = self._next, self._labels

    def place(self, title: str, size_px: tuple[float, float], plot_px: tuple[float, float]) -> str:
        """The corner (or :data:`OUTSIDE`) for ``title``'s legend of ``size_px`` in a plot
        area of ``plot_px`` pixels, from the last frame's items."""
        items = self.items.get(title, [])
        if title in self.log_y:  # the corners are boxes on screen: in log10 y
            items = [(k, x, None if y is None else _log10(y)) for k, x, y in items]
        size = (size_px[0] / max(plot_px[0], 1.0), size_px[1] / max(plot_px[1], 1.0))
        self.sizes[title] = size
        if size[0] >= 1.0 or size[1] >= 1.0:
            return OUTSIDE
        limits = data_limits(items)
        if limits is not None and title in self.y_limits:
            limits = (limits[0], limits[1], *self.y_limits[title])
        return legend_corner(items, size, limits)


def _log10(y: Any) -> np.ndarray:
    """log10 of the positive values (the others are not drawn on a log axis)."""
    y = np.asarray(y, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(y > 0, np.log10(np.where(y > 0, y, 1.0)), np.nan)


def nice_ticks(lo: float, hi: float, min_step: float) -> np.ndarray:
    """Round tick values inside ``[lo, hi]``, evenly spaced by the smallest of 1, 2, 2.5 or 5
    times a power of ten that is at least ``min_step`` (ImPlot puts a label at every tick it
    picks, however short the plot: on a plot 130 pixels high its labels ran into each other).
    Empty for an empty or non-finite range or step."""
    if not (np.isfinite(lo) and np.isfinite(hi) and np.isfinite(min_step)) or hi <= lo:
        return np.zeros(0)
    min_step = max(float(min_step), (hi - lo) * 1e-9)
    exponent = int(np.floor(np.log10(min_step)))
    step = next(
        m * 10.0**k
        for k in (exponent, exponent + 1)
        for m in (1.0, 2.0, 2.5, 5.0)
        if m * 10.0**k >= min_step * (1 - 1e-12)
    )
    first = np.ceil(lo / step - 1e-9) * step
    ticks = np.arange(first, hi + 1e-9 * step, step)
    ticks[np.abs(ticks) < 1e-12 * step] = 0.0  # -0.0 and round-off at zero
    return ticks
