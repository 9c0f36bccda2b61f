"""OBJ reader: a bulk numpy path for plain ``v``/``f`` files and a per-line general path.

Both follow the tokenizer contract of :mod:`meshlap_core.io._scan` and give the same mesh, or
the same error, on every input (a property test feeds both the same files): the bulk path
only answers for files it covers completely (``\\n`` or ``\\r\\n`` line ends, comments on lines
of their own, no continuations, no indentation, every ``v``/``f`` token a literal of the
contract, ``f`` corners written ``v``, ``v/vt``, ``v/vt/vn`` or ``v//vn``) and otherwise, or on
any error, hands the file to the general path, whose messages name the line.

Face and vertex lines are read in blocks of about 8 MB (in two threads for a big file:
numpy's text parsing releases the GIL), so the temporary arrays of the bulk path stay
small beside the file (``f a/1 b/1 c/1`` costs about what ``f a b c`` does).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from ..errors import MeshError
from ..types import IntArray
from ..validate import Polygons
from ._scan import (
    FLOAT_CHARS,
    HUGE_INDEX,
    INT_CHARS,
    WHITESPACE,
    Parsed,
    bulk_numbers,
    check_text,
    has_bare_cr,
    line_table,
    select_lines,
    shown,
    split_lines,
    strip_comment,
    to_float,
    tokens_per_line,
)

# a face corner: v, v/vt, v/vt/vn or v//vn (each an integer of the contract)
_CORNER = re.compile(rb"([+-]?[0-9]+)(?:/[+-]?[0-9]+(?:/[+-]?[0-9]+)?|//[+-]?[0-9]+)?")
_BLOCK = 1 << 23  # bytes of face or vertex lines parsed at a time on the bulk path
_PARALLEL_BYTES = 1 << 23  # a file at least this big parses its blocks in two threads
_WORKERS = 2
_SEP = (9, 10, 11, 12, 13, 32)  # what may follow a keyword: whitespace or the line end
_BLANK = (9, 11, 12, 32)  # a line starting with one of these is indented


def parse_obj(data: bytes, src: str) -> Parsed:
    """The OBJ file ``data`` (named ``src`` in errors): bulk path, else the per-line one."""
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    check_text(np.frombuffer(data, dtype=np.uint8), src, "OBJ")
    fast = parse_obj_bulk(data)
    return fast if fast is not None else parse_obj_lines(data, src)


# --------------------------------------------------------------------------------- bulk path


def _bulk_applies(data: bytes, arr: np.ndarray, starts: IntArray, c0: np.ndarray) -> bool:
    """Whether the file's line structure is one the bulk path reads exactly as written."""
    if len(starts) == 0 or np.isin(c0, _BLANK).any():  # indented lines
        return False
    if has_bare_cr(data):  # a bare CR ends a line too
        return False
    if b"\\\n" in data or b"\\\r" in data or data.endswith(b"\\"):  # line continuations
        return False
    if b"#" in data:  # comments only on lines of their own
        h = np.flatnonzero(arr == ord("#"))
        line = np.searchsorted(starts, h, side="right") - 1
        if np.any(c0[line] != ord("#")):
            return False
    return True


