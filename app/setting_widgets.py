"""The widget of a declared setting: its label, tooltip, choices and limits read from the schema.

A panel draws a setting with :func:`setting_widget` (a combo over its choices, a checkbox, a
slider over its range or the part of it the schema names for the slider, a typed field); the
panel applies what it returns with its own setter (which checks it against the same schema). A
bound that depends on the mesh or the basis (the modes computed, the surface's domain) narrows
the schema's range for that frame. No polyscope import (the UI adapter is given).
"""

from __future__ import annotations

from typing import Any

from .state.settings import Choice, Integer, Number, Setting, Text, Toggle


def setting_widget(
    ui: Any,
    setting: Setting,
    value: Any,
    lo: float | None = None,
    hi: float | None = None,
    fmt: str | None = None,
) -> tuple[bool, Any]:
    """Draw ``setting``'s widget showing ``value``: ``(changed, new value)``.

    Parameters
    ----------
    ui : UI
        The panel's UI adapter (:class:`meshlap_app.ui.UI`).
    setting : Setting
        The declared setting (its label, tooltip, type, range, widget kind).
    value : Any
        What the state holds now.
    lo, hi : float, optional
        A narrower range for this frame (a slider's ends; a typed field's tooltip says it).
    fmt : str, optional
        How a float slider prints this frame's value (default: the setting's ``fmt``).

    Raises
    ------
    TypeError
        The setting has no widget of its own (``widget`` "button" or "none": the panel draws
        it).
    """
    s, kind = setting, setting.drawn_as
    if isinstance(s, Choice) and kind == "combo":
        return ui.combo(s.label, value, s.choices, s.tooltip)
    if isinstance(s, Toggle) and kind == "checkbox":
        return ui.checkbox(s.label, bool(value), s.tooltip)
    if isinstance(s, Text) and kind == "input":
        return ui.input_text(s.label, str(value), s.tooltip)
    if isinstance(s, Integer | Number) and kind in ("slider", "input"):
        a, b = s.slider if isinstance(s, Number) and s.slider is not None else (s.lo, s.hi)
        a = a if lo is None else max(a, lo)
        b = b if hi is None else min(b, hi)
        if isinstance(s, Integer):
            if kind == "slider":
                return ui.slider_int(s.label, int(value), int(a), int(b), s.tooltip)
            tip = s.tooltip if lo is None and hi is None else f"{s.tooltip} ({a} to {b})"
            return ui.input_int(s.label, int(value), tip)
        if kind == "slider":
            return ui.slider_float(s.label, float(value), a, b, fmt or s.fmt, s.tooltip)
        return ui.input_float(s.label, float(value), fmt or s.fmt, s.tooltip)
    raise TypeError(f"setting {s.key!r} ({kind}) is drawn by its panel, not setting_widget")
