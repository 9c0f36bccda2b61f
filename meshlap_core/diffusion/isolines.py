"""Level curves of a per-vertex scalar field (``igl.isolines``) and their polyline file."""

from __future__ import annotations

import os
from collections.abc import Iterable
from typing import Any

import igl
import numpy as np

from ..errors import MeshError
from ..io.atomic import atomic_write
from ..options import MAX_ISOLINES
from ..types import FloatArray, IntArray, as_count, as_indices, as_mesh, as_vertices, real_array


def isoline_values(values: FloatArray, count: int) -> FloatArray:
    """``count`` levels evenly spaced strictly inside the finite range of ``values``
    (``(max − min)·j/(count+1)`` above the minimum, ``j = 1 … count``), ``(count,)``."""
    count = as_count(count, "count", 1, MAX_ISOLINES)
    raw = real_array(values, "values", "values")
    v = raw.astype(np.float64).ravel()
    v = v[np.isfinite(v)]
    if v.size == 0:
        raise MeshError("the field has no finite value", "values")
    lo, hi = float(v.min()), float(v.max())
    return lo + (hi - lo) * np.arange(1, count + 1) / (count + 1)


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
    s = real_array(values, "values", "values").astype(np.float64)
    if s.shape != (len(V),):
        raise MeshError(f"needs one value per vertex ({len(V)}), got shape {s.shape}", "values")
    if np.isnan(s).any():
        raise MeshError(
            f"the value at vertex {int(np.flatnonzero(np.isnan(s))[0])} is NaN", "values"
        )
    lv = real_array(levels, "levels", "levels").astype(np.float64).ravel()
    if not np.isfinite(lv).all():
        raise MeshError("levels must be finite", "levels")
    if lv.size > MAX_ISOLINES:
        raise MeshError(f"at most {MAX_ISOLINES} levels, got {lv.size}", "levels")
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

    Parameters
    ----------
    path : str or PathLike
    P : (p,3) float
        Finite curve points.
    E : (e,2) int
        Segments, indices into ``P``.

    Raises
    ------
    MeshError
        ``P`` or ``E`` of the wrong shape or type, a non-finite point, a segment index out of
        range, or the output problems of :func:`~meshlap_core.io.atomic.atomic_write`.

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
    P = as_vertices(np.zeros((0, 3)) if np.size(P) == 0 else P, "P")
    raw = real_array(E, "E", "segment indices")
    if raw.size == 0:
        raw = raw.reshape(0, 2)
    if raw.ndim != 2 or raw.shape[1] != 2:
        raise MeshError(f"should have shape (e,2); shape is {raw.shape}", "E")
    E = as_indices(raw, len(P), "E", "segment indices").reshape(-1, 2)
    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        f.write(b"# isolines written by meshlap\n")
        if len(P):
            np.savetxt(f, P, fmt="v %.17g %.17g %.17g")
        if len(E):
            np.savetxt(f, E + 1, fmt="l %d %d")
