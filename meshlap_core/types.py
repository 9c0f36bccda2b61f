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


def _index_range(raw: np.ndarray, name: str, what: str = "face indices") -> tuple[Any, Any]:
    """The smallest and largest index of a non-empty real array, exactly as given; refuses
    non-integral values (13.5, NaN, inf)."""
    if raw.dtype.kind == "O":
        for x in raw.flat:
            if isinstance(x, float | np.floating) and not float(x).is_integer():
                raise MeshError(f"{what} must be integers, got {float(x)!r}", name)
        ints = [int(x) for x in raw.flat]
        return min(ints), max(ints)
    if raw.dtype.kind == "f":
        if not np.isfinite(raw).all():
            raise MeshError(f"{what} must be integers, got NaN or infinity", name)
        if not np.all(np.mod(raw, 1) == 0):
            bad = raw[np.mod(raw, 1) != 0].flat[0]
            raise MeshError(f"{what} must be integers, got {float(bad)!r}", name)
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


# ----------------------------------------------------------------- arguments other than V, F
# (the same refusals as for V and F: no bool taken for 1, no 2.5 truncated to 2, no index
# wrapped to the end, no complex number losing its imaginary part; each names the argument)


def as_indices(values: Any, n: int, name: str, what: str = "vertex indices") -> IntArray:
    """Indices into ``n`` items as a flat ``int64`` array, each checked as given (before a
    cast could wrap ``2⁶³`` to a negative index or truncate ``2.5``) to lie in ``[0, n)``.

    Raises
    ------
    MeshError
        Booleans, complex numbers, strings, non-integral values, NaN, or an index out of
        range (shown as given, with the range).
    """
    raw = np.atleast_1d(real_array(values, name, what))
    if raw.size == 0:
        return np.zeros(0, dtype=np.int64)
    lo, hi = _index_range(raw, name, what)
    if lo < 0 or hi >= n:
        bad = lo if lo < 0 else hi
        raise MeshError(
            f"index {_show_index(bad)} is out of range (there are {n}: 0..{n - 1})"
            if n > 0
            else f"index {_show_index(bad)} is out of range (there are none)",
            name,
        )
    return np.ascontiguousarray(raw.astype(np.int64).ravel())


def as_index(value: Any, n: int, name: str, what: str = "vertex indices") -> int:
    """One index into ``n`` items, as :func:`as_indices` checks it (a scalar, not a list)."""
    if np.ndim(value) != 0:
        raise MeshError(f"must be one index (an integer), got shape {np.shape(value)}", name)
    return int(as_indices(value, n, name, what)[0])


def _scalar(value: Any, name: str, what: str) -> int | float:
    """A real scalar as given (``int`` or ``float``): booleans, complex numbers, strings,
    arrays and other objects refused, saying what was expected."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    if isinstance(value, bool | np.bool_):
        raise MeshError(f"must be {what}, got {value!r}", name)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        return float(value)
    if isinstance(value, complex | np.complexfloating):
        raise MeshError(f"must be {what} (a real number), got {value!r}", name)
    raise MeshError(f"must be {what}, got {_shown(value)}", name)


def as_count(value: Any, name: str, lo: int = 1, hi: int | None = None) -> int:
    """A count (a number of modes, steps, curves...) as an ``int`` in ``[lo, hi]``: booleans,
    fractions (``2.5``), NaN, strings refused, not rounded; a count above ``hi`` refused
    saying the bound."""
    x = _scalar(value, name, "an integer count")
    if isinstance(x, float) and not (np.isfinite(x) and x.is_integer()):
        raise MeshError(f"must be an integer count, got {x!r}", name)
    count = int(x)
    if count < lo:
        raise MeshError(f"must be at least {lo}, got {count}", name)
    if hi is not None and count > hi:
        shown = str(count) if len(str(count)) <= 24 else f"a number of {len(str(count))} digits"
        raise MeshError(f"must be at most {hi}, got {shown}", name)
    return count


def as_real(value: Any, name: str, *, positive: bool = False) -> float:
    """A finite real number (``positive``: ``> 0``); booleans, complex numbers, strings, NaN
    and infinities refused."""
    x = _scalar(value, name, "a number")
    try:
        f = float(x)
    except OverflowError:  # an int beyond the floats
        raise MeshError(f"must be a finite number, got {_shown(value)}", name) from None
    if not np.isfinite(f):
        raise MeshError(f"must be a finite number, got {f!r}", name)
    if positive and not f > 0:
        raise MeshError(f"must be positive, got {f!r}", name)
    return f


def as_field(X: Any, n: int, name: str, columns: bool = True) -> FloatArray:
    """A per-vertex field as a new ``float64`` array of shape ``(n,)`` (or ``(n,c)`` when
    ``columns``): real numbers (no booleans, complex numbers or strings), finite.

    Raises
    ------
    MeshError
        The values are not real numbers, the shape is not ``(n,)`` / ``(n,c)``, or a value
        is NaN or infinite (its vertex named).
    """
    raw = real_array(X, name, "values")
    try:
        arr = np.array(raw, dtype=np.float64, copy=True)
    except (TypeError, ValueError, OverflowError) as exc:
        raise MeshError(f"values are not numbers ({exc})", name) from None
    ok = arr.shape == (n,) or (columns and arr.ndim == 2 and arr.shape[0] == n)
    if not ok:
        want = f"({n},) or ({n},c)" if columns else f"({n},)"
        raise MeshError(
            f"should have shape {want} (one value per vertex); shape is {arr.shape}", name
        )
    finite = np.isfinite(arr) if arr.ndim == 1 else np.isfinite(arr).all(axis=1)
    if not finite.all():
        bad = int(np.flatnonzero(~finite)[0])
        raise MeshError(f"the value at vertex {bad} is NaN or infinite", name)
    return arr


def _shown(value: Any) -> str:
    """``repr(value)``, or its type's name when that is long (a 400-digit int, an array)."""
    text = repr(value)
    return text if len(text) <= 40 else type(value).__name__
