"""Curvature fields of the current mesh (``CurvatureState``) and their colour ranges."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.curvature import all_curvature_fields
from meshlap_core.errors import MeshError
from meshlap_core.options import (
    AREA_KINDS,
    BOUNDARY_RULES,
    CURVATURE_AREA,
    CURVATURE_FIELD_LABELS,
    CURVATURE_FIELDS,
    check_choice,
)
from meshlap_core.types import FloatArray

from .checks import Schema, boolean, number, one_of
from .mesh import MeshState

SESSION: Schema = {
    "field": ("cotan", one_of(CURVATURE_FIELDS)),
    "area": (CURVATURE_AREA, one_of(AREA_KINDS)),
    "boundary": ("pi", one_of(BOUNDARY_RULES)),
    "clip": (2.0, number(0.0, 49.0)),
    "side_by_side": (False, boolean),
    "second_field": ("uniform", one_of(CURVATURE_FIELDS)),
}
"""The Curvature panel's section of a saved session (:mod:`.session`)."""


def check_view_options(options: dict[str, Any], state: Any) -> None:
    """``meshlap view --field``: a known field.

    Raises
    ------
    MeshError
        An unknown field, naming the choices.
    """
    if options.get("field") is not None:
        check_choice(options["field"], CURVATURE_FIELDS, "field", "--field")


def robust_range(values: FloatArray, signed: bool, percentile: float = 2.0) -> tuple[float, float]:
    """Colour-map range that one outlier cannot wash out.

    Parameters
    ----------
    values : (n,) float
    signed : bool
        Symmetric range ``[-r, r]`` around zero (diverging maps) when true.
    percentile : float
        Clip this percentage at each end (0 = full range).

    Returns
    -------
    lo, hi : float
        ``lo < hi`` always (a constant field gets a small symmetric range).
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return -1.0, 1.0
    p = float(np.clip(percentile, 0.0, 49.0))
    lo, hi = np.percentile(v, [p, 100.0 - p])
    if signed:
        r = max(abs(lo), abs(hi))
        r = r if r > 0 else 1.0
        return -float(r), float(r)
    if hi <= lo:
        return float(lo) - 0.5, float(lo) + 0.5
    return float(lo), float(hi)


@dataclass
class CurvatureState:
    """Curvature fields of the current mesh for the chosen area and boundary rule, and how
    they are shown (the field, its clip percentage, a second field side by side)."""

    area: str = CURVATURE_AREA
    boundary: str = "pi"
    field_name: str = "cotan"
    percentile: float = 2.0
    side_by_side: bool = False
    second_field: str = "uniform"
    _key: tuple[Any, ...] = ()
    fields: dict[str, FloatArray] = field(default_factory=dict)
    _summaries: dict[tuple[Any, ...], dict[str, Any]] = field(default_factory=dict)

    def update(self, mesh: MeshState) -> bool:
        """Recompute when the mesh, area or boundary rule changed. Returns whether it did."""
        if self.current(mesh):
            return False
        self.adopt(mesh, self.compute(mesh.V, mesh.F, self.area, self.boundary))
        return True

    def current(self, mesh: MeshState) -> bool:
        """The fields are those of ``mesh`` with the chosen area and boundary rule."""
        return self._key == (mesh.version, self.area, self.boundary)

    def computed_for(self) -> tuple[Any, ...]:
        """``(mesh version, area, boundary rule)`` the fields were computed for (``()``:
        none yet)."""
        return self._key

    @staticmethod
    def compute(
        V: FloatArray, F: Any, area: str, boundary: str, progress: Any = None
    ) -> dict[str, FloatArray]:
        """Every curvature field (any thread or a child process: touches no state)."""
        return all_curvature_fields(V, F, area, boundary)

    def adopt(self, mesh: MeshState, fields: dict[str, FloatArray]) -> None:
        """Take ``fields``, computed for ``mesh`` with the current area and boundary rule."""
        self.fields = fields
        self._key = (mesh.version, self.area, self.boundary)

    def set_percentile(self, percentile: float) -> None:
        """Clip percentage of the colour range, in ``[0, 49]``.

        Raises
        ------
        MeshError
            ``percentile`` is not a finite number (the previous one stays).
        """
        p = float(percentile)
        if not np.isfinite(p):
            raise MeshError(f"must be a finite number, got {percentile!r}", "clip %")
        self.percentile = float(np.clip(p, 0.0, 49.0))

    def color_range(self, name: str | None = None) -> tuple[float, float]:
        """Robust colour range of a field (symmetric around 0 for signed fields)."""
        return self.summary(name)["range"]

    def summary(self, name: str | None = None, bins: int = 60) -> dict[str, Any]:
        """Range, min/max and histogram of a field, cached until the field or the clip
        percentage changes (the panel reads it every frame)."""
        name = name or self.field_name
        key = (self._key, name, self.percentile, bins)
        cached = self._summaries.get(key)
        if cached is None:
            values = self.fields[name]
            lo, hi = robust_range(values, CURVATURE_FIELD_LABELS[name][1], self.percentile)
            counts, edges = np.histogram(np.clip(values, lo, hi), bins=bins, range=(lo, hi))
            cached = {
                "range": (lo, hi),
                "min": float(values.min()),
                "max": float(values.max()),
                "centers": 0.5 * (edges[1:] + edges[:-1]),
                "counts": counts.astype(np.float64),
                "width": float(edges[1] - edges[0]),
            }
            self._summaries = {k: v for k, v in self._summaries.items() if k[0] == self._key}
            self._summaries[key] = cached
        return cached