def parse_obj_bulk(data: bytes) -> Parsed | None:
    """Bulk parser for plain ``v x y z`` / ``f a b c ...`` files; None: use the general one.

    ``data`` has no byte-order mark and no control bytes (as :func:`parse_obj` ensures).
    Never raises: a file it would refuse goes to the general parser, whose message then names
    the line (so both paths give the same error).
    """
    arr = np.frombuffer(data, dtype=np.uint8)
    starts, ends = line_table(arr)
    c0 = arr[starts] if len(starts) else np.zeros(0, np.uint8)
    if not _bulk_applies(data, arr, starts, c0):
        return None
    c1 = arr[np.minimum(starts + 1, len(arr) - 1)]
    c1 = np.where(ends - starts >= 2, c1, 10)
    sep = np.isin(c1, _SEP)
    is_v = (c0 == ord("v")) & sep
    is_f = (c0 == ord("f")) & sep
    nv, nf = int(is_v.sum()), int(is_f.sum())
    if nv == 0 or nf == 0:
        return None  # the general parser gives the precise error
    vtext = select_lines(data, arr, starts, ends, is_v)
    ftext = select_lines(data, arr, starts, ends, is_f)
    if len(data) < _PARALLEL_BYTES:
        V, got = _bulk_vertices(vtext, nv, _serial), _bulk_faces(ftext, nf, _serial)
    else:  # numpy's text parsing releases the GIL: the blocks on two cores
        with ThreadPoolExecutor(_WORKERS) as pool:

            def parallel(fn: Any, blocks: Iterator[bytes]) -> list[Any]:
                return [task.result() for task in [pool.submit(fn, b) for b in blocks]]

            # every block submitted before any result is awaited: faces beside vertices
            vertex_tasks = [pool.submit(_vertex_block, b) for b in _blocks(vtext)]
            got = _bulk_faces(ftext, nf, parallel)
            V = _bulk_vertices(vtext, nv, lambda fn, blocks: [t.result() for t in vertex_tasks])
    del vtext
    if V is None or got is None:
        return None
    vals, sizes = got
    if b"-" in ftext and np.any(vals < 0):  # relative indices: -1 is the latest vertex
        per_value = np.repeat(np.cumsum(is_v)[np.flatnonzero(is_f)], sizes)
        neg = vals < 0
        if np.any(neg & (per_value + vals < 0)):
            return None
        vals = np.where(neg, per_value + vals + 1, vals)
    if np.any(sizes < 3) or np.any((vals < 1) | (vals > nv)):
        return None
    idx = vals - 1
    faces: Any = idx.reshape(-1, 3) if np.all(sizes == 3) else Polygons(idx, sizes)
    ignored = {kw: int(np.count_nonzero((c0 == ord(kw)) & sep)) for kw in ("l", "p")}
    return Parsed(V=V.reshape(-1, 3), faces=faces, warnings=_ignored_warnings(ignored))


def _blocks(text: bytes) -> Iterator[bytes]:
    """``text`` (whole lines, each ending in ``\\n``) in pieces of about ``_BLOCK`` bytes."""
    i = 0
    while i < len(text):
        j = text.find(b"\n", min(i + _BLOCK, len(text)) - 1)
        j = len(text) if j < 0 else j + 1
        yield text[i:j]
        i = j


def _keyword_blanked(block: bytes, keyword: bytes, chars: bytes) -> bytes | None:
    """``block`` (lines that each start with ``keyword``) with each line's keyword byte
    blanked; None when a byte outside ``chars`` (or a second keyword letter) occurs.

    With one keyword letter per line and every line starting with it, the letter occurs
    nowhere else: one ``bytes.replace`` blanks exactly the first byte of every line."""
    n_lines = block.count(b"\n")
    if block.translate(None, chars + WHITESPACE + keyword) or block.count(keyword) != n_lines:
        return None
    return block.replace(keyword, b" ")


def _serial(fn: Any, blocks: Iterator[bytes]) -> list[Any]:
    """``fn`` of each block, one after the other (small files)."""
    return [fn(b) for b in blocks]


def _vertex_block(block: bytes) -> np.ndarray | None:
    """The coordinates of a block of ``v`` lines, or None (not exactly 3 literals per line)."""
    text = _keyword_blanked(block, b"v", FLOAT_CHARS)
    if text is None or not np.all(tokens_per_line(np.frombuffer(text, np.uint8)) == 3):
        return None  # w coordinates, vertex colours, missing coordinates, other characters
    vals = bulk_numbers(text, np.float64)
    if vals is None or vals.size != 3 * block.count(b"\n"):
        return None
    return vals


def _bulk_vertices(vtext: bytes, nv: int, run: Any) -> np.ndarray | None:
    """The ``3·nv`` coordinates of the ``v`` lines, or None; ``run(fn, blocks)`` maps
    :func:`_vertex_block` over the blocks (in order; in threads for a big file)."""
    parts = run(_vertex_block, _blocks(vtext))
    if any(p is None for p in parts):
        return None
    V = np.concatenate(parts) if len(parts) != 1 else parts[0]
    return V if V.size == 3 * nv else None


def _face_block(block: bytes) -> tuple[IntArray, IntArray] | None:
    """The vertex indices (as written) and corner counts of a block of ``f`` lines, or None."""
    text = _keyword_blanked(block, b"f", INT_CHARS + b"/")
    if text is None:
        return None
    slashes = b"/" in block
    buf = np.frombuffer(text, dtype=np.uint8)
    buf = buf.copy() if slashes else buf  # _blank_after_slash writes into it
    if not _signs_ok(buf) or (slashes and not _blank_after_slash(buf)):
        return None
    sizes = tokens_per_line(buf)
    vals = bulk_numbers(buf.tobytes() if slashes else text, np.int64)
    if vals is None or vals.size != int(sizes.sum()):
        return None
    return vals, sizes


