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


_NOT_NUMBERS = "USVMm"  # strings, bytes, records, datetimes: never coordinates or indices


def real_array(X: Any, name: str, what: str) -> np.ndarray:
    """``X`` as an array of real numbers (any int/uint/float dtype, or an object array of real
    numbers), refusing booleans, complex numbers, strings and the like before any cast could
    drop the imaginary part, turn ``True`` into 1 or parse a string.

    Parameters
    ----------
    X : array_like
    name : str
        The argument or file, named in messages.
    what : str
        What the values are (``"vertex coordinates"``), for messages.

    Returns
    -------
    ndarray
        ``np.asarray(X)`` (not copied, not cast).

    Raises
    ------
    MeshError
    """
    try:
        raw = np.asarray(X)
    except (TypeError, ValueError) as exc:  # ragged nested lists
        raise MeshError(f"{what} are not an array of numbers ({exc})", name) from None
    kind = raw.dtype.kind
    if kind == "b":
        raise MeshError(f"{what} must be numbers, got a boolean array", name)
    if kind == "c":
        raise MeshError(f"{what} must be real numbers, got complex dtype {raw.dtype}", name)
    if kind in _NOT_NUMBERS:
        raise MeshError(f"{what} must be numbers, got dtype {raw.dtype}", name)
    if kind == "O" and raw.size:
        for x in raw.flat:
            if isinstance(x, bool | np.bool_) or not isinstance(
                x, int | float | np.integer | np.floating
            ):
                shown = repr(x) if len(repr(x)) <= 40 else type(x).__name__
                raise MeshError(f"{what} must be real numbers, got {shown}", name)
    return raw


def as_vertices(V: Any, name: str = "V") -> FloatArray:
    """Coerce ``V`` to a C-contiguous ``(n,3) float64`` array (a new array, never a view).

    Accepted: integer, unsigned or float arrays (or nested lists / object arrays of real
    numbers). Refused, never cast: booleans, complex numbers (a cast would drop the imaginary
    part), strings.

    Raises
    ------
    MeshError
        If the values are not real numbers, the shape is not ``(n,3)``, a coordinate is NaN
        or infinite, or beyond ``±MAX_COORDINATE`` (1e75, as the loader: squared lengths
        overflow, and libigl can crash the interpreter on such input).
    """
    raw = real_array(V, name, "vertex coordinates")
    try:
        arr = np.array(raw, dtype=np.float64, copy=True, order="C")
    except (TypeError, ValueError, OverflowError) as exc:
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


def _show_index(value: Any) -> str:
    """An index as the user gave it: exact for integers, ``%g`` for floats (``1e+20``)."""
    if isinstance(value, float | np.floating):
        return f"{float(value):.17g}"
    return str(int(value))


def as_faces(F: Any, n_vertices: int | None = None, name: str = "F") -> IntArray:
    """Coerce ``F`` to a C-contiguous ``(m,3) int64`` array (a new array).

    Every index is checked as given, before the cast to ``int64`` (which would truncate
    ``13.5`` to 13, wrap the ``uint64`` value 2⁶⁴−1 to −1, or turn ``1e20`` into
    −9223372036854775808).

    Parameters
    ----------
    F : (m,3) array_like of int
        Triangle corner indices, 0-based: integers, or floats with integral values. Booleans,
        complex numbers, strings and non-integral values are refused.
    n_vertices : int, optional
        When given, every index must lie in ``[0, n_vertices)``; without it, every index must
        be ``>= 0`` and below 2⁶³.

    Raises
    ------
    MeshError
        On non-integer values, a wrong shape or an index out of range (the index shown as
        given).
    """
    raw = real_array(F, name, "face indices")
    if raw.size == 0:
        raw = raw.reshape(0, 3) if raw.ndim <= 1 or raw.shape[-1] in (0, 3) else raw
    if raw.ndim != 2 or raw.shape[1] != 3:
        raise MeshError(f"should have shape (m,3); shape is {raw.shape}", name)
    if raw.size == 0:
        return np.zeros((0, 3), dtype=np.int64)
    lo, hi = _index_range(raw, name)
    limit = 2**63 if n_vertices is None else int(n_vertices)
    if lo < 0 or hi >= limit:
        bad = lo if lo < 0 else hi
        face = int(np.flatnonzero((raw == bad).any(axis=1))[0])
        shown = _show_index(bad)
        if n_vertices is not None:
            raise MeshError(
                f"face {face} has index {shown} but the mesh has {n_vertices} vertices", name
            )
        rule = "must be >= 0" if lo < 0 else "must be below 2^63"
        raise MeshError(f"face {face} has index {shown}; indices {rule}", name)
    return np.ascontiguousarray(raw.astype(np.int64))  # astype copies: never a view


def _index_range(raw: np.ndarray, name: str) -> tuple[Any, Any]:
    """The smallest and largest index of a non-empty real array, exactly as given; refuses
    non-integral values (13.5, NaN, inf)."""
    if raw.dtype.kind == "O":
        for x in raw.flat:
            if isinstance(x, float | np.floating) and not float(x).is_integer():
                raise MeshError(f"face indices must be integers, got {float(x)!r}", name)
        ints = [int(x) for x in raw.flat]
        return min(ints), max(ints)
    if raw.dtype.kind == "f":
        if not np.isfinite(raw).all():
            raise MeshError("face indices must be integers, got NaN or infinity", name)
        if not np.all(np.mod(raw, 1) == 0):
            bad = raw[np.mod(raw, 1) != 0].flat[0]
            raise MeshError(f"face indices must be integers, got {float(bad)!r}", name)
    return raw.min(), raw.max()


def exact_indices(F: Any, name: str = "F") -> IntArray:
    """Integer indices of any shape as ``int64``, checked before the cast: booleans, complex
    numbers, strings, non-integral values (``13.5``) and values outside ``int64`` (``uint64``
    2⁶⁴−1, ``1e20``: a cast would wrap them) are refused, the value shown as given. The range
    against a vertex count is the caller's check.

    Parameters
    ----------
    F : array_like
    name : str
        Names the argument or file in messages.

    Returns
    -------
    (same shape) int64 array (a new array)

    Raises
    ------
    MeshError
    """
    raw = real_array(F, name, "face indices")
    if raw.size == 0:
        return np.zeros(raw.shape, dtype=np.int64)
    lo, hi = _index_range(raw, name)
    if lo < -(2**63) or hi >= 2**63:
        bad = lo if lo < -(2**63) else hi
        raise MeshError(f"index {_show_index(bad)} is beyond the range of int64", name)
    return np.ascontiguousarray(raw.astype(np.int64))


def as_mesh(V: Any, F: Any) -> tuple[FloatArray, IntArray]:
    """Coerce a ``(V, F)`` pair; indices are checked against ``len(V)``."""
    Vc = as_vertices(V)
    return Vc, as_faces(F, len(Vc))
