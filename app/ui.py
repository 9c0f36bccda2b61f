"""The one thin adapter between the panels and ``polyscope.imgui`` / ``polyscope.implot``.

Every widget of every panel is drawn through a :class:`UI`. It calls the real imgui function
(so the window looks and behaves as imgui makes it), and on top of that it

- **pins the polyscope API**: each call's return value is checked against the type this module
  was written for (``EXPECTED``); a difference raises :class:`UIApiMismatch` (shown in the panel
  and failing the widget tests) instead of a ``TypeError`` deep in a handler;
- keeps imgui's begin/end pairs balanced even when a handler raises (``plot``, ``table`` and
  ``choose`` close what they opened in a ``finally``);
- tracks the panel section being drawn (:meth:`UI.begin_section`, ``section``) and whether a
  widget of it reported a change (``changed``), for the viewer's per-panel error handling;
- names shortcut keys the way a user does (:meth:`UI.key`: ``"space"``, ``"left"``, any letter
  or digit).

Numeric fields apply on Enter only (``ImGuiInputTextFlags_EnterReturnsTrue``): a half-typed
number (the ``0`` of ``0.5``) is never applied; a click selects the whole number.

**Hooks.** The adapter knows nothing of tests. Each interactive widget, shortcut key, scene click
and hover calls :meth:`UI._record` once per frame after imgui drew it; its return value, when not
``None``, replaces what the user did on that frame. Tables call :meth:`UI._record_table`,
:meth:`UI._record_row` and :meth:`UI._record_table_end`. Here the hooks do nothing; the tests'
``ScriptedUI`` (``tests/support/scripted_ui.py``) overrides them to script widgets ("this
frame, combo ``field`` returns ``gaussian``") and to record every widget and table drawn.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from .field_errors import FieldErrors, read_float
from .keys import imgui_key
from .text_numbers import is_number
from .text_wrap import wrap_at_spaces
from .ui_checks import EXPECTED, UIApiMismatch, check_return
from .ui_plots import Plots

RED = (1.0, 0.35, 0.35, 1.0)
GREY = (0.7, 0.7, 0.7, 1.0)
HIGHLIGHT = (0.95, 0.75, 0.2, 0.35)  # the background of a highlighted table row
TABLE_ROWS = ((0.11, 0.11, 0.12, 0.94), (0.17, 0.17, 0.19, 0.94))  # opaque: readable over 3D

MODIFIERS = ("shift", "ctrl", "alt")
"""The modifier keys a scene click reports (:meth:`UI.scene_click`), by these names."""

RGBA = tuple[float, float, float, float]


def fit_text(text: str, width: float, measure: Any) -> str:
    """``text`` cut at its end to ``width`` pixels with ``...`` (``measure(s)[0]``: a string's
    width); the whole text when it fits."""
    if float(measure(text)[0]) <= width:
        return text
    lo, hi = 0, len(text)  # the longest prefix that fits with the dots
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if float(measure(text[:mid].rstrip() + "...")[0]) <= width:
            lo = mid
        else:
            hi = mid - 1
    return text[:lo].rstrip() + "..."


class UI(FieldErrors, Plots):
    """imgui/implot for the panels (see the module docstring).

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
        # window pixel x where meshlap's panel starts: text over the 3D view ends left of it
        self.overlay_right: float | None = None
        self.pointer = True  # False: no hover (a picture of the view is being drawn)
        self.scale = 1.0
        self.section = ""
        self.changed = False  # some widget reported a change since begin_section
        self._table: tuple[int, bool] | None = None  # the open table: (columns, shown)
        self.entered: tuple[str, str, str] | None = None  # see FieldErrors
        self.field_errors: dict[tuple[str, str], str] = {}
        self._field_error_shown = False

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

    def layout(self) -> str:
        """The window's UI layout as Dear ImGui's ini text (``SaveIniSettingsToMemory``)."""
        return str(self.im.SaveIniSettingsToMemory())

    def load_layout(self, text: str) -> None:
        """Apply a layout saved by :meth:`layout` (before the first frame)."""
        self.im.LoadIniSettingsFromMemory(text)

    def begin_section(self, name: str) -> None:
        """The widgets drawn from now on belong to the panel section ``name``; ``changed``
        starts again from ``False``."""
        self.section = name
        self.changed = False
        self.entered = None
        self._field_error_shown = False

    # ------------------------------------------------------------------ hooks
    def _record(
        self,
        label: str,
        kind: str,
        tooltip: str,
        current: Any = None,
        choices: Sequence[str] | None = None,
    ) -> Any:
        """Hook called once per frame by each interactive widget after imgui drew it.

        Parameters
        ----------
        label : str
            The widget's label (``"key <name>"`` for a shortcut key, ``"click"`` / ``"hover"``
            for the scene).
        kind : str
            ``button``, ``checkbox``, ``combo``, ``choose``, ``slider``, ``input``, ``header``,
            ``key``, ``click``, ``hover`` or ``mouse`` (:meth:`scene_drag`).
        tooltip : str
            The widget's tooltip (already shown by the adapter; ``""`` for none).
        current : optional
            The value the widget was drawn with (its type is the type of the answer:
            ``bool``, ``int``, ``float`` or ``str``; ``None`` for keys, clicks and hovers).
        choices : sequence of str, optional
            The items of a combo or drop-down list.

        Returns
        -------
        None or value
            ``None``: what the user did this frame stands (here, always). Otherwise a value
            that replaces it: for a button, header or key whether it was pressed; for a
            checkbox, combo, drop-down, slider or field the new value; for a hover the window
            position ``(x, y)``; for a click ``(x, y)`` followed by the modifier keys held
            (``"shift"``, ``"ctrl"``, ``"alt"``), if any; for a mouse drag ``(x, y, held)``.
        """
        return None

    def _record_button_width(self, label: str, width: float) -> None:
        """Hook called before :meth:`button` draws: its width in pixels (0: its label's)."""

    def _record_table(self, table_id: str, headers: list[str], tips: list[str]) -> None:
        """Hook called when :meth:`table` starts a table, before imgui's ``BeginTable``."""

    def _record_row(self, cells: list[str], rgba: RGBA | None, highlight: bool) -> None:
        """Hook called for each row of the open table (also when imgui does not draw it)."""

    def _record_table_end(self, shown: bool) -> None:
        """Hook called when the table ends, right after imgui's ``EndTable`` when ``shown``."""

    def _widget(
        self,
        label: str,
        kind: str,
        tooltip: str,
        current: Any = None,
        choices: Sequence[str] | None = None,
    ) -> Any:
        """Show ``tooltip`` on the widget just drawn and ask :meth:`_record`."""
        if tooltip:
            self.im.SetItemTooltip(tooltip)
        return self._record(label, kind, tooltip, current, choices)

    def _changed(self, changed: bool) -> bool:
        self.changed = self.changed or bool(changed)
        return bool(changed)

    # ------------------------------------------------------------------ text
    def text(self, text: str) -> None:
        """A line of text, wrapped at the panel width."""
        self.im.PushTextWrapPos(self.wrap_width * self.scale)
        self.im.TextUnformatted(text)
        self.im.PopTextWrapPos()

    def text_whole_words(self, text: str) -> None:
        """Text wrapped at the panel width only at spaces: a file name or a number stays whole
        (imgui's wrap also breaks after ``.``: ``smoothing.`` / ``gif``)."""
        lines = wrap_at_spaces(
            text, self.wrap_width * self.scale, lambda s: float(self.im.CalcTextSize(s)[0])
        )
        for line in lines:
            self.im.TextUnformatted(line)
        self._record_lines(lines)

    def _record_lines(self, lines: list[str]) -> None:
        """Hook called after :meth:`text_whole_words` drew its ``lines``."""

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

    def progress(self, fraction: float, text: str, tail: str = "", width: float = -1.0) -> None:
        """A progress bar (``fraction`` in [0, 1]) with ``text`` and ``tail`` on it, ``width``
        pixels wide (-1: to the panel's edge). Text too long for the bar is cut at its end
        (``...``), keeping ``tail`` (the elapsed time and the percentage: the line still
        moves); ImGui would cut its beginning, what the bar is about."""
        im = self.im
        bar = float(width) if width > 0 else float(im.GetContentRegionAvail()[0])
        room = bar - 2 * float(im.GetStyle().FramePadding[0])
        shown = fit_text(text, room - float(im.CalcTextSize(tail)[0]), im.CalcTextSize) + tail
        if float(im.CalcTextSize(shown)[0]) > room:  # not even the tail fits: cut it too
            shown = fit_text(text + tail, room, im.CalcTextSize)
        im.ProgressBar(float(fraction), (bar, 0), shown)
        self._record_progress(float(fraction), text + tail)

    def job_row(self, fraction: float, text: str, tail: str, button: str, tooltip: str) -> bool:
        """A job's row: its progress bar and, on the same row, a button (Cancel); True when
        the button was pressed. One row, as high as :meth:`status_row`."""
        im = self.im
        label = button.split("##")[0]
        size = float(im.CalcTextSize(label)[0]) + 2 * float(im.GetStyle().FramePadding[0])
        spacing = float(im.GetStyle().ItemSpacing[0])
        avail = float(im.GetContentRegionAvail()[0])
        self.progress(fraction, text, tail, max(avail - size - spacing, 1.0))
        im.SameLine()
        return self.button(button, tooltip)

    def status_row(self, text: str) -> None:
        """A row as high as a widget's with ``text`` in grey, cut to one line (empty: a blank
        row): the place a job's row takes when it runs, so the widgets below never move when
        a job starts or ends."""
        im = self.im
        if not text:
            im.Dummy((1.0, float(im.GetFrameHeight())))
            return
        im.AlignTextToFramePadding()  # the line as high as a framed widget's
        im.TextColored(GREY, fit_text(text, float(im.GetContentRegionAvail()[0]), im.CalcTextSize))

    def _record_progress(self, fraction: float, text: str) -> None:
        """Hook called after :meth:`progress` drew a bar (a job's progress line)."""

    def push_width(self, width: float) -> None:
        self.im.PushItemWidth(width * self.scale)

    def pop_width(self) -> None:
        self.im.PopItemWidth()

    # ------------------------------------------------------------------ widgets
    def header(self, label: str, default_open: bool = True, force: bool | None = None) -> bool:
        """A collapsing header (``force``: open or close it now): is it open this frame?"""
        flags = self.im.ImGuiTreeNodeFlags_DefaultOpen if default_open else 0
        if force is not None:
            self.im.SetNextItemOpen(bool(force))
        result = check_return("CollapsingHeader", self.im.CollapsingHeader(label, flags))
        v = self._record(label, "header", "", result)
        return result if v is None else bool(v)

    def button(self, label: str, tooltip: str = "", width_of: Sequence[str] = ()) -> bool:
        """A button: was it pressed this frame?

        Parameters
        ----------
        label : str
            Its text.
        tooltip : str
            Shown when the mouse rests on it.
        width_of : sequence of str
            Labels the button takes turns with (*play* / *pause*): it is as wide as the widest,
            so the widgets after it keep their place when the label changes.
        """
        width = 0.0
        if width_of:
            pad = float(self.im.GetStyle().FramePadding[0])
            width = max(float(self.im.CalcTextSize(t)[0]) for t in (label, *width_of)) + 2 * pad
        self._record_button_width(label, width)
        result = check_return("Button", self.im.Button(label, (width, 0.0)))
        v = self._widget(label, "button", tooltip, False)
        return self._changed(result if v is None else bool(v))

    def checkbox(self, label: str, value: bool, tooltip: str = "") -> tuple[bool, bool]:
        changed, new = check_return("Checkbox", self.im.Checkbox(label, bool(value)))
        v = self._widget(label, "checkbox", tooltip, bool(value))
        if v is not None:
            changed, new = bool(v) != bool(value), bool(v)
        return self._changed(changed), new

    def combo(
        self, label: str, current: str, items: Sequence[str], tooltip: str = ""
    ) -> tuple[bool, str]:
        """A combo over strings: ``(changed, chosen item)``."""
        items = list(items)
        idx = items.index(current) if current in items else 0
        changed, idx = check_return("Combo", self.im.Combo(label, idx, items))
        v = self._widget(label, "combo", tooltip, current, items)
        if v is not None:
            return self._changed(v != current), v
        return self._changed(changed), items[idx]

    def choose(self, label: str, preview: str, items: Sequence[str], tooltip: str = "") -> str:
        """A drop-down list of ``items`` (BeginCombo + Selectable): the item picked this frame,
        or ``""``."""
        items = list(items)
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
        v = self._widget(label, "choose", tooltip, preview, items)
        if v is not None:
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
        v = self._widget(label, "slider", tooltip, float(value))
        if v is not None:
            changed, new = True, v
        return self._changed(changed), new

    def slider_int(
        self, label: str, value: int, lo: int, hi: int, tooltip: str = ""
    ) -> tuple[bool, int]:
        changed, new = check_return("SliderInt", self.im.SliderInt(label, int(value), lo, hi))
        v = self._widget(label, "slider", tooltip, int(value))
        if v is not None:
            changed, new = True, v
        return self._changed(changed), new

    def input_float(
        self, label: str, value: float, fmt: str = "%.4g", tooltip: str = ""
    ) -> tuple[bool, float]:
        """A typed float, applied on Enter only: ``(entered, value)``.

        The field is text read as a double (imgui's ``InputFloat`` holds a float32, so 1e308
        would arrive as inf); the typed text is kept (:attr:`entered`) for an error to quote,
        and a refused value's error is drawn under the field (:meth:`field_failed`).

        Raises
        ------
        ValueError
            The text is empty or not a number (naming the field and quoting the text).
        """
        im = self.im
        flags = self._number_flags() | im.ImGuiInputTextFlags_CharsScientific
        shown = fmt % float(value)
        entered, text = check_return("InputText", im.InputText(label, shown, flags))
        try:
            v = self._widget(label, "input", tooltip, shown)
        finally:
            self._draw_field_error(label)
        if v is not None:
            entered, text = True, str(v)
        if not entered:
            return self._changed(False), float(value)
        self._entered(label, text)
        return self._changed(True), read_float(text, label)

    def input_int(self, label: str, value: int, tooltip: str = "") -> tuple[bool, int]:
        """A typed integer with -/+ buttons, applied on Enter or a button: ``(changed, value)``
        (a refused value's error is drawn under the field)."""
        flags = self._number_flags()
        changed, new = check_return("InputInt", self.im.InputInt(label, int(value), 1, 100, flags))
        try:
            v = self._widget(label, "input", tooltip, int(value))
        except ValueError:  # typed text that is not a whole number (the tests' adapter)
            self._entered(label, "")
            raise
        finally:
            self._draw_field_error(label)
        if v is not None:
            changed, new = True, v
        if changed:
            self._entered(label, str(new))
        return self._changed(changed), new

    def input_text(self, label: str, text: str, tooltip: str = "") -> tuple[bool, str]:
        """A text field: ``(Enter pressed, current text)`` (the text is kept while typing; a
        refused value's error is drawn under the field)."""
        flags = self.im.ImGuiInputTextFlags_EnterReturnsTrue
        entered, new = check_return("InputText", self.im.InputText(label, text, flags))
        v = self._widget(label, "input", tooltip, str(text))
        self._draw_field_error(label)
        if v is not None:
            entered, new = True, v
        if entered:
            self._entered(label, new)
        return self._changed(entered), new

    # ------------------------------------------------------------------ tables
    @contextmanager
    def table(
        self, table_id: str, headers: Sequence[str], tips: Sequence[str] = ()
    ) -> Iterator[bool]:
        """``with ui.table(id, headers, tips) as shown:`` then :meth:`row` per row: an ImGui
        table with borders, alternating (nearly opaque, so the 3D view behind the panel does
        not show through) row shades, columns as wide as their widest cell, and each header's
        tooltip from ``tips``. EndTable always runs; the hooks see the table also when imgui
        skips drawing it (e.g. a collapsed window)."""
        headers, tips = [str(h) for h in headers], [str(t) for t in tips]
        self._record_table(table_id, headers, tips)
        im = self.im
        flags = (
            im.ImGuiTableFlags_Borders
            | im.ImGuiTableFlags_RowBg
            | im.ImGuiTableFlags_SizingFixedFit
            | im.ImGuiTableFlags_NoHostExtendX
        )
        im.PushStyleColor(im.ImGuiCol_TableRowBg, TABLE_ROWS[0])
        im.PushStyleColor(im.ImGuiCol_TableRowBgAlt, TABLE_ROWS[1])
        shown = False
        try:
            shown = check_return("BeginTable", im.BeginTable(table_id, len(headers), flags))
            self._table = (len(headers), shown)
            if shown:
                for h in headers:
                    im.TableSetupColumn(h)
                im.TableNextRow(im.ImGuiTableRowFlags_Headers)
                for k, h in enumerate(headers):
                    im.TableSetColumnIndex(k)
                    im.TableHeader(h)
                    if k < len(tips) and tips[k]:
                        im.SetItemTooltip(tips[k])
            yield shown
        finally:
            self._table = None
            try:
                if shown:
                    im.EndTable()
                self._record_table_end(shown)
            finally:
                im.PopStyleColor(2)

    def row(
        self,
        cells: Sequence[str],
        rgba: RGBA | None = None,
        highlight: bool = False,
    ) -> None:
        """One row of the open :meth:`table`: numbers right-aligned, the whole row in ``rgba``
        when given (a flagged row), its background lit when ``highlight``.

        Raises
        ------
        RuntimeError
            Outside ``with ui.table(...)``, or with more cells than the table has columns.
        """
        if self._table is None:
            raise RuntimeError("ui.row() outside a ui.table() block")
        columns, shown = self._table
        cells = [str(c) for c in cells]
        if len(cells) > columns:
            raise RuntimeError(f"{len(cells)} cells for {columns} columns")
        self._record_row(cells, rgba, highlight)
        if not shown:
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
        """Was the shortcut key ``name`` pressed this frame, outside a text field?

        ``name`` is one letter or digit, or a named key of :data:`.keys.KEYS` (``"space"``,
        ``"left"``, ...): see :func:`.keys.imgui_key`. The hook sees it as the label
        ``"key <name>"``.
        """
        code = imgui_key(name)
        v = self._record(f"key {name}", "key", "")
        if v is not None:
            return bool(v)
        if self.im.GetIO().WantCaptureKeyboard:
            return False
        return bool(self.im.IsKeyPressed(getattr(self.im, code), False))

    def scene_click(self) -> tuple[tuple[float, float], frozenset[str]] | None:
        """A left click on the 3D view this frame (not on a panel): its window position and
        the modifier keys held (a subset of :data:`MODIFIERS`), or ``None``. The hook sees it
        as the label ``"click"`` (a scripted ``(x, y, "shift")`` is a shift-click)."""
        v = self._record("click", "click", "")
        if v is not None:
            return (float(v[0]), float(v[1])), frozenset(str(m) for m in v[2:])
        io = self.im.GetIO()
        if io.WantCaptureMouse or not self.im.IsMouseClicked(0):
            return None
        held = (bool(io.KeyShift), bool(io.KeyCtrl), bool(io.KeyAlt))
        mods = frozenset(m for m, down in zip(MODIFIERS, held, strict=True) if down)
        return (float(io.MousePos[0]), float(io.MousePos[1])), mods

    def scene_drag(self, tooltip: str = "") -> tuple[tuple[float, float], bool]:
        """The mouse this frame for a drag that a panel follows in the 3D view: its window
        position and whether the left button is held (a drag that started on the view goes on
        over the panel). The hook sees it as the widget ``"scene drag"`` of kind ``mouse``
        with ``tooltip`` (what the drag does); a scripted ``(x, y, held)`` replaces it."""
        v = self._record("scene drag", "mouse", tooltip)
        if v is not None:
            return (float(v[0]), float(v[1])), bool(v[2])
        io = self.im.GetIO()
        return (float(io.MousePos[0]), float(io.MousePos[1])), bool(self.im.IsMouseDown(0))

    def hover(self) -> tuple[float, float] | None:
        """Window position of the mouse over the 3D view this frame (``None`` over a panel).
        The hook sees it as the label ``"hover"``; ``None`` while :attr:`pointer` is off (a
        picture of the view has no pointer)."""
        if not self.pointer:
            return None
        v = self._record("hover", "hover", "")
        if v is not None:
            return tuple(v)
        io = self.im.GetIO()
        if io.WantCaptureMouse:
            return None
        return tuple(io.MousePos)

    def activity(self) -> tuple[Any, ...]:
        """What the user is doing this frame, as a value that changes with any input (mouse
        position, buttons, wheel, typed characters, modifier keys, an active widget): the
        host compares it with the last frame's to tell input from idle."""
        im = self.im
        io = im.GetIO()
        return (
            tuple(io.MousePos),
            bool(im.IsAnyMouseDown()),
            float(io.MouseWheel),
            float(io.MouseWheelH),
            bool(io.WantTextInput),
            int(io.KeyMods),
            bool(im.IsAnyItemActive()),
        )

    def keys_down(self) -> bool:
        """Is any key of the keyboard down this frame (a key press waiting to be answered)?"""
        im = self.im
        keys = self.__dict__.get("_keyboard")
        if keys is None:  # imgui's named keys (ImGuiKey_NamedKey_BEGIN .. END), made once
            known = {int(k) for k in im.ImGuiKey}
            first, end = int(im.ImGuiKey_NamedKey_BEGIN), int(im.ImGuiKey_NamedKey_END)
            keys = self.__dict__["_keyboard"] = [
                im.ImGuiKey(k) for k in range(first, end) if k in known
            ]
        return any(im.IsKeyDown(k) for k in keys)

    def overlay_text(self, pos: tuple[float, float], text: str) -> None:
        """Text drawn over the 3D view at window pixel ``pos``, moved left to end before
        :attr:`overlay_right` (meshlap's panel), not drawn when it has no room there."""
        if self.overlay_right is not None:
            x = min(float(pos[0]), self.overlay_right - float(self.im.CalcTextSize(text)[0]))
            if x < 0:
                return
            pos = (x, float(pos[1]))
        dl = self.im.GetForegroundDrawList()
        dl.AddText(pos, self.im.GetColorU32((0.05, 0.05, 0.05, 1.0)), text)
        self._record_overlay(pos, text)

    def _record_overlay(self, pos: tuple[float, float], text: str) -> None:
        """Hook called after :meth:`overlay_text` drew ``text`` at window pixel ``pos``."""


__all__ = ["EXPECTED", "MODIFIERS", "RGBA", "UI", "UIApiMismatch", "check_return"]
