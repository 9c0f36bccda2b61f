"""The one thin adapter between the panels and ``polyscope.imgui`` / ``polyscope.implot``.

Every widget of every panel is drawn through a :class:`UI`. It calls the real imgui function
(so the window looks and behaves as imgui makes it), and on top of that it

- **pins the polyscope API**: each call's return value is checked against the type this module
  was written for (``EXPECTED``); a difference raises :class:`UIApiMismatch` (shown in the panel
  and failing the widget tests) instead of a ``TypeError`` deep in a handler;
- **can be scripted** by a test: ``ui.script("field", "gaussian")`` makes the next frame's
  combo ``field`` return ``(True, "gaussian")``; ``ui.script("lambda", "0", "0.5")`` types ``0``
  (and presses Enter) on one frame and ``0.5`` on the next;
- **records** the label of every interactive widget it drew (``seen``, per section) and of every
  scripted one (``driven``), so a test fails when a panel has a widget no test drives;
- **records the tables** it drew (``tables``, per section and table id: headers, every row's
  cells, flagged and highlighted rows), so a test reads what a panel listed without pixels;
- keeps imgui's begin/end pairs balanced even when a handler raises (``plot``, ``table`` and
  ``choose`` close what they opened in a ``finally``).

Numeric fields apply on Enter only (``ImGuiInputTextFlags_EnterReturnsTrue``): a half-typed
number (the ``0`` of ``0.5``) is never applied.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np

RED = (1.0, 0.35, 0.35, 1.0)
GREY = (0.7, 0.7, 0.7, 1.0)
HIGHLIGHT = (0.95, 0.75, 0.2, 0.35)  # the background of a highlighted table row
TABLE_ROWS = ((0.11, 0.11, 0.12, 0.94), (0.17, 0.17, 0.19, 0.94))  # opaque: readable over 3D

# the return types the adapter was written for (polyscope 2.6.x; pyproject pins the range)
EXPECTED: dict[str, tuple[type, ...]] = {
    "Combo": (bool, int),
    "Selectable": (bool,),
    "BeginCombo": (bool,),
    "Checkbox": (bool, bool),
    "Button": (bool,),
    "CollapsingHeader": (bool,),
    "SliderFloat": (bool, float),
    "SliderInt": (bool, int),
    "InputFloat": (bool, float),
    "InputInt": (bool, int),
    "InputText": (bool, str),
    "BeginPlot": (bool,),
    "BeginTable": (bool,),
}


KEYS = {
    "space": "ImGuiKey_Space",
    "left": "ImGuiKey_LeftArrow",
    "right": "ImGuiKey_RightArrow",
    "1": "ImGuiKey_1",
    "2": "ImGuiKey_2",
    "3": "ImGuiKey_3",
    "4": "ImGuiKey_4",
    "5": "ImGuiKey_5",
    "f": "ImGuiKey_F",
    "h": "ImGuiKey_H",
    "r": "ImGuiKey_R",
}
"""The viewer's shortcut keys and their imgui names."""


