"""The shared scanner: what every text format's parser agrees on.

Byte-level helpers over a file's bytes held as a ``uint8`` array (line tables, tokens per
line, bulk number parsing, binary-garbage detection) and :class:`Parsed`, what a format
parser hands to :func:`meshlap_core.validate.validate_mesh`.
"""

from __future__ import annotations

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
    """All whitespace-separated numbers of ``text``, or None if one does not parse."""
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


def strip_comment(line: str) -> str:
    i = line.find("#")
    return line if i < 0 else line[:i]
