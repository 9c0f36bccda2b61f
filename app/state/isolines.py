"""Isoline settings per scalar field, shared by every panel that shows one (polyscope-free).

A panel keeps one :class:`Isolines` and names its fields by what they show (``"mean"``,
``"eigenfunction"``, ``"distance"`` ...); each field has its own toggle and count. The
count is turned into polyscope's ``isoline_period`` (absolute: the field's finite range
divided by the count) by :meth:`Isolines.options`; :mod:`..isolines` draws the widgets.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.types import FloatArray

COUNT_RANGE = (1, 200)
"""Allowed isoline counts (a typed value is clamped into it)."""
DEFAULT_COUNT = 12


@dataclass
class IsolineSetting:
    """One field's isolines: shown or not, and how many over its range."""

    on: bool = False
    count: int = DEFAULT_COUNT

    def set_count(self, count: Any) -> None:
        """Clamp ``count`` into :data:`COUNT_RANGE`."""
        lo, hi = COUNT_RANGE
        self.count = int(min(max(int(count), lo), hi))


def isoline_period(values: FloatArray | None, count: int) -> float:
    """The spacing of ``count`` isolines over the finite range of ``values`` (1 when the
    range is empty or flat)."""
    if values is None:
        return 1.0
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    span = float(v.max() - v.min()) if v.size else 0.0
    return span / max(int(count), 1) if span > 0 else 1.0


@dataclass
class Isolines:
    """Per field name, its :class:`IsolineSetting` (created on first use)."""

    fields: dict[str, IsolineSetting] = field(default_factory=dict)

    def of(self, name: str, on: bool = False) -> IsolineSetting:
        """The setting of field ``name``; a new one starts shown when ``on``."""
        if name not in self.fields:
            self.fields[name] = IsolineSetting(on=on)
        return self.fields[name]

    def options(self, name: str, values: FloatArray | None, on: bool = False) -> dict[str, Any]:
        """Keywords for polyscope's ``add_scalar_quantity``: ``isolines_enabled`` and, only
        when shown (setting it turns polyscope's isolines on), ``isoline_period``."""
        s = self.of(name, on)
        if not s.on:
            return {"isolines_enabled": False}
        return {"isolines_enabled": True, "isoline_period": isoline_period(values, s.count)}
