"""OBJ reader: a bulk numpy path for plain ``v``/``f`` files and a per-line general path.

Both give the same mesh (or the same error) on every input: the fast path hands anything it
does not cover (slashes aside: comments inside data, continuations, indentation, polygons
with relative indices, ...) to the general one.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import MeshError
from ..types import IntArray
from ..validate import Polygons
from ._scan import (
    HUGE_INDEX,
    Parsed,
    bulk_numbers,
    check_text,
    line_table,
    select_lines,
    strip_comment,
    tokens_per_line,
)


def _parse_obj(data: bytes, src: str) -> Parsed:
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    arr = np.frombuffer(data, dtype=np.uint8)
    check_text(arr, src, "OBJ")
    fast = _parse_obj_fast(data, arr, src)
    return fast if fast is not None else _parse_obj_general(data, src)


def _parse_obj_fast(data: bytes, arr: np.ndarray, src: str) -> Parsed | None:
    """Bulk parser for plain `v x y z` / `f a b c ...` lines; None: use the general parser."""
    if b"\\\n" in data or b"\\\r\n" in data:  # line continuations
        return None
    starts, ends = line_table(arr)
    if len(starts) == 0:
        return None
    c0 = arr[starts]
    c1 = arr[np.minimum(starts + 1, len(arr) - 1)]
    c1 = np.where(ends - starts >= 2, c1, 10)
    if np.any((c0 == 32) | (c0 == 9)):  # indented lines
        return None
    # keyword followed by blank / tab, or alone on its line (then the token check sends the
    # line to the general parser, which reports it)
    sep = (c1 == 32) | (c1 == 9) | (c1 == 13) | (c1 == 10)
    is_v = (c0 == ord("v")) & sep
    is_f = (c0 == ord("f")) & sep
    nv, nf = int(is_v.sum()), int(is_f.sum())
    if nv == 0 or nf == 0:
        return None  # the general parser gives the precise error

    vtext = select_lines(data, arr, starts, ends, is_v)
    if b"#" in vtext:
        return None
    vbuf = np.frombuffer(vtext, dtype=np.uint8).copy()
    vbuf[vbuf == ord("v")] = 32
    if not np.all(tokens_per_line(vbuf) == 3):
        return None  # w coordinates, vertex colours, missing coordinates
    V = bulk_numbers(vbuf.tobytes(), np.float64)
    if V is None or V.size != 3 * nv:
        return None

    ftext = select_lines(data, arr, starts, ends, is_f)
    if b"#" in ftext:
        return None
    fbuf = np.frombuffer(ftext, dtype=np.uint8).copy()
    fbuf[fbuf == ord("f")] = 32
    if b"/" in ftext:  # "a/b/c", "a//c", "a/b": keep the vertex index before the first slash
        _blank_after_slash(fbuf)
    sizes = tokens_per_line(fbuf)
    if len(sizes) != nf:
        return None
    vals = bulk_numbers(fbuf.tobytes(), np.int64)
    if vals is None or vals.size != int(sizes.sum()):
        return None
    if vals.size and (vals.max() >= HUGE_INDEX or vals.min() <= -HUGE_INDEX):
        return None  # numpy saturates huge integers; the general parser quotes them as written
    if b"-" in ftext and np.any(vals < 0):  # relative indices: -1 is the latest vertex
        nv_before = np.cumsum(is_v)[np.flatnonzero(is_f)]
        per_value = np.repeat(nv_before, sizes)
        neg = vals < 0
        bad = neg & (per_value + vals < 0)
        if bad.any():
            pos = int(np.flatnonzero(bad)[0])
            k = int(np.searchsorted(np.cumsum(sizes), pos, side="right"))
            raise MeshError(
                f"line {int(np.flatnonzero(is_f)[k]) + 1}: face {k} has relative index "
                f"{int(vals[pos])} but only {int(per_value[pos]):,} vertices precede it",
                src,
            )
        vals = np.where(neg, per_value + vals + 1, vals)
    face_lines = np.flatnonzero(is_f) + 1
    _check_obj_faces(vals, sizes, nv, face_lines, src)
    idx = vals - 1
    faces: Any = idx.reshape(-1, 3) if np.all(sizes == 3) else Polygons(idx, sizes)
    ignored = {kw: int(np.count_nonzero((c0 == ord(kw)) & sep)) for kw in ("l", "p")}
    return Parsed(V=V.reshape(-1, 3), faces=faces, warnings=_ignored_warnings(ignored))


def _ignored_warnings(n_ignored: dict[str, int]) -> list[str]:
    return [
        f"ignored {n:,} {'line' if kw == 'l' else 'point'} element{'s' if n != 1 else ''} "
        f"('{kw}' lines)"
        for kw, n in n_ignored.items()
        if n
    ]


def _blank_after_slash(buf: np.ndarray) -> None:
    """In place: replace every byte from a token's first ``/`` to the token's end by a space."""
    ws = buf <= 32
    slash = np.cumsum(buf == ord("/"))
    pos = np.arange(len(buf))
    last_ws = np.maximum.accumulate(np.where(ws, pos, 0))
    buf[(slash - slash[last_ws] > 0) & ~ws] = 32


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


def _parse_obj_general(data: bytes, src: str) -> Parsed:
    """Line-by-line OBJ parser: slashes, negative indices, comments, continuations, polygons."""
    text = data.decode("utf-8", errors="replace")
    raw_lines = text.splitlines()
    coords: list[float] = []
    flat: list[int] = []
    sizes: list[int] = []
    face_lines: list[int] = []
    n_ignored: dict[str, int] = {}
    pending = ""
    pending_ln = 0
    for ln0, raw in enumerate(raw_lines):
        if raw.endswith("\\"):
            if not pending:
                pending_ln = ln0 + 1
            pending += raw[:-1] + " "
            continue
        if pending:
            raw = pending + raw
            ln = pending_ln
            pending = ""
        else:
            ln = ln0 + 1
        parts = strip_comment(raw).split()
        if not parts:
            continue
        kw = parts[0]
        if kw == "v":
            if len(parts) < 4:
                raise MeshError(
                    f"line {ln}: a vertex needs 3 coordinates, found {len(parts) - 1}", src
                )
            try:
                coords.extend((float(parts[1]), float(parts[2]), float(parts[3])))
            except ValueError:
                raise MeshError(
                    f"line {ln}: cannot read {raw.strip()[:60]!r} as vertex coordinates", src
                ) from None
        elif kw == "f":
            flat.extend(_obj_face_indices(parts[1:], len(coords) // 3, len(sizes), ln, src))
            sizes.append(len(parts) - 1)
            face_lines.append(ln)
        elif kw in ("l", "p"):
            n_ignored[kw] = n_ignored.get(kw, 0) + 1
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
    warns = _ignored_warnings(n_ignored)
    return Parsed(
        V=np.asarray(coords, dtype=np.float64).reshape(-1, 3), faces=faces, warnings=warns
    )


def _obj_face_indices(tokens: list[str], nv_sofar: int, k: int, ln: int, src: str) -> list[int]:
    """The 1-based vertex indices of face ``k`` (line ``ln``); relative ones made absolute."""
    out: list[int] = []
    for tok in tokens:
        head = tok.split("/", 1)[0]
        try:
            i = int(head)
        except ValueError:
            raise MeshError(
                f"line {ln}: cannot read {tok!r} as a vertex index (face {k})", src
            ) from None
        if i == 0:
            raise MeshError(
                f"line {ln}: face {k} refers to vertex 0 but OBJ indices start at 1", src
            )
        if abs(i) >= HUGE_INDEX:
            raise MeshError(
                f"line {ln}: face {k} refers to vertex {head} (far beyond any vertex count)", src
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
