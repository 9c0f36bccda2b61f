"""The plot half of the UI adapter (:class:`Plots`, a base of :class:`.ui.UI`): ImPlot plots with
labelled axes, refitted every frame, each legend in a corner no data runs through
(:mod:`.plot_legend`)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from .plot_legend import CORNERS, OUTSIDE, LegendPlacer, data_limits, nice_ticks
from .ui_checks import check_return


class Plots:
    """``plot`` and its items; the hook ``_record_plot`` sees every item drawn, and
    ``_record_legend`` where each plot's legend went."""

    im: Any
    ip: Any
    scale: float
    _legends: LegendPlacer | None = None
    _colors: dict[str, Any] | None = None
    _areas: dict[str, float] | None = None  # plot title -> its data area's height last frame

    @property
    def legends(self) -> LegendPlacer:
        if self._legends is None:
            self._legends = LegendPlacer()
        return self._legends

    def _record_plot(self, label: str, kind: str, x: Any, y: Any) -> None:
        """Hook called after a plot item was drawn: ``kind`` is ``line`` (``x``, ``y``),
        ``bars`` (centres ``x``, heights ``y``), ``vlines`` (``x``) or ``hlines`` (``y``)."""

    def _record_legend(self, title: str, where: str) -> None:
        """Hook called when plot ``title`` places its legend (a corner or ``outside``)."""

    def _record_ticks(self, title: str, ticks: Any, spacing: float) -> None:
        """Hook called when plot ``title`` sets its y ticks (``spacing``: pixels apart)."""

    def _record_plot_area(self, title: str) -> None:
        """Hook called inside plot ``title`` after its items, before ``EndPlot``."""

    @property
    def plot_colors(self) -> dict[str, Any]:
        """Each plot item's colour as asked (label -> RGBA), when it was given one."""
        if self._colors is None:
            self._colors = {}
        return self._colors

    def _y_ticks(self, title: str, data_px: float) -> None:
        """Round y ticks at least two text lines apart on the plot's data area ``data_px``
        pixels high, from the last frame's data of ``title`` (ImPlot's own put a label at
        every tick it chose: they overlapped on short plots)."""
        limits = data_limits(self.legends.items.get(title, []))
        if limits is None or not limits[3] > limits[2]:
            return
        lo, hi = limits[2], limits[3]
        line = float(self.im.GetTextLineHeight())
        ticks = nice_ticks(lo, hi, 2.0 * line * (hi - lo) / data_px)
        if not len(ticks):
            return
        self.ip.SetupAxisTicks(self.ip.ImAxis_Y1, np.ascontiguousarray(ticks, dtype=np.float64))
        spacing = data_px * float(ticks[1] - ticks[0]) / (hi - lo) if len(ticks) > 1 else 0.0
        self._record_ticks(title, ticks, spacing)

    def _legend_place(self, title: str, height: float) -> str:
        """Where ``title``'s legend goes this frame: its size estimated from the last frame's
        labels, the plot area from the panel's width and the plot's height."""
        labels = self.legends.labels.get(title, [])
        if not labels:  # the first frame: ImPlot's first corner until the data is known
            return CORNERS[0]
        s = self.scale
        text_w = max(float(self.im.CalcTextSize(t)[0]) for t in labels)
        # the box (swatch, text, inner padding) plus ImPlot's 10-pixel inset from the corner
        rows = len(labels) * (self.im.GetTextLineHeight() + 4.0 * s)
        size = (text_w + 40.0 * s, rows + 18.0 * s)
        # the data area: less the y axis' labels, the title, the x axis' ticks and label
        area = (float(self.im.GetContentRegionAvail()[0]) - 70.0 * s, (height - 90.0) * s)
        return self.legends.place(title, size, area)

    def _legend_row(self) -> float:
        """Pixels of a one-row legend above a plot (a line of text, ImPlot's padding)."""
        return float(self.im.GetTextLineHeight()) + 22.0 * self.scale

    def _plotted(self, label: str, kind: str, x: Any, y: Any) -> None:
        self.legends.add(kind, x, y, label)
        self._record_plot(label, kind, x, y)

    @contextmanager
    def plot(
        self, title: str, height: float, x_label: str, y_label: str, y_log: bool = False,
        fit_y: bool = True,
    ) -> Iterator[bool]:  # fmt: skip
        """``with ui.plot(...) as shown:`` an ImPlot with labelled axes, refitted to the data
        every frame (``fit_y=False``: the caller sets the y limits), its legend where no data
        is (a corner, else a row above the plot); EndPlot always runs."""
        (self.legends.log_y.add if y_log else self.legends.log_y.discard)(title)
        where = self._legend_place(title, height)
        self._record_legend(title, where)
        # a legend above the plot takes a row of its height: the plot grows by that row, so
        # the data keeps the height asked for (else a short plot's data area all but vanishes)
        px = height * self.scale + (self._legend_row() if where == OUTSIDE else 0.0)
        shown = check_return("BeginPlot", self.ip.BeginPlot(title, (-1, px)))
        self.legends.begin(title)
        ip = self.ip
        try:
            if shown:
                fit = ip.ImPlotAxisFlags_AutoFit
                ip.SetupAxes(x_label, y_label, fit, fit if fit_y else 0)
                if where == OUTSIDE:
                    flags = ip.ImPlotLegendFlags_Outside | ip.ImPlotLegendFlags_Horizontal
                    ip.SetupLegend(ip.ImPlotLocation_North, flags)
                else:
                    ip.SetupLegend(getattr(ip, f"ImPlotLocation_{where}"), 0)
                if y_log:
                    ip.SetupAxisScale(ip.ImAxis_Y1, ip.ImPlotScale_Log10)
                elif fit_y:  # the data area: as drawn last frame, else estimated
                    area = (self._areas or {}).get(title, (height - 90.0) * self.scale)
                    self._y_ticks(title, max(area, 1.0))
            yield shown
        finally:
            if shown:
                if self._areas is None:
                    self._areas = {}
                self._areas[title] = float(ip.GetPlotSize()[1])
                self._record_plot_area(title)
                ip.EndPlot()
            self.legends.end()

    def plot_y_limits(self, lo: float, hi: float) -> None:
        self.ip.SetupAxisLimits(self.ip.ImAxis_Y1, float(lo), float(hi), self.ip.ImPlotCond_Always)
        self.legends.y_limits[self.legends.drawing] = (float(lo), float(hi))

    def _style(self, label: str, rgba: Any) -> None:
        """The next item's line colour (``None``: ImPlot's next one)."""
        if rgba is not None:
            rgba = tuple(float(c) for c in rgba)
            self.ip.SetNextLineStyle(rgba)
        self.plot_colors[label] = rgba

    def plot_line(self, label: str, x: Any, y: Any, rgba: Any = None) -> None:
        self._style(label, rgba)
        self.ip.PlotLine(label, _f64(x), _f64(y))
        self._plotted(label, "line", x, y)

    def plot_bars(
        self, label: str, x: Any, y: Any, width: float, colors: Any | None = None
    ) -> None:
        """Bars at ``x`` of heights ``y``; ``colors (k,4)`` gives each bar its own fill (one
        legend entry, ``label``, for all of them)."""
        self._plotted(label, "bars", x, y)
        if colors is None:
            self.ip.PlotBars(label, _f64(x), _f64(y), float(width))
            return
        for i, (xi, yi, c) in enumerate(zip(_f64(x), _f64(y), colors, strict=True)):
            self.ip.SetNextFillStyle(tuple(float(t) for t in c))
            self.ip.PlotBars(label if i == 0 else f"##{label}{i}", _f64([xi]), _f64([yi]), width)

    def plot_drag_point(
        self, label: str, index: int, x: float, y: float, tooltip: str
    ) -> tuple[bool, float, float]:
        """A point of the open plot the user drags (ImPlot's ``DragPoint``, id ``index``):
        ``(moved, x, y)``. The hook sees it as the widget ``label`` of kind ``drag`` (drawn
        with ``(x, y)``; a scripted ``(x, y)`` moves it there)."""
        moved, nx, ny = check_return(
            "DragPoint",
            self.ip.DragPoint(
                int(index), float(x), float(y), (0.85, 0.2, 0.1, 1.0), 5 * self.scale
            ),
        )
        if moved and tooltip:
            self.im.SetTooltip(tooltip)
        v = self._record(label, "drag", tooltip, (float(x), float(y)))  # type: ignore[attr-defined]
        if v is not None:
            moved, nx, ny = True, float(v[0]), float(v[1])
        self._changed(moved)  # type: ignore[attr-defined]
        return bool(moved), float(nx), float(ny)

    def plot_vlines(self, label: str, x: Any, rgba: Any = None) -> None:
        self._style(label, rgba)
        self.ip.PlotInfLines(label, _f64(x))
        self._plotted(label, "vlines", x, None)

    def plot_hlines(self, label: str, y: Any) -> None:
        self.ip.PlotInfLines(label, _f64(y), self.ip.ImPlotInfLinesFlags_Horizontal)
        self._plotted(label, "hlines", None, y)


def _f64(a: Any) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).ravel()
