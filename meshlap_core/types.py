"""Array type aliases and the coercion every public entry point applies.

``V`` is always ``(n,3) float64`` and ``F`` always ``(m,3) int64``; inputs are copied, never
modified in place.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from .errors import MeshError
from .options import MAX_COORDINATE

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]


def as_vertices(V: Any, name: str = "V") -> FloatArray:
    """Coerce ``V`` to a C-contiguous ``(n,3) float64`` array (a new array, never a view).

    Raises
    ------
    MeshError
        If the shape is not ``(n,3)``, a coordinate is NaN or infinite, or beyond
        ``±MAX_COORDINATE`` (1e75, as the loader: squared lengths overflow, and libigl can
        crash the interpreter on such input).
    """
    try:
        arr = np.array(V, dtype=np.float64, copy=True, order="C")
    except (TypeError, ValueError) as exc:
        raise MeshError(f"vertex coordinates are not numbers ({exc})", name) from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise MeshError(f"should have shape (n,3); shape is {arr.shape}", name)
    if arr.size and not np.abs(arr).max() <= MAX_COORDINATE:  # NaN fails the test too
        if not np.isfinite(arr).all():
            bad = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
            raise MeshError(f"vertex {bad} has a NaN or infinite coordinate", name)
        big = np.abs(arr).max(axis=1)
        bad = int(np.argmax(big))
        raise MeshError(
            f"vertex {bad} has coordinate {float(big[bad]):.3g}; coordinates beyond "
            f"±{MAX_COORDINATE:.0e} overflow squared-length computations (rescale the mesh)",
            name,
        )
    return arr


def as_faces(F: Any, n_vertices: int | None = None, name: str = "F") -> IntArray:
    """Coerce ``F`` to a C-contiguous ``(m,3) int64`` array (a new array).

    Parameters
    ----------
    F : (m,3) array_like of int
        Triangle corner indices, 0-based.
    n_vertices : int, optional
        When given, every index must lie in ``[0, n_vertices)``.

    Raises
    ------
    MeshError
        On a wrong shape, non-integer values or an index out of range.
    """
    raw = np.asarray(F)
    if raw.size and raw.dtype.kind == "f" and not np.all(np.mod(raw, 1) == 0):
        raise MeshError("face indices must be integers", name)
    arr = np.array(raw, dtype=np.int64, copy=True, order="C")
    if arr.size == 0:
        arr = arr.reshape(0, 3)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise MeshError(f"should have shape (m,3); shape is {arr.shape}", name)
    if n_vertices is not None and arr.size:
        lo, hi = int(arr.min()), int(arr.max())
        if lo < 0 or hi >= n_vertices:
            bad = lo if lo < 0 else hi
            face = int(np.flatnonzero((arr == bad).any(axis=1))[0])
            raise MeshError(
                f"face {face} has index {bad} but the mesh has {n_vertices} vertices", name
            )
    return arr


def as_mesh(V: Any, F: Any) -> tuple[FloatArray, IntArray]:
    """Coerce a ``(V, F)`` pair; indices are checked against ``len(V)``."""
    Vc = as_vertices(V)
    return Vc, as_faces(F, len(Vc))
