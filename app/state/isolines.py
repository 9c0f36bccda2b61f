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

from .settings import Custom, integer_problem

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


@dataclass(frozen=True, kw_only=True)
class IsolineFields(Custom):
    """A panel's isolines as one declared setting (its session key ``isolines``): per field
    of ``fields`` whose isolines a user changed, ``{"on": bool, "count": int}`` (a field not
    listed is at its default: shown when in ``shown``, :data:`DEFAULT_COUNT` curves). Made by
    :func:`isoline_fields`; :meth:`capture` and :meth:`apply` read and set a panel's
    :class:`Isolines` (the base panel's ``capture`` / ``configure`` do it)."""

    fields: tuple[str, ...] = ()
    shown: tuple[str, ...] = ()

    def capture(self, iso: Isolines) -> dict[str, dict[str, Any]]:
        """The fields of ``iso`` changed from their defaults, as the session keeps them."""
        out = {}
        for name in self.fields:
            s = iso.fields.get(name)
            if s is not None and (s.on != (name in self.shown) or s.count != DEFAULT_COUNT):
                out[name] = {"on": bool(s.on), "count": int(s.count)}
        return out

    def apply(self, iso: Isolines, value: dict[str, dict[str, Any]]) -> None:
        """Set every field of ``iso`` from a checked ``value`` (a field not in it: default)."""
        for name in self.fields:
            saved = value.get(name, {"on": name in self.shown, "count": DEFAULT_COUNT})
            s = iso.of(name, name in self.shown)
            s.on = bool(saved["on"])
            s.set_count(saved["count"])


def isoline_fields(
    fields: tuple[str, ...], labels: tuple[str, ...] = ("isolines", "isoline count")
) -> IsolineFields:
    """The isolines setting of a panel showing ``fields`` (isolines off by default), drawn by
    the widgets ``labels`` (:func:`meshlap_app.isolines.draw_isolines`: a toggle and a count
    per field; a panel with two fields draws them with a suffix each)."""

    def check(x: Any) -> str | None:
        if not isinstance(x, dict):
            return "must be an object of fields"
        for name, v in x.items():
            if name not in fields:
                return f"has {name!r}; fields are {', '.join(fields)}"
            if not (isinstance(v, dict) and set(v) == {"on", "count"}):
                return f'{name!r} must be {{"on": true/false, "count": N}}'
            if not isinstance(v["on"], bool) or integer_problem(v["count"], *COUNT_RANGE):
                return f"{name!r}: on must be true/false, count {COUNT_RANGE[0]}..{COUNT_RANGE[1]}"
        return None

    hi = COUNT_RANGE[1]
    return IsolineFields(
        "isolines",
        {},
        check=check,
        fields=fields,
        label=labels[0],
        also=labels[1:],
        widget="checkbox",
        added=True,
        tooltip="level curves of the shown field: on or off and how many, per field",
        example={fields[0]: {"on": True, "count": 5}},
        refused=([], {"nonsense": {"on": True, "count": 3}}, {fields[0]: {"on": 1, "count": 3}},
                 {fields[0]: {"on": True, "count": hi + 1}}, {fields[0]: {"on": True}}),
    )  # fmt: skip
