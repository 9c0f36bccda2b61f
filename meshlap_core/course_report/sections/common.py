"""Helpers shared by the sections."""

from __future__ import annotations

import numpy as np

from ...types import FloatArray

STAT_COLUMNS = ["min", "max", "mean", "median", "p01", "p99"]
"""The columns :func:`stats_row` fills."""


def stats_row(values: FloatArray) -> list[float]:
    """min, max, mean, median, 1st and 99th percentile of the finite values (NaN if none)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return [float("nan")] * 6
    p01, med, p99 = np.percentile(v, [1, 50, 99])
    return [float(v.min()), float(v.max()), float(v.mean()), float(med), float(p01), float(p99)]
