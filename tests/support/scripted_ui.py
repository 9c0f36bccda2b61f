"""The tests' UI adapter: :class:`ScriptedUI` scripts widgets and records what the panels drew.

It is :class:`meshlap_app.ui.UI` (every real imgui call still runs, on polyscope's
``openGL_mock`` or EGL backend) with the adapter's hooks overridden:

- **scripted**: ``ui.script("field", "gaussian")`` makes the next frame's combo ``field`` return
  ``(True, "gaussian")``; ``ui.script("lambda", "0", "0.5")`` types ``0`` (and presses Enter) on
  one frame and ``0.5`` on the next; text typed into a numeric widget is read as imgui reads it
  (:func:`parse_number`); ``ui.script("key space", True)`` presses a shortcut,
  ``ui.script("click", (x, y))`` clicks the scene, ``ui.script("Export", True)`` opens a header
  for one frame. :meth:`ScriptedUI.pending` lists what was scripted and never drawn;
- **recording**: the label of every interactive widget drawn (``seen``, per section; keys under
  ``"keys"``, clicks and hovers under ``"scene"``), of every scripted one (``driven``), their
  ``tooltips``, and every table (``tables``: headers, each row's cells, flagged and highlighted
  rows, the width drawn), so a test fails when a panel has a widget no test drives and reads
  what a panel listed without pixels.

Tests import it as a plain module (pytest puts ``tests/`` on the path):
``from scripted_ui import ScriptedUI``.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from meshlap_app.ui import RGBA, UI

# where the hooks' non-widget kinds are recorded in ``seen`` (widgets: their panel section)
SECTION_OF_KIND = {"key": "keys", "click": "scene", "hover": "scene"}


def parse_number(text: str, label: str, integer: bool = False) -> float:
    """What imgui reads from a typed numeric field: an int or float literal (``nan``, ``inf``
    and overflowing literals such as ``1e309`` included, as C's ``strtod`` reads them).

    Parameters
    ----------
    text : str
        What was typed.
    label : str
        The field's label (named in the error).
    integer : bool
        The field holds a whole number (``InputInt``, ``SliderInt``).

    Returns
    -------
    float or int

    Raises
    ------
    ValueError
        For an empty field or text that is not a number, naming the field.
    """
    t = text.strip()
    if not t:
        raise ValueError(f"{label}: the field is empty; type a number and press Enter")
    try:
        value = float(t)
    except ValueError:
        raise ValueError(f"{label}: {text!r} is not a number") from None
    if integer:
        if not math.isfinite(value) or value != int(value):
            raise ValueError(f"{label}: {text!r} is not a whole number")
        return int(value)
    return value


@dataclass
class TableRecord:
    """What :meth:`UI.table` drew the last time it was drawn: ``headers`` (with their ``tips``),
    every row's ``cells`` (strings, as shown), each row's colour (``None``: the text colour),
    the indices of the ``highlighted`` rows, and its measured ``width``."""

    headers: list[str]
    tips: list[str] = field(default_factory=list)
    rows: list[list[str]] = field(default_factory=list)
    colors: list[RGBA | None] = field(default_factory=list)
    highlighted: list[int] = field(default_factory=list)
    width: float = 0.0  # pixels, as drawn (0 when imgui skipped it)
    avail: float = 0.0  # pixels of panel width available where the table starts

    def flagged(self) -> list[list[str]]:
        """The rows drawn in a colour of their own."""
        return [r for r, c in zip(self.rows, self.colors, strict=True) if c is not None]

    def column(self, header: str) -> list[str]:
        """The cells of the column ``header``, top to bottom."""
        k = self.headers.index(header)
        return [r[k] for r in self.rows]


class ScriptedUI(UI):
    """:class:`meshlap_app.ui.UI` that a test scripts and that records what it drew (see the
    module docstring). Takes the same parameters as :class:`~meshlap_app.ui.UI`."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.seen: dict[tuple[str, str], str] = {}  # (section, label) -> widget kind
        self.tooltips: dict[tuple[str, str], str] = {}
        self.driven: set[tuple[str, str]] = set()
        self.tables: dict[tuple[str, str], TableRecord] = {}  # (section, id) -> last drawn
        self._script: dict[str, deque[Any]] = {}
        self._drawing: TableRecord | None = None  # the table being drawn
        self.progress_lines: list[tuple[str, float, str]] = []  # (section, fraction, text)
        # (section, label) -> (kind, x, y) of the last plot item drawn
        self.plots: dict[tuple[str, str], tuple[str, Any, Any]] = {}
        self.legend_at: dict[str, str] = {}  # plot title -> where its legend was placed
        # every error line drawn: (section, text, label of the widget drawn just before it)
        self.errors_drawn: list[tuple[str, str, str]] = []
        self._last_label = ""
        # (section, label) -> the width in pixels each button was last drawn with (0: its label's)
        self.button_widths: dict[tuple[str, str], float] = {}
        self.drawn: dict[tuple[str, str], Any] = {}  # (section, label) -> value last drawn with
        self.lines: list[tuple[str, str]] = []  # (section, line) of text wrapped at spaces
        self.overlays: list[tuple[tuple[float, float], str]] = []  # text over the 3D view
        # (section, label) -> (x0, y0, x1, y1): where each widget (and header) was last drawn
        # in the window, as imgui laid it out (the layout a user sees, headless)
        self.rects: dict[tuple[str, str], tuple[float, float, float, float]] = {}
        # every plain line drawn (text, note, coloured): (section, text, colour or None)
        self.texts: list[tuple[str, str, RGBA | None]] = []
        # plot title -> (the y ticks set, their spacing in pixels as ImPlot laid the plot out
        # that frame: GetPlotSize over GetPlotLimits, the text line's height)
        self.y_ticks: dict[str, tuple[Any, float, float]] = {}
        self._ticks_asked: dict[str, list[float]] = {}

    # ------------------------------------------------------------------ the script
    def script(self, label: str, *values: Any) -> None:
        """Queue values for the widget ``label``: one value is consumed per frame it is drawn."""
        self._script.setdefault(label, deque()).extend(values)

    def pending(self) -> dict[str, list[Any]]:
        """Scripted values not consumed yet (a widget that was never drawn)."""
        return {k: list(v) for k, v in self._script.items() if v}

    # ------------------------------------------------------------------ the hooks
    def _record(
        self,
        label: str,
        kind: str,
        tooltip: str,
        current: Any = None,
        choices: Sequence[str] | None = None,
    ) -> Any:
        """Record the widget (headers are layout, not recorded) and hand out its next scripted
        value, read as the widget reads it (the type of ``current``; one of ``choices``)."""
        key = (SECTION_OF_KIND.get(kind, self.section), label)
        self._last_label = label
        if kind not in SECTION_OF_KIND:  # a widget just drawn: its rectangle
            lo, hi = self.im.GetItemRectMin(), self.im.GetItemRectMax()
            self.rects[key] = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        if kind != "header":
            self.seen[key] = kind
            self.drawn[key] = current
            if tooltip:
                self.tooltips[key] = tooltip
        queue = self._script.get(label)
        if not queue:
            return None
        value = queue.popleft()
        if kind != "header":
            self.driven.add(key)
        return _as_widget_reads(value, label, kind, current, choices)

    def _record_button_width(self, label: str, width: float) -> None:
        self.button_widths[(self.section, label)] = width

    def _record_lines(self, lines: list[str]) -> None:
        self.lines += [(self.section, line) for line in lines]

    def _record_overlay(self, pos: tuple[float, float], text: str) -> None:
        self.overlays.append(((float(pos[0]), float(pos[1])), text))

    def _record_progress(self, fraction: float, text: str) -> None:
        self.progress_lines.append((self.section, fraction, text))

    def _record_table(self, table_id: str, headers: list[str], tips: list[str]) -> None:
        record = TableRecord(list(headers), list(tips))
        record.avail = float(self.im.GetContentRegionAvail()[0])
        self.tables[(self.section, table_id)] = record
        self._drawing = record

    def error(self, text: str) -> None:
        super().error(text)
        self.errors_drawn.append((self.section, text, self._last_label))

    def _record_plot(self, label: str, kind: str, x: Any, y: Any) -> None:
        self.plots[(self.section, label)] = (kind, x, y)

    def _record_ticks(self, title: str, ticks: Any, spacing: float) -> None:
        self._ticks_asked[title] = list(ticks)

    def _record_plot_area(self, title: str) -> None:
        """The ticks a plot set, spaced as ImPlot laid the plot out this frame (its data
        area's height in pixels over its y range, read inside the plot), not as asked."""
        ticks = self._ticks_asked.pop(title, None)
        if ticks is None or len(ticks) < 2:
            return
        height = float(self.ip.GetPlotSize()[1])
        _, _, y0, y1 = self.ip.GetPlotLimits()
        gap = height * (ticks[1] - ticks[0]) / (y1 - y0) if y1 > y0 else 0.0
        self.y_ticks[title] = (ticks, float(gap), float(self.im.GetTextLineHeight()))

    def text(self, text: str) -> None:
        super().text(text)
        self.texts.append((self.section, text, None))

    def note(self, text: str) -> None:
        super().note(text)
        self.texts.append((self.section, text, None))

    def colored(self, text: str, rgba: RGBA) -> None:
        super().colored(text, rgba)
        self.texts.append((self.section, text, tuple(rgba)))

    def _record_legend(self, title: str, where: str) -> None:
        self.legend_at[title] = where

    def _record_row(self, cells: list[str], rgba: RGBA | None, highlight: bool) -> None:
        record = self._drawing
        assert record is not None, "a row outside a table reached the hook"
        record.rows.append(list(cells))
        record.colors.append(rgba)
        if highlight:
            record.highlighted.append(len(record.rows) - 1)

    def _record_table_end(self, shown: bool) -> None:
        if self._drawing is not None and shown:
            self._drawing.width = float(self.im.GetItemRectSize()[0])
        self._drawing = None


def _as_widget_reads(
    value: Any, label: str, kind: str, current: Any, choices: Sequence[str] | None
) -> Any:
    """A scripted ``value`` as the widget ``label`` returns it.

    Raises
    ------
    ValueError
        A choice not among ``choices``; typed text that is not a number for a numeric widget
        (:func:`parse_number`).
    """
    if choices is not None:
        if value not in choices:
            if kind == "combo":
                raise ValueError(f"{label}: {value!r} is not one of {', '.join(choices)}")
            raise ValueError(f"{label}: {value!r} is not in the list")
        return value
    if isinstance(current, bool):
        return bool(value)
    if isinstance(current, int):
        return parse_number(value, label, True) if isinstance(value, str) else value
    if isinstance(current, float):
        return parse_number(value, label) if isinstance(value, str) else float(value)
    if isinstance(current, str):
        return str(value)
    return value  # keys, clicks and hovers: the adapter reads it
