"""The shared scanner: one tokenizer contract for every text format (OBJ, OFF, PLY, STL).

The contract, followed by the bulk (numpy) and the per-line parsers alike:

* **lines** end at ``\\n``, ``\\r\\n`` or ``\\r``, nothing else (not U+0085, U+2028,
  U+2029, VT or FF, which :meth:`str.splitlines` would also split on);
* **tokens** are separated by ASCII whitespace (space, tab, VT, FF); a non-ASCII space is part
  of a token;
* **numbers** are ASCII decimal literals with an optional exponent (``-1``, ``.5``,
  ``2.5e-3``), plus ``nan``/``inf``/``infinity`` (any case), which the validator then refuses;
  **integers** are ASCII digits with an optional sign. Anything else in a numeric field
  (``1_0``, ``0x10``, non-ASCII or full-width digits, ``3f2``) is an error naming the line,
  although Python's ``float``/``int`` would accept some of it.

:func:`bulk_numbers` (numpy's ``fromstring``) only answers for text made of the characters of
such literals, and callers check that it yields one value per token, so a bulk parse either
agrees with :func:`to_float`/:func:`to_int` value for value or declines (None) and the caller
falls back to its per-line path. Also here: byte-level helpers over a file's bytes held as a
``uint8`` array (line tables, tokens per line, binary-garbage detection) and :class:`Parsed`,
what a format parser hands to :func:`meshlap_core.validate.validate_mesh`.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import MeshError
from ..types import FloatArray, IntArray


@dataclass
class Parsed:
    """What a format parser hands to the validator."""

    V: FloatArray
    faces: Any  # (m,3) int64 array or Polygons, 0-based
    vertex_map: IntArray | None = None
    repairs: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    vertex_props: dict[str, FloatArray] = field(default_factory=dict)


TEXT_BYTES = bytes(range(9, 14)) + bytes(range(32, 256))  # all but control characters
# |index| at or above this cannot be a vertex index (and would overflow int64 arithmetic)
HUGE_INDEX = 2**53

WHITESPACE = b" \t\v\f\r\n"  # exactly what ``bytes.split()`` splits on
DIGITS = b"0123456789"
INT_CHARS = DIGITS + b"+-"
FLOAT_CHARS = INT_CHARS + b".eE"
_LINE_BREAK = re.compile(rb"\r\n|\r|\n")
_FLOAT = re.compile(
    rb"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|(?i:nan|inf|infinity))"
)
_INT = re.compile(rb"[+-]?[0-9]+")


def split_lines(data: bytes) -> list[bytes]:
    """The lines of ``data``, split at ``\\n``, ``\\r\\n`` and ``\\r`` only."""
    return _LINE_BREAK.split(data) if b"\r" in data else data.split(b"\n")


def has_bare_cr(data: bytes) -> bool:
    """Whether a ``\\r`` not followed by ``\\n`` ends a line (the bulk paths, which split at
    ``\\n``, then leave the file to the per-line parsers)."""
    n_cr = data.count(b"\r")
    return bool(n_cr) and n_cr != data.count(b"\r\n")


def to_float(tok: bytes) -> float:
    """One number token under the contract; ``ValueError`` for anything else."""
    if _FLOAT.fullmatch(tok) is None:
        raise ValueError(tok)
    return float(tok)


def to_int(tok: bytes) -> int:
    """One integer token under the contract (ASCII digits, optional sign); else ``ValueError``."""
    if _INT.fullmatch(tok) is None:
        raise ValueError(tok)
    return int(tok)


def shown(text: bytes, n: int = 60) -> str:
    """``text`` (stripped, at most ``n`` characters) for an error message."""
    return text.strip().decode("utf-8", errors="replace")[:n]


def check_text(arr: np.ndarray, src: str, what: str, offset: int = 0) -> None:
    """Reject control bytes other than tab / newline / CR / FF / VT (binary garbage)."""
    if arr.size == 0 or not arr.tobytes().translate(None, TEXT_BYTES):
        return
    bad = (arr < 9) | ((arr > 13) & (arr < 32))
    pos = int(np.flatnonzero(bad)[0])
    raise MeshError(
        f"binary data in a text {what} file (byte 0x{int(arr[pos]):02x} at offset "
        f"{pos + offset}); the file is corrupt or not {what}",
        src,
    )


def line_table(arr: np.ndarray) -> tuple[IntArray, IntArray]:
    """Start and end (exclusive, before ``\\n``) byte offsets of every line."""
    nl = np.flatnonzero(arr == 10)
    starts = np.concatenate([[0], nl + 1])
    ends = np.concatenate([nl, [len(arr)]])
    if starts[-1] >= len(arr):  # file ends with a newline
        starts, ends = starts[:-1], ends[:-1]
    return starts.astype(np.int64), ends.astype(np.int64)


def tokens_per_line(buf: np.ndarray) -> IntArray:
    """Number of whitespace-separated tokens on each ``\\n``-terminated line of ``buf``."""
    if buf.size == 0:
        return np.zeros(0, dtype=np.int64)
    ws = buf <= 32
    tok = np.flatnonzero(~ws[1:] & ws[:-1]) + 1
    if not ws[0]:
        tok = np.concatenate([[0], tok])
    nl = np.flatnonzero(buf == 10)
    if buf[-1] != 10:
        nl = np.concatenate([nl, [len(buf)]])
    return np.diff(np.concatenate([[0], np.searchsorted(tok, nl)])).astype(np.int64)


def bulk_numbers(text: bytes, dtype: type) -> np.ndarray | None:
    """All whitespace-separated numbers of ``text``, or None if one does not parse.

    None also when ``text`` holds a character that no literal of the contract has (letters
    other than ``e``/``E``, ``_``, non-ASCII bytes; for an integer ``dtype`` also ``.``, ``e``):
    numpy would read ``nan`` or hexadecimal forms the contract leaves to the per-line parsers.
    The caller still checks that the count equals the number of tokens (``"1-2"`` is one token).
    """
    allowed = INT_CHARS if np.dtype(dtype).kind in "iu" else FLOAT_CHARS
    if text.translate(None, allowed + WHITESPACE):
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (ValueError, DeprecationWarning):
            return None


def select_lines(
    data: bytes, arr: np.ndarray, starts: IntArray, ends: IntArray, mask: np.ndarray
) -> bytes:
    """Concatenate the selected lines (each keeps its ``\\n``)."""
    idx = np.flatnonzero(mask)
    if len(idx) == 0:
        return b""
    if idx[-1] - idx[0] + 1 == len(idx):  # one contiguous block (the usual case)
        return data[starts[idx[0]] : ends[idx[-1]]] + b"\n"
    lens = np.diff(np.concatenate([starts, [len(arr)]]))
    out = arr[np.repeat(mask, lens)].tobytes()
    return out if out.endswith(b"\n") else out + b"\n"


def strip_comment(line: bytes) -> bytes:
    i = line.find(b"#")
    return line if i < 0 else line[:i]