def _bulk_faces(ftext: bytes, nf: int, run: Any) -> tuple[IntArray, IntArray] | None:
    """The vertex indices (as written) and corner counts of the ``f`` lines, or None;
    ``run(fn, blocks)`` maps :func:`_face_block` over the blocks (see :func:`_bulk_vertices`)."""
    parts = run(_face_block, _blocks(ftext))
    if any(p is None for p in parts):
        return None
    vals_parts, size_parts = [p[0] for p in parts], [p[1] for p in parts]
    vals = np.concatenate(vals_parts) if len(vals_parts) != 1 else vals_parts[0]
    sizes = np.concatenate(size_parts) if len(size_parts) != 1 else size_parts[0]
    if len(sizes) != nf:
        return None
    if vals.size and (vals.max() >= HUGE_INDEX or vals.min() <= -HUGE_INDEX):
        return None  # numpy saturates huge integers; the general parser quotes them as written
    return vals, sizes


def _is_digit(b: np.ndarray) -> np.ndarray:
    return (b >= ord("0")) & (b <= ord("9"))


def _signs_ok(buf: np.ndarray) -> bool:
    """Every ``+``/``-`` starts an integer: after a blank or ``/``, before a digit."""
    sg = np.flatnonzero((buf == ord("+")) | (buf == ord("-")))
    if len(sg) == 0:
        return True
    prev, nxt = buf[sg - 1], buf[sg + 1]  # 0 < sg < len - 1: keyword first, newline last
    return bool(np.all(((prev <= 32) | (prev == ord("/"))) & _is_digit(nxt)))


def _blank_after_slash(buf: np.ndarray) -> bool:
    """Check every corner is ``v``, ``v/vt``, ``v/vt/vn`` or ``v//vn`` and blank (in place)
    every byte from a token's first ``/`` to its end; False if a corner has another form.

    Memory: a few bytes per byte of ``buf`` (positions of blanks and slashes only)."""
    s = np.flatnonzero(buf == ord("/"))
    n = len(buf)
    prev, nxt = buf[s - 1], buf[s + 1]
    slash_prev = prev == ord("/")
    nxt_ok = _is_digit(nxt) | (nxt == ord("+")) | (nxt == ord("-")) | (nxt == ord("/"))
    if not np.all((_is_digit(prev) | slash_prev) & nxt_ok):
        return False
    blanks = np.flatnonzero(buf <= 32)
    token = np.searchsorted(blanks, s)  # slashes with equal values share a token
    if len(s) > 2 and np.any(token[2:] == token[:-2]):  # three slashes in one corner
        return False
    first = np.concatenate([[True], token[1:] != token[:-1]])
    start = s[first]
    end = blanks[token[first]]  # the block ends with a newline: every token has a blank after it
    mark = np.zeros(n + 1, dtype=np.int8)
    mark[start] = 1
    mark[end] = -1
    buf[np.cumsum(mark[:n], dtype=np.int8).view(np.bool_)] = 32
    return True


def _ignored_warnings(n_ignored: dict[str, int]) -> list[str]:
    return [
        f"ignored {n:,} {'line' if kw == 'l' else 'point'} element{'s' if n != 1 else ''} "
        f"('{kw}' lines)"
        for kw, n in n_ignored.items()
        if n
    ]


# ------------------------------------------------------------------------------ general path


def _statements(data: bytes) -> Iterator[tuple[int, bytes, list[bytes]]]:
    """``(line number, line, tokens)`` of every non-blank line, comments removed and
    continuation lines (ending in ``\\``) joined; a continuation on the last line is read as
    written (the backslash dropped), not lost."""
    pending: bytes | None = None
    pending_ln = 0
    for ln, raw in enumerate(split_lines(data), 1):
        if raw.endswith(b"\\"):
            if pending is None:
                pending, pending_ln = b"", ln
            pending += raw[:-1] + b" "
            continue
        if pending is not None:
            raw, ln, pending = pending + raw, pending_ln, None
        parts = strip_comment(raw).split()
        if parts:
            yield ln, raw, parts
    if pending is not None:
        parts = strip_comment(pending).split()
        if parts:
            yield pending_ln, pending, parts


