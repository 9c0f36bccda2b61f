"""OFF reader (ASCII; the ``OFF``/``COFF``/``NOFF``/... keywords): bulk path for triangle
files with one record per line, per-line general path for the rest.

The header's counts are checked against the body, never guessed: the body must hold exactly
``nv`` vertex lines, then ``nf`` face lines. A vertex line holds the numbers its keyword calls
for (``OFF`` 3: x y z; ``NOFF`` 6; ``STOFF`` 5; ``COFF`` 3 + an RGB or RGBA colour; ``CNOFF``
and ``NCOFF`` 6 + a colour); a face line holds ``c``, ``c`` vertex indices and an optional
colour (0, 1, 3 or 4 numbers). A face line where the header promises a vertex (or the
reverse) is reported with the counts declared and found.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ..errors import MeshError
from ..validate import Polygons
from ._scan import (
    HUGE_INDEX,
    INT_CHARS,
    WHITESPACE,
    Parsed,
    bulk_numbers,
    check_text,
    has_bare_cr,
    line_table,
    shown,
    split_lines,
    strip_comment,
    to_float,
    to_int,
    tokens_per_line,
)

# numbers on a vertex line, by keyword
_VERTEX_FIELDS: dict[str, tuple[int, ...]] = {
    "OFF": (3,),
    "COFF": (6, 7),
    "NOFF": (6,),
    "CNOFF": (9, 10),
    "NCOFF": (9, 10),
    "STOFF": (5,),
}
_FACE_COLOUR = (0, 1, 3, 4)  # numbers after a face's indices
_BREAK = re.compile(rb"\r\n|\r|\n")


def parse_off(data: bytes, src: str) -> Parsed:
    """The OFF file ``data`` (named ``src`` in errors), its header checked against its body."""
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    keyword, nv, nf, body_start = _off_header(data, src)
    arr = np.frombuffer(data, dtype=np.uint8)
    body = arr[body_start:]
    check_text(body, src, "OFF", body_start)
    if keyword == "OFF" and b"#" not in data[body_start:] and not has_bare_cr(data):
        fast = _off_fast(body, nv, nf)
        if fast is not None:
            return fast
    return _parse_off_general(data[body_start:], keyword, nv, nf, src)


def _off_header(data: bytes, src: str) -> tuple[str, int, int, int]:
    """Keyword, vertex and face counts, and the byte offset where the body starts."""
    pos = 0
    tokens: list[bytes] = []
    keyword = None
    while pos < len(data):
        m = _BREAK.search(data, pos)
        end, nxt = (m.start(), m.end()) if m else (len(data), len(data))
        parts = strip_comment(data[pos:end]).split()
        pos = nxt
        if not parts:
            continue
        if keyword is None:
            keyword = parts[0].decode("latin-1")
            if keyword not in _VERTEX_FIELDS:
                raise MeshError(
                    f"not an OFF file: the first line should be 'OFF', found {keyword[:20]!r}", src
                )
            parts = parts[1:]
            if parts and parts[0].upper() == b"BINARY":
                raise MeshError("binary OFF files are not supported; use ASCII OFF", src)
            if not parts:
                continue
        tokens = parts
        break
    if keyword is None:
        raise MeshError("not an OFF file: no 'OFF' header line", src)
    if len(tokens) < 2:
        raise MeshError("truncated OFF header: the vertex and face counts are missing", src)
    try:
        nv, nf = to_int(tokens[0]), to_int(tokens[1])
    except ValueError:
        raise MeshError(
            f"OFF header counts should be integers, found {shown(b' '.join(tokens[:3]))!r}", src
        ) from None
    if nv < 0 or nf < 0:
        raise MeshError(f"OFF header has negative counts ({nv} vertices, {nf} faces)", src)
    if nv == 0:
        raise MeshError("the OFF header declares 0 vertices", src)
    if nf == 0:
        raise MeshError("the OFF header declares 0 faces (a point cloud is not a mesh)", src)
    return keyword, nv, nf, pos


def _off_fast(body: np.ndarray, nv: int, nf: int) -> Parsed | None:
    """Plain ``OFF``: ``nv`` lines of 3 numbers, then ``nf`` lines ``3 a b c``; else None."""
    ntok = tokens_per_line(body)
    lines = np.flatnonzero(ntok > 0)
    ntok = ntok[lines]
    if len(ntok) != nv + nf or not np.all(ntok[:nv] == 3) or not np.all(ntok[nv:] == 4):
        return None
    text = body.tobytes()
    face_start = int(line_table(body)[0][lines[nv]])
    if text[face_start:].translate(None, INT_CHARS + WHITESPACE):
        return None  # a face field that is not an integer literal: the general path says which
    vals = bulk_numbers(text, np.float64)
    if vals is None or vals.size != 3 * nv + 4 * nf:
        return None
    fv = vals[3 * nv :].reshape(nf, 4)
    if not np.all(fv[:, 0] == 3) or np.abs(fv[:, 1:]).max() >= HUGE_INDEX:
        return None
    return Parsed(V=vals[: 3 * nv].reshape(nv, 3), faces=fv[:, 1:].astype(np.int64))


def _parse_off_general(body: bytes, keyword: str, nv: int, nf: int, src: str) -> Parsed:
    lines = [parts for parts in (strip_comment(x).split() for x in split_lines(body)) if parts]
    if len(lines) < nv + nf:
        got_v = min(len(lines), nv)
        got_f = max(0, len(lines) - nv)
        raise MeshError(
            f"truncated OFF file: the header declares {nv:,} vertices and {nf:,} faces, but "
            f"the file has only {got_v:,} vertex lines and {got_f:,} face lines",
            src,
        )
    if len(lines) > nv + nf:
        raise MeshError(
            f"OFF header counts do not match the data: it declares {nv:,} vertices and "
            f"{nf:,} faces, but {len(lines) - nv - nf:,} more non-empty lines follow the last face",
            src,
        )
    fields = _VERTEX_FIELDS[keyword]
    V = np.empty((nv, 3))
    for i in range(nv):
        V[i] = _off_vertex(lines, i, keyword, nv, nf, src)
    flat: list[int] = []
    sizes: list[int] = []
    for k in range(nf):
        parts = lines[nv + k]
        if _is_vertex(parts, fields):
            n_vert = nv + _run_length(lines, nv, lambda p: _is_vertex(p, fields))
            raise MeshError(_mismatch(keyword, nv, nf, n_vert, nv + k), src)
        idx = _off_face(parts, k, src)
        flat.extend(idx)
        sizes.append(len(idx))
    vals = np.asarray(flat, dtype=np.int64)
    size_arr = np.asarray(sizes, dtype=np.int64)
    faces: Any = vals.reshape(-1, 3) if np.all(size_arr == 3) else Polygons(vals, size_arr)
    return Parsed(V=V, faces=faces)


def _off_vertex(
    lines: list[list[bytes]], i: int, keyword: str, nv: int, nf: int, src: str
) -> tuple[float, float, float]:
    """x, y, z of vertex ``i``; every field must be a number of the contract."""
    parts = lines[i]
    fields = _VERTEX_FIELDS[keyword]
    if len(parts) not in fields:
        if len(parts) > 3 and _is_face(parts):
            n_vert = _run_length(lines, 0, lambda p: len(p) in fields and not _is_face(p))
            raise MeshError(_mismatch(keyword, nv, nf, n_vert, i), src)
        if len(parts) < 3:
            raise MeshError(f"vertex {i} has {len(parts)} coordinates; it needs 3", src)
        want = " or ".join(str(f) for f in fields)
        raise MeshError(
            f"vertex {i} has {len(parts)} numbers; {keyword} vertex lines have {want}", src
        )
    try:
        x, y, z, *_ = (to_float(t) for t in parts)
    except ValueError:
        raise MeshError(
            f"cannot read vertex {i} ({shown(b' '.join(parts))!r}) as numbers", src
        ) from None
    return x, y, z


def _off_face(parts: list[bytes], k: int, src: str) -> list[int]:
    try:
        c = to_int(parts[0])
        idx = [to_int(t) for t in parts[1 : 1 + c]]
        for t in parts[1 + c :]:
            to_float(t)
    except ValueError:
        raise MeshError(
            f"cannot read face {k} ({shown(b' '.join(parts))!r}) as integers", src
        ) from None
    if c < 3:
        raise MeshError(f"face {k} has {c} corners; a face needs at least 3", src)
    if len(idx) < c:
        raise MeshError(f"face {k} declares {c} corners but lists {len(idx)}", src)
    if len(parts) - 1 - c not in _FACE_COLOUR:
        raise MeshError(
            f"face {k} has {len(parts) - 1 - c} numbers after its {c} indices; a face colour "
            "has 1, 3 or 4 (one face per line)",
            src,
        )
    big = [i for i in idx if abs(i) >= HUGE_INDEX]
    if big:
        raise MeshError(f"face {k} has index {big[0]} (far beyond any vertex count)", src)
    return idx


def _is_face(parts: list[bytes]) -> bool:
    """Whether a line reads as a face: ``c`` (>= 3), ``c`` indices, an optional colour."""
    try:
        c = to_int(parts[0])
        [to_int(t) for t in parts[1 : 1 + c]]
    except ValueError:
        return False
    return c >= 3 and len(parts) - 1 - c in _FACE_COLOUR


def _is_vertex(parts: list[bytes], fields: tuple[int, ...]) -> bool:
    """Whether a line in the face section is plainly a vertex: the right count of numbers,
    one of them not an integer (an all-integer line is judged as a face)."""
    if len(parts) not in fields:
        return False
    try:
        [to_float(t) for t in parts]
    except ValueError:
        return False
    try:
        [to_int(t) for t in parts]
    except ValueError:
        return True
    return False


def _run_length(lines: list[list[bytes]], start: int, pred: Any) -> int:
    """How many lines from ``start`` on satisfy ``pred``."""
    n = 0
    while start + n < len(lines) and pred(lines[start + n]):
        n += 1
    return n


def _mismatch(keyword: str, nv: int, nf: int, n_vert: int, line: int) -> str:
    total = nv + nf
    where = "a face" if line < nv else "a vertex"
    return (
        f"OFF header counts do not match the body: the header declares {nv:,} vertices and "
        f"{nf:,} faces, but the body has {n_vert:,} vertex lines and {total - n_vert:,} face "
        f"lines (data line {line + 1} is {where})"
    )
