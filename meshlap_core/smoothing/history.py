"""The smoothing stepper's history: one entry of figures per step, kept within a limit or
sampled over the whole run (:class:`~.stepper.Smoother`'s ``history``).

An entry holds scalars only (about 0.5 kB): ``iteration``, ``time_ms``, ``step_rms``,
``step_max``, ``drift_rms``, ``volume``, ``volume_change_pct`` and, with a reference,
``rmse``. The displacement figures come from one pass over the positions in cache-sized
blocks (:func:`displacement_sums`): at 692k vertices a step's figures cost a third of a
solve, so they are measured without ``(n,3)`` temporaries.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import MeshError
from ..metrics import percent_volume_change, signed_volume_unchecked
from ..types import FloatArray, IntArray
from .params import check_iters

ROWS_CHUNK = 16384
"""Vertices per block of :func:`displacement_sums` (the block's differences stay in the
cache)."""


def check_history_options(limit: int | None, samples: int | None) -> tuple[int | None, int | None]:
    """``history_limit`` (at least 2) and ``history_samples`` (at least 4), not both.

    Raises
    ------
    MeshError
        Naming the option.
    """
    if limit is not None and check_iters(limit, "history_limit", None) < 2:
        raise MeshError(f"must be at least 2, got {limit}", "history_limit")
    if samples is not None and check_iters(samples, "history_samples", None) < 4:
        raise MeshError(f"must be at least 4, got {samples}", "history_samples")
    if limit is not None and samples is not None:
        raise MeshError("give history_limit or history_samples, not both", "history_samples")
    return limit, None if samples is None else int(samples)


def keep(
    history: list[dict[str, Any]],
    entry: dict[str, Any],
    limit: int | None,
    samples: int | None,
    stride: int,
) -> int:
    """Append ``entry`` to ``history`` in place, keeping the list within ``limit`` (the
    input's entry and the latest ones) or ``samples`` (every ``stride``-th iteration and the
    latest; the stride doubles when the list is full). Returns the stride."""
    if samples is not None:
        if len(history) > 1 and history[-1]["iteration"] % stride:
            history.pop()  # the previous latest entry is off the sampling grid
        history.append(entry)
        if len(history) > samples:
            stride *= 2
            kept = [e for e in history[:-1] if e["iteration"] % stride == 0]
            history[:] = [*kept, history[-1]]
        return stride
    history.append(entry)
    if limit is not None and len(history) > limit:
        del history[1]  # keep the input's entry and the latest ones
    return stride


def displacement_sums(
    x: FloatArray, x0: FloatArray, old: FloatArray | None, ref: FloatArray | None
) -> tuple[float, float, float, float]:
    """``Σ|x − x0|²``, ``Σ|x − old|²``, ``max |x − old|²`` and ``Σ|x − ref|²`` (0 for a
    missing ``old`` or ``ref``) in one pass over blocks of :data:`ROWS_CHUNK` vertices."""
    drift = step = top = dev = 0.0
    for s in range(0, len(x), ROWS_CHUNK):
        e = s + ROWS_CHUNK
        xs = x[s:e]
        d = xs - x0[s:e]
        drift += float(np.einsum("ij,ij->", d, d))
        if old is not None:
            np.subtract(xs, old[s:e], out=d)
            d2 = np.einsum("ij,ij->i", d, d)
            step += float(d2.sum())
            top = max(top, float(d2.max()))
        if ref is not None:
            np.subtract(xs, ref[s:e], out=d)
            dev += float(np.einsum("ij,ij->", d, d))
    return drift, step, top, dev


def step_entry(
    iteration: int,
    elapsed: float,
    x: FloatArray,
    sums: tuple[float, float, float, float],
    *,
    stepped: bool,
    faces: tuple[IntArray, IntArray] | None,
    volume0: float | None,
    reference: bool,
) -> dict[str, Any]:
    """The history entry of positions ``x`` ``(n,3)`` after ``iteration`` steps.

    ``sums``: :func:`displacement_sums` of ``x`` (against the input, the step's start, the
    reference); ``stepped``: a step was taken (else the step figures are 0); ``faces``:
    ``(F, F.T contiguous)`` of a closed mesh with input volume ``volume0`` (``None``: the
    volume is undefined); ``reference``: the sums hold the distance to a reference."""
    n = max(len(x), 1)
    entry: dict[str, Any] = {"iteration": iteration, "time_ms": 1e3 * elapsed}
    entry["step_rms"] = math.sqrt(sums[1] / n) if stepped else 0.0
    entry["step_max"] = math.sqrt(sums[2]) if stepped else 0.0
    entry["drift_rms"] = math.sqrt(sums[0] / n)
    if faces is not None and volume0 is not None:
        vol = signed_volume_unchecked(x, *faces)
        entry["volume"] = vol
        entry["volume_change_pct"] = percent_volume_change(vol, volume0)
    else:
        entry["volume"] = None
        entry["volume_change_pct"] = None
    if reference:
        entry["rmse"] = math.sqrt(sums[3] / n)
    return entry
