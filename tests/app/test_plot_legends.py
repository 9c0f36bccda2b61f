"""Plot legends placed off the data: the corner chosen covers none of the curve, bars or lines
(above the plot when every corner does), in every plot of every panel."""

from __future__ import annotations

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from tests.support.widgets import frames  # noqa: E402


def data_in_box(items, box) -> list[str]:
    """The items with a drawn point inside ``box`` (x0, x1, y0, y1): lines sampled 200 times
    between their points, bars as rectangles from 0, infinite lines across."""
    x0, x1, y0, y1 = box
    hits = []
    for kind, x, y in items:
        if kind == "vlines":
            inside = np.any((np.asarray(x) >= x0) & (np.asarray(x) <= x1))
        elif kind == "hlines":
            inside = np.any((np.asarray(y) >= y0) & (np.asarray(y) <= y1))
        elif kind == "bars":
            cx, h = np.asarray(x, float), np.asarray(y, float)
            half = 0.5 * np.min(np.diff(np.sort(cx))) if len(cx) > 1 else 0.5
            inside = np.any((cx + half >= x0) & (cx - half <= x1) & (h > y0) & (h != 0))
        else:
            xs = np.linspace(np.min(x), np.max(x), 200 * len(x))
            order = np.argsort(x)
            ys = np.interp(xs, np.asarray(x, float)[order], np.asarray(y, float)[order])
            inside = np.any((xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1))
        if inside:
            hits.append(kind)
    return hits


def test_the_smoothing_curve_runs_through_the_old_north_west_legend():
    from meshlap_app.plot_legend import CORNERS, OUTSIDE, corner_box, data_limits, legend_corner

    mu = np.linspace(-1.5, 0.0, 200)
    g = 1.0 / (1.0 - 0.5 * mu)  # implicit, lambda 0.5: from 0.57 at mu = -1.5 up to 1
    items = [("line", mu, g), ("hlines", None, np.array([-1.0, 1.0]))]
    limits = (mu[0], mu[-1], -1.2, 1.2)
    size = (0.25, 0.3)
    assert data_in_box(items, corner_box("NorthWest", limits, size))  # ImPlot's default: covered
    # every corner of this plot holds the curve or a |g| = 1 line: the legend goes above it
    assert legend_corner(items, size, limits) == OUTSIDE
    assert all(data_in_box(items, corner_box(c, limits, size)) for c in CORNERS)
    assert data_limits(items)[2] < -1.0  # the autofit shows the hlines with a margin
    # a histogram's bell: the north-west corner is free above its left tail
    x = np.linspace(-2.0, 2.0, 40)
    bars = [("bars", x, 100.0 * np.exp(-(x**2)))]
    where = legend_corner(bars, size)
    assert where in CORNERS and not data_in_box(bars, corner_box(where, data_limits(bars), size))
    assert data_in_box(bars, corner_box("NorthEast", data_limits(bars), (0.6, 0.3)))


@pytest.mark.parametrize("panel", ["curvature", "smoothing", "spectral", "surfaces"])
def test_every_plot_legend_covers_none_of_its_data(mock, viewer, panel):
    from meshlap_app.plot_legend import OUTSIDE, corner_box, data_limits

    ps.set_window_size(1600, 2400)  # the whole panel on screen (ImPlot skips a clipped plot)
    viewer.set_ui_scale(1.0)
    viewer.set_panel(panel)
    for _ in range(4):
        ps.frame_tick()
    if panel == "spectral":
        viewer.ui.script("compute eigenbasis", True)
        for _ in range(6):
            ps.frame_tick()
    placer = viewer.ui.legends
    titles = [t for t in viewer.ui.legend_at if placer.items.get(t)]
    assert titles, f"no plot drawn in the {panel} panel"
    for title in titles:
        for _ in range(2):  # placed from the last frame's data: one more frame
            ps.frame_tick()
        where = viewer.ui.legend_at[title]
        if where == OUTSIDE or not placer.labels.get(title):  # above the plot, or no legend
            continue
        items = placer.items[title]
        if title in placer.log_y:  # corners are boxes on screen: log10 y
            items = [(k, x, None if y is None else np.log10(y)) for k, x, y in items]
        limits = data_limits(items)
        if title in placer.y_limits:
            limits = (limits[0], limits[1], *placer.y_limits[title])
        box = corner_box(where, limits, placer.sizes[title])
        assert not data_in_box(items, box), (title, where, data_in_box(items, box))


def test_y_tick_labels_never_overlap(viewer):
    """ImPlot put a label at every y tick it chose: on a plot 130 pixels high they ran into
    each other. Each plot's ticks are round values (1, 2, 2.5 or 5 times a power of ten)
    spaced well over a text line apart (two asked; 1.5 at least as ImPlot laid the plot out:
    its data area's height over its y range, read inside the plot the same frame)."""
    viewer.ui.y_ticks.clear()
    for view, n in (("curvature", 3), ("surfaces", 3), ("smoothing", 3), ("curvature_lab", 4)):
        viewer.set_panel(view)
        frames(viewer, n)
    assert "normal curvature k_n(phi)" in viewer.ui.y_ticks, viewer.ui.y_ticks
    for title, (ticks, gap, line) in viewer.ui.y_ticks.items():
        if len(ticks) < 2:
            continue  # one label cannot overlap
        assert gap >= 1.5 * line, (title, ticks, gap, line)
        step = ticks[1] - ticks[0]
        mantissa = step / 10.0 ** np.floor(np.log10(step))
        assert min(abs(mantissa - m) for m in (1.0, 2.0, 2.5, 5.0)) < 1e-9, (title, ticks)
        assert np.allclose(np.diff(ticks), step), (title, ticks)
