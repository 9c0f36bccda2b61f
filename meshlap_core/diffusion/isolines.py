"""Level curves of a per-vertex scalar field (``igl.isolines``) and their polyline file."""

from __future__ import annotations

import os
from collections.abc import Iterable
from typing import Any

import igl
import numpy as np

from ..errors import MeshError
from ..io.atomic import atomic_write
from ..types import FloatArray, IntArray, as_mesh


def isoline_values(values: FloatArray, count: int) -> FloatArray:
    """``count`` levels evenly spaced strictly inside the finite range of ``values``
    (``(max − min)·j/(count+1)`` above the minimum, ``j = 1 … count``), ``(count,)``."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if int(count) < 1:
        raise MeshError(f"needs at least one isoline, got {count}", "count")
    if v.size == 0:
        raise MeshError("the field has no finite value", "values")
    lo, hi = float(v.min()), float(v.max())
    return lo + (hi - lo) * np.arange(1, int(count) + 1) / (int(count) + 1)


def isolines(
    V: FloatArray, F: IntArray, values: FloatArray, levels: FloatArray
) -> tuple[FloatArray, IntArray, IntArray]:
    """The segments where the piecewise-linear field crosses each level (``igl.isolines``).

    Non-finite values (``inf`` distance in a component without a source) are set above every
    level, so no curve enters such a component.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    values : (n,) float
    levels : (L,) float

    Returns
    -------
    P : (p,3) float
        Curve points.
    E : (e,2) int
        Segments (indices into ``P``).
    level : (e,) int
        Which level each segment belongs to.

    Examples
    --------
    The level ``x = ¼`` of the field ``x`` on the unit square is the segment ``x = ¼``:

    >>> import numpy as np
    >>> from meshlap_core import grid, isolines
    >>> V, F = grid(5, 5)
    >>> P, E, level = isolines(V, F, V[:, 0], np.array([0.25]))
    >>> bool(np.allclose(P[:, 0], 0.25)), sorted(P[:, 1].round(2).tolist()), len(E)
    (True, [0.0, 0.25, 0.5, 0.75, 1.0], 4)
    """
    V, F = as_mesh(V, F)
    s = np.asarray(values, dtype=np.float64)
    if s.shape != (len(V),):
        raise MeshError(f"needs one value per vertex ({len(V)}), got shape {s.shape}", "values")
    lv = np.asarray(levels, dtype=np.float64).ravel()
    if lv.size == 0:
        return np.zeros((0, 3)), np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    top = float(max(np.nanmax(np.where(np.isfinite(s), s, -np.inf)), lv.max()))
    s = np.where(np.isfinite(s), s, top + 1.0 + abs(top))
    P, E, level = igl.isolines(V, F, s, lv)
    return np.asarray(P), np.asarray(E, dtype=np.int64), np.asarray(level, dtype=np.int64)


def save_polylines(
    path: str | os.PathLike, P: FloatArray, E: IntArray, *, overwrite_inputs: Iterable[Any] = ()
) -> None:
    """Write curve segments as an OBJ of ``v`` and ``l`` lines (1-based), atomically.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from meshlap_core import save_polylines
    >>> path = Path(tempfile.mkdtemp()) / "curves.obj"
    >>> P = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0]])  # an L of two segments
    >>> save_polylines(path, P, np.array([[0, 1], [1, 2]]))
    >>> path.read_text().splitlines()[1:]
    ['v 0 0 0', 'v 1 0 0', 'v 1 1 0', 'l 1 2', 'l 2 3']
    """
    P = np.asarray(P, dtype=np.float64)
    E = np.asarray(E, dtype=np.int64)
    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        f.write(b"# isolines written by meshlap\n")
        if len(P):
            np.savetxt(f, P, fmt="v %.17g %.17g %.17g")
        if len(E):
            np.savetxt(f, E + 1, fmt="l %d %d")