def sig(x: float, scale: float, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits, or ``0`` when ``|x| < 1e-12 · scale`` (round-off
    of a quantity whose size is ``scale``, e.g. ``F = -3.5e-18`` beside ``E = 1``)."""
    if abs(x) < 1e-12 * abs(scale) or x == 0:
        return "0"
    return f"{x:.{digits}g}"


def is_number(cell: str) -> bool:
    """Is the table cell a number (``-0.5007``, ``38.07°``, ``1e-05``)? Those are right-aligned;
    ``-`` (no value) is too, so a column of numbers stays one column."""
    t = cell.strip().rstrip("°")
    if t == "-":
        return True
    try:
        float(t)
    except ValueError:
        return False
    return True


@dataclass
class TableRecord:
    """What :meth:`UI.table` drew the last time it was drawn: ``headers`` (with their ``tips``),
    every row's ``cells`` (strings, as shown), each row's colour (``None``: the text colour),
    the indices of the ``highlighted`` rows, and its measured ``width``."""

    headers: list[str]
    tips: list[str] = field(default_factory=list)
    rows: list[list[str]] = field(default_factory=list)
    colors: list[tuple[float, float, float, float] | None] = field(default_factory=list)
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


class UIApiMismatch(TypeError):
    """polyscope's imgui returned a type this adapter does not expect (its API changed)."""


def check_return(name: str, result: Any) -> Any:
    """Check ``result`` of ``polyscope.imgui.<name>`` against :data:`EXPECTED`.

    Raises
    ------
    UIApiMismatch
        When the shape or the element types differ (e.g. ``Selectable`` returning a tuple).
    """
    want = EXPECTED[name]
    got = result if len(want) > 1 else (result,)
    ok = isinstance(got, tuple) and len(got) == len(want)
    ok = ok and all(
        isinstance(g, w) and (w is not int or not isinstance(g, bool))
        for g, w in zip(got, want, strict=False)
    )
    if not ok:
        shape = " ".join(t.__name__ for t in want)
        raise UIApiMismatch(
            f"polyscope.imgui.{name} returned {result!r} ({type(result).__name__}); this viewer "
            f"expects ({shape}): the installed polyscope differs from the tested range"
        )
    return result


def parse_number(text: str, label: str, integer: bool = False) -> float:
    """What imgui reads from a typed numeric field: an int or float literal (``nan``, ``inf``
    and overflowing literals such as ``1e309`` included, as C's ``strtod`` reads them).

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


class UI:
    """imgui/implot for the panels, scriptable and recording (see the module docstring).

    Parameters
    ----------
    imgui, implot : module, optional
        ``polyscope.imgui`` / ``polyscope.implot`` (imported on first use when omitted).
    wrap_width : float
        Text wider than this (pixels, before the UI scale) wraps.
    """

    def __init__(self, imgui: Any = None, implot: Any = None, wrap_width: float = 430.0) -> None:
        self._im = imgui
        self._ip = implot
        self.wrap_width = wrap_width
        self.scale = 1.0
        self.section = ""
        self.seen: dict[tuple[str, str], str] = {}  # (section, label) -> widget kind
        self.tooltips: dict[tuple[str, str], str] = {}
        self.driven: set[tuple[str, str]] = set()
        self.changed = False  # some widget reported a change since begin_section
        self._script: dict[str, deque[Any]] = {}
        self.tables: dict[tuple[str, str], TableRecord] = {}  # (section, id) -> last drawn
        self._table: TableRecord | None = None  # the table being drawn
        self._table_shown = False

    # ------------------------------------------------------------------ set-up
    @property
    def im(self) -> Any:
        if self._im is None:
            import polyscope.imgui as psim

            self._im = psim
        return self._im

    @property
    def ip(self) -> Any:
        if self._ip is None:
            import polyscope.implot as psimplot

            self._ip = psimplot
        return self._ip

    def script(self, label: str, *values: Any) -> None:
        """Queue values for the widget ``label``: one value is consumed per frame it is drawn."""
        self._script.setdefault(label, deque()).extend(values)

    def pending(self) -> dict[str, list[Any]]:
        """Scripted values not consumed yet (a widget that was never drawn)."""
        return {k: list(v) for k, v in self._script.items() if v}

    def begin_section(self, name: str) -> None:
        self.section = name
        self.changed = False

    def _record(self, label: str, kind: str, tooltip: str) -> tuple[bool, Any]:
        key = (self.section, label)
        self.seen[key] = kind
        if tooltip:
            self.tooltips[key] = tooltip
            self.im.SetItemTooltip(tooltip)
        queue = self._script.get(label)
        if queue:
            self.driven.add(key)
            return True, queue.popleft()
        return False, None

    def _changed(self, changed: bool) -> bool:
        self.changed = self.changed or bool(changed)
        return bool(changed)

    # ------------------------------------------------------------------ text
    def text(self, text: str) -> None:
        """A line of text, wrapped at the panel width."""
        self.im.PushTextWrapPos(self.wrap_width * self.scale)
        self.im.TextUnformatted(text)
        self.im.PopTextWrapPos()

    def error(self, text: str) -> None:
        """Text in red, wrapped (a refused input or a failed action)."""
        self.im.PushTextWrapPos(self.wrap_width * self.scale)
        self.im.TextColored(RED, text)
        self.im.PopTextWrapPos()

    def note(self, text: str) -> None:
        """Text in grey, wrapped (an explanation)."""
        self.im.PushTextWrapPos(self.wrap_width * self.scale)
        self.im.TextColored(GREY, text)
        self.im.PopTextWrapPos()

    def colored(self, text: str, rgba: tuple[float, float, float, float]) -> None:
        """Text in the colour ``rgba``, wrapped (a legend entry, a flagged row)."""
        self.im.PushTextWrapPos(self.wrap_width * self.scale)
        self.im.TextColored(rgba, text)
        self.im.PopTextWrapPos()

    def same_line(self) -> None:
        self.im.SameLine()

    def separator(self) -> None:
        self.im.Separator()

    def progress(self, fraction: float, text: str) -> None:
        self.im.ProgressBar(float(fraction), (-1, 0), text)

    def push_width(self, width: float) -> None:
        self.im.PushItemWidth(width * self.scale)

    def pop_width(self) -> None:
        self.im.PopItemWidth()

    # ------------------------------------------------------------------ widgets
    def header(self, label: str, default_open: bool = True, force: bool | None = None) -> bool:
        """A collapsing header (``force``: open or close it now); scripting ``label`` with a
        bool opens/closes it for one frame."""
        flags = self.im.ImGuiTreeNodeFlags_DefaultOpen if default_open else 0
        if force is not None:
            self.im.SetNextItemOpen(bool(force))
        result = check_return("CollapsingHeader", self.im.CollapsingHeader(label, flags))
        queue = self._script.get(label)
        if queue:
            return bool(queue.popleft())
        return result

    def button(self, label: str, tooltip: str = "") -> bool:
        result = check_return("Button", self.im.Button(label))
        scripted, value = self._record(label, "button", tooltip)
        return self._changed(bool(value) if scripted else result)

    def checkbox(self, label: str, value: bool, tooltip: str = "") -> tuple[bool, bool]:
        changed, new = check_return("Checkbox", self.im.Checkbox(label, bool(value)))
        scripted, v = self._record(label, "checkbox", tooltip)
        if scripted:
            changed, new = bool(v) != bool(value), bool(v)
        return self._changed(changed), new

    def combo(
        self, label: str, current: str, items: Sequence[str], tooltip: str = ""
    ) -> tuple[bool, str]:
        """A combo over strings: ``(changed, chosen item)``."""
        items = list(items)
        idx = items.index(current) if current in items else 0
        changed, idx = check_return("Combo", self.im.Combo(label, idx, items))
        scripted, v = self._record(label, "combo", tooltip)
        if scripted:
            if v not in items:
                raise ValueError(f"{label}: {v!r} is not one of {', '.join(items)}")
            return self._changed(v != current), v
        return self._changed(changed), items[idx]

    def choose(self, label: str, preview: str, items: Sequence[str], tooltip: str = "") -> str:
        """A drop-down list of ``items`` (BeginCombo + Selectable): the item picked this frame,
        or ``""``."""
        opened = check_return("BeginCombo", self.im.BeginCombo(label, preview))
        picked = ""
        try:
            if opened:
                for item in items:
                    if check_return("Selectable", self.im.Selectable(item)):
                        picked = item
        finally:
            if opened:
                self.im.EndCombo()
        scripted, v = self._record(label, "choose", tooltip)
        if scripted:
            if v not in items:
                raise ValueError(f"{label}: {v!r} is not in the list")
            picked = v
        self._changed(bool(picked))
        return picked

    def slider_float(
        self,
        label: str,
        value: float,
        lo: float,
        hi: float,
        fmt: str = "%.3f",
        tooltip: str = "",
    ) -> tuple[bool, float]:
        """A float slider (Ctrl+click types a value, which may lie outside ``[lo, hi]``)."""
        changed, new = check_return(
            "SliderFloat", self.im.SliderFloat(label, float(value), float(lo), float(hi), fmt)
        )
        scripted, v = self._record(label, "slider", tooltip)
        if scripted:
            changed, new = True, parse_number(v, label) if isinstance(v, str) else float(v)
        return self._changed(changed), new

    def slider_int(
        self, label: str, value: int, lo: int, hi: int, tooltip: str = ""
    ) -> tuple[bool, int]:
        changed, new = check_return("SliderInt", self.im.SliderInt(label, int(value), lo, hi))
        scripted, v = self._record(label, "slider", tooltip)
        if scripted:
            changed, new = True, parse_number(v, label, True) if isinstance(v, str) else v
        return self._changed(changed), new

    def input_float(
        self, label: str, value: float, fmt: str = "%.4g", tooltip: str = ""
    ) -> tuple[bool, float]:
        """A typed float, applied on Enter only: ``(entered, value)``."""
        flags = self.im.ImGuiInputTextFlags_EnterReturnsTrue
        changed, new = check_return(
            "InputFloat", self.im.InputFloat(label, float(value), 0.0, 0.0, fmt, flags)
        )
        scripted, v = self._record(label, "input", tooltip)
        if scripted:
            changed, new = True, parse_number(v, label) if isinstance(v, str) else float(v)
        return self._changed(changed), new

    def input_int(self, label: str, value: int, tooltip: str = "") -> tuple[bool, int]:
        """A typed integer with -/+ buttons, applied on Enter or a button: ``(changed, value)``."""
        flags = self.im.ImGuiInputTextFlags_EnterReturnsTrue
        changed, new = check_return("InputInt", self.im.InputInt(label, int(value), 1, 100, flags))
        scripted, v = self._record(label, "input", tooltip)
        if scripted:
            changed, new = True, parse_number(v, label, True) if isinstance(v, str) else v
        return self._changed(changed), new

    def input_text(self, label: str, text: str, tooltip: str = "") -> tuple[bool, str]:
        """A text field: ``(Enter pressed, current text)`` (the text is kept while typing)."""
        flags = self.im.ImGuiInputTextFlags_EnterReturnsTrue
        entered, new = check_return("InputText", self.im.InputText(label, text, flags))
        scripted, v = self._record(label, "input", tooltip)
        if scripted:
            entered, new = True, str(v)
        return self._changed(entered), new

    # ------------------------------------------------------------------ plots
    @contextmanager
    def plot(
        self,
        title: str,
        height: float,
        x_label: str,
        y_label: str,
        y_log: bool = False,
        fit_y: bool = True,
    ) -> Iterator[bool]:
        """``with ui.plot(...) as shown:`` an ImPlot with labelled axes, refitted to the data
        every frame (``fit_y=False``: the caller sets the y limits); EndPlot always runs."""
        shown = check_return("BeginPlot", self.ip.BeginPlot(title, (-1, height * self.scale)))
        try:
            if shown:
                fit = self.ip.ImPlotAxisFlags_AutoFit
                self.ip.SetupAxes(x_label, y_label, fit, fit if fit_y else 0)
                if y_log:
                    self.ip.SetupAxisScale(self.ip.ImAxis_Y1, self.ip.ImPlotScale_Log10)
            yield shown
        finally:
            if shown:
                self.ip.EndPlot()

    def plot_y_limits(self, lo: float, hi: float) -> None:
        self.ip.SetupAxisLimits(self.ip.ImAxis_Y1, float(lo), float(hi), self.ip.ImPlotCond_Always)

    def plot_line(self, label: str, x: Any, y: Any) -> None:
        self.ip.PlotLine(label, _f64(x), _f64(y))

    def plot_bars(
        self, label: str, x: Any, y: Any, width: float, colors: Any | None = None
    ) -> None:
        """Bars at ``x`` of heights ``y``; ``colors (k,4)`` gives each bar its own fill (one
        legend entry, ``label``, for all of them)."""
        if colors is None:
            self.ip.PlotBars(label, _f64(x), _f64(y), float(width))
            return
        for i, (xi, yi, c) in enumerate(zip(_f64(x), _f64(y), colors, strict=True)):
            self.ip.SetNextFillStyle(tuple(float(t) for t in c))
            self.ip.PlotBars(label if i == 0 else f"##{label}{i}", _f64([xi]), _f64([yi]), width)

    def plot_vlines(self, label: str, x: Any) -> None:
        self.ip.PlotInfLines(label, _f64(x))

    def plot_hlines(self, label: str, y: Any) -> None:
        self.ip.PlotInfLines(label, _f64(y), self.ip.ImPlotInfLinesFlags_Horizontal)

    # ------------------------------------------------------------------ tables
    @contextmanager
    def table(
        self, table_id: str, headers: Sequence[str], tips: Sequence[str] = ()
    ) -> Iterator[bool]:
        """``with ui.table(id, headers, tips) as shown:`` then :meth:`row` per row: an ImGui
        table with borders, alternating (nearly opaque, so the 3D view behind the panel does
        not show through) row shades, columns as wide as their widest cell, and each header's
        tooltip from ``tips``. EndTable always runs; the table is recorded in :attr:`tables`
        (also when imgui skips drawing it, e.g. a collapsed window)."""
        record = TableRecord(list(headers), list(tips))
        self.tables[(self.section, table_id)] = record
        im = self.im
        flags = (
            im.ImGuiTableFlags_Borders
            | im.ImGuiTableFlags_RowBg
            | im.ImGuiTableFlags_SizingFixedFit
            | im.ImGuiTableFlags_NoHostExtendX
        )
        record.avail = float(im.GetContentRegionAvail()[0])
        im.PushStyleColor(im.ImGuiCol_TableRowBg, TABLE_ROWS[0])
        im.PushStyleColor(im.ImGuiCol_TableRowBgAlt, TABLE_ROWS[1])
        shown = False
        try:
            shown = check_return("BeginTable", im.BeginTable(table_id, len(record.headers), flags))
            self._table, self._table_shown = record, shown
            if shown:
                for h in record.headers:
                    im.TableSetupColumn(h)
                im.TableNextRow(im.ImGuiTableRowFlags_Headers)
                for k, h in enumerate(record.headers):
                    im.TableSetColumnIndex(k)
                    im.TableHeader(h)
                    if k < len(record.tips) and record.tips[k]:
                        im.SetItemTooltip(record.tips[k])
            yield shown
        finally:
            self._table, self._table_shown = None, False
            if shown:
                im.EndTable()
                record.width = float(im.GetItemRectSize()[0])
            im.PopStyleColor(2)

    def row(
        self,
        cells: Sequence[str],
        rgba: tuple[float, float, float, float] | None = None,
        highlight: bool = False,
    ) -> None:
        """One row of the open :meth:`table`: numbers right-aligned, the whole row in ``rgba``
        when given (a flagged row), its background lit when ``highlight``.

        Raises
        ------
        RuntimeError
            Outside ``with ui.table(...)``, or with more cells than the table has columns.
        """
        record = self._table
        if record is None:
            raise RuntimeError("ui.row() outside a ui.table() block")
        cells = [str(c) for c in cells]
        if len(cells) > len(record.headers):
            raise RuntimeError(f"{len(cells)} cells for {len(record.headers)} columns")
        record.rows.append(cells)
        record.colors.append(rgba)
        if highlight:
            record.highlighted.append(len(record.rows) - 1)
        if not self._table_shown:
            return
        im = self.im
        im.TableNextRow()
        if highlight:
            im.TableSetBgColor(im.ImGuiTableBgTarget_RowBg1, im.GetColorU32(HIGHLIGHT))
        for k, cell in enumerate(cells):
            im.TableSetColumnIndex(k)
            if is_number(cell):
                free = im.GetContentRegionAvail()[0] - im.CalcTextSize(cell)[0]
                if free > 0:
                    im.SetCursorPosX(im.GetCursorPosX() + free)
            if rgba is None:
                im.TextUnformatted(cell)
            else:
                im.TextColored(rgba, cell)

    # ------------------------------------------------------------------ overlay, keys
    def key(self, name: str) -> bool:
        """Was the shortcut key ``name`` (see :data:`KEYS`) pressed this frame, outside a text
        field? Scripted as the label ``"key <name>"``."""
        label = f"key {name}"
        self.seen[("keys", label)] = "key"
        queue = self._script.get(label)
        if queue:
            self.driven.add(("keys", label))
            return bool(queue.popleft())
        if self.im.GetIO().WantCaptureKeyboard:
            return False
        return bool(self.im.IsKeyPressed(getattr(self.im, KEYS[name]), False))

    def scene_click(self) -> tuple[float, float] | None:
        """Window position of a left click on the 3D view this frame (not on a panel), or
        ``None``. Scripted as the label ``"click"`` with an ``(x, y)``."""
        self.seen[("scene", "click")] = "click"
        queue = self._script.get("click")
        if queue:
            self.driven.add(("scene", "click"))
            return tuple(queue.popleft())
        io = self.im.GetIO()
        if io.WantCaptureMouse or not self.im.IsMouseClicked(0):
            return None
        return tuple(io.MousePos)

    def hover(self) -> tuple[float, float] | None:
        """Window position of the mouse over the 3D view this frame (``None`` over a panel).
        Scripted as the label ``"hover"`` with an ``(x, y)``."""
        self.seen[("scene", "hover")] = "hover"
        queue = self._script.get("hover")
        if queue:
            self.driven.add(("scene", "hover"))
            return tuple(queue.popleft())
        io = self.im.GetIO()
        if io.WantCaptureMouse:
            return None
        return tuple(io.MousePos)

    def overlay_text(self, pos: tuple[float, float], text: str) -> None:
        """Text drawn over the 3D view at window pixel ``pos``."""
        dl = self.im.GetForegroundDrawList()
        dl.AddText(pos, self.im.GetColorU32((0.05, 0.05, 0.05, 1.0)), text)


def _f64(a: Any) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).ravel()