def parse_obj_lines(data: bytes, src: str) -> Parsed:
    """Line-by-line OBJ parser: slashes, negative indices, comments, continuations, polygons."""
    coords: list[float] = []
    flat: list[int] = []
    sizes: list[int] = []
    face_lines: list[int] = []
    n_ignored: dict[str, int] = {}
    for ln, raw, parts in _statements(data):
        kw = parts[0]
        if kw == b"v":
            coords.extend(_obj_vertex(parts, raw, ln, src))
        elif kw == b"f":
            flat.extend(_obj_face_indices(parts[1:], len(coords) // 3, len(sizes), ln, src))
            sizes.append(len(parts) - 1)
            face_lines.append(ln)
        elif kw in (b"l", b"p"):
            n_ignored[kw.decode()] = n_ignored.get(kw.decode(), 0) + 1
    if not coords:
        raise MeshError("no vertices: the file has no 'v' lines (is it an OBJ file?)", src)
    if not sizes:
        raise MeshError("no faces: the file has no 'f' lines (a point cloud is not a mesh)", src)
    nv = len(coords) // 3
    vals = np.asarray(flat, dtype=np.int64)
    size_arr = np.asarray(sizes, dtype=np.int64)
    _check_obj_faces(vals, size_arr, nv, np.asarray(face_lines), src)
    idx = vals - 1
    faces: Any = idx.reshape(-1, 3) if np.all(size_arr == 3) else Polygons(idx, size_arr)
    warns = _ignored_warnings(dict(sorted(n_ignored.items())))
    return Parsed(
        V=np.asarray(coords, dtype=np.float64).reshape(-1, 3), faces=faces, warnings=warns
    )


def _obj_vertex(parts: list[bytes], raw: bytes, ln: int, src: str) -> list[float]:
    """x, y, z of a ``v`` line; every field (w, colour) must be a number of the contract."""
    if len(parts) < 4:
        raise MeshError(
            f"line {ln}: a vertex needs 3 coordinates, found {len(parts) - 1} ({shown(raw)!r})",
            src,
        )
    try:
        xyz = [to_float(t) for t in parts[1:]]
    except ValueError:
        raise MeshError(
            f"line {ln}: cannot read {shown(raw)!r} as vertex coordinates", src
        ) from None
    return xyz[:3]


def _check_obj_faces(
    vals: IntArray, sizes: IntArray, nv: int, face_lines: IntArray, src: str
) -> None:
    """File-level checks with line numbers: corners per face, 1-based indices in range."""
    small = np.flatnonzero(sizes < 3)
    if len(small):
        k = int(small[0])
        raise MeshError(
            f"line {int(face_lines[k])}: face {k} has {int(sizes[k])} "
            f"{'corner' if sizes[k] == 1 else 'corners'}; a face needs at least 3",
            src,
        )
    bad = (vals < 1) | (vals > nv)
    if bad.any():
        pos = int(np.flatnonzero(bad)[0])
        k = int(np.searchsorted(np.cumsum(sizes), pos, side="right"))
        v = int(vals[pos])
        why = (
            "OBJ indices start at 1"
            if v == 0
            else f"the file has {nv:,} {'vertex' if nv == 1 else 'vertices'}"
        )
        raise MeshError(f"line {int(face_lines[k])}: face {k} refers to vertex {v} but {why}", src)


def _obj_face_indices(tokens: list[bytes], nv_sofar: int, k: int, ln: int, src: str) -> list[int]:
    """The 1-based vertex indices of face ``k`` (line ``ln``); relative ones made absolute."""
    out: list[int] = []
    for tok in tokens:
        m = _CORNER.fullmatch(tok)
        if m is None:
            raise MeshError(
                f"line {ln}: cannot read {shown(tok)!r} as a vertex index (face {k})", src
            )
        head = m.group(1)
        i = int(head)
        if i == 0:
            raise MeshError(
                f"line {ln}: face {k} refers to vertex 0 but OBJ indices start at 1", src
            )
        if abs(i) >= HUGE_INDEX:
            raise MeshError(
                f"line {ln}: face {k} refers to vertex {head.decode()} (far beyond any vertex "
                "count)",
                src,
            )
        if i < 0:
            if nv_sofar + i < 0:
                raise MeshError(
                    f"line {ln}: face {k} has relative index {i} but only "
                    f"{nv_sofar:,} vertices precede it",
                    src,
                )
            out.append(nv_sofar + i + 1)  # stored 1-based, like positive ones
        else:
            out.append(i)
    return out
