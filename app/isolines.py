"""The isoline widgets of a scalar field: one toggle and one count, for any panel (the
settings are :class:`.state.isolines.Isolines`; no panel is named here)."""

from __future__ import annotations

from typing import Any

from .state.isolines import COUNT_RANGE, Isolines


def draw_isolines(ui: Any, iso: Isolines, name: str, on: bool = False, suffix: str = "") -> bool:
    """Draw ``isolines{suffix}`` (a checkbox) and ``isoline count{suffix}`` for the field
    ``name``; returns whether either changed (the panel then re-uploads the field with
    :meth:`Isolines.options`)."""
    s = iso.of(name, on)
    ch1, shown = ui.checkbox(
        f"isolines{suffix}", s.on, f"level curves of the {name} field on the mesh"
    )
    if ch1:
        s.on = bool(shown)
    lo, hi = COUNT_RANGE
    ch2, count = ui.input_int(
        f"isoline count{suffix}", s.count, f"curves over the field's range ({lo} to {hi})"
    )
    if ch2:
        s.set_count(count)
    return bool(ch1 or ch2)
