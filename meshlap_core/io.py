"""Reading and writing meshes and per-vertex scalars (OBJ, OFF, PLY, STL), atomically.

Every loader is written here (libigl's readers can crash or silently accept garbage) and ends in
:func:`meshlap_core.validate.validate_mesh`, so :func:`load_mesh` returns a
:class:`~meshlap_core.validate.Mesh` whose report lists every repair. Problems with the file
raise :class:`~meshlap_core.errors.MeshError` naming the file and, where it helps, the line,
face or vertex.

Speed: the common case (an all-triangle OBJ with ``v``/``f`` lines, an ASCII OFF/PLY with
one record per line, any binary PLY/STL) is parsed in bulk with numpy, without a Python loop
over lines; everything else (slashes, negative indices, comments inside data, polygons in OFF,
extra properties) takes a slower per-line path that gives the same result.

Writing: :func:`save_mesh` (``.obj``, ``.off``, ``.ply``; PLY can carry a per-vertex
``quality`` scalar), :func:`save_scalars` (``.csv``, ``.npy``, ``.ply``) and the
:func:`atomic_write` context manager they use: temp file in the target's directory, fsync,
``os.replace``; an exception leaves any existing target untouched.
"""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import stat
import warnings
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np

from .errors import MeshError
from .types import FloatArray, IntArray, as_mesh
from .validate import Mesh, Polygons, validate_mesh

MESH_FORMATS: tuple[str, ...] = (".obj", ".off", ".ply", ".stl")
WRITE_FORMATS: tuple[str, ...] = (".obj", ".off", ".ply")
SCALAR_FORMATS: tuple[str, ...] = (".csv", ".npy", ".ply")

PathLike = str | os.PathLike


@dataclass
class _Parsed:
    """What a format parser hands to the validator."""

    V: FloatArray
    faces: Any  # (m,3) int64 array or Polygons, 0-based
    vertex_map: IntArray | None = None
    repairs: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    vertex_props: dict[str, FloatArray] = field(default_factory=dict)


# --------------------------------------------------------------------------------------------
# public API: loading


def load_mesh(path: PathLike, *, repair: bool = True) -> Mesh:
    """Load an OBJ, OFF, PLY (ASCII / binary) or STL (ASCII / binary) triangle mesh.

    The format is chosen by the extension (case-insensitive). The result is validated (and,
    with ``repair=True``, repaired) by :func:`meshlap_core.validate.validate_mesh`.

    Parameters
    ----------
    path : str or PathLike
    repair : bool
        Remove degenerate / duplicate faces and unreferenced vertices (always reported).

    Returns
    -------
    mesh : Mesh
        ``mesh.V (n,3) float64``, ``mesh.F (m,3) int64``, ``mesh.report`` (repairs, warnings,
        manifoldness), ``mesh.vertex_map`` (index of each vertex in the file).

    Raises
    ------
    MeshError
        Missing / unreadable / empty file, a directory, an unknown extension, or any problem
        with the contents (the message names the file).

    Examples
    --------
    >>> mesh = load_mesh("bunny.obj")            # doctest: +SKIP
    >>> mesh.V.shape, mesh.report.repairs        # doctest: +SKIP
    ((3485, 3), [])
    """
    p, src, data = _read_input(path)
    parsed = _parse(p.suffix.lower(), data, src)
    del data  # the parsed arrays are copies: free the file's bytes before validating
    return validate_mesh(
        parsed.V,
        parsed.faces,
        src,
        repair=repair,
        vertex_map=parsed.vertex_map,
        repairs=parsed.repairs,
        warnings=parsed.warnings,
    )


def load_vertex_scalars(path: PathLike, name: str = "quality") -> FloatArray:
    """Read one per-vertex scalar property (default ``quality``) from a PLY file.

    The values are in the file's vertex order (use ``mesh.vertex_map`` to follow a repaired
    mesh): ``load_vertex_scalars(p)[mesh.vertex_map]``.

    Parameters
    ----------
    path : str or PathLike
        A ``.ply`` file.
    name : str
        The vertex property.

    Returns
    -------
    values : (n,) float64

    Raises
    ------
    MeshError
        Not a PLY file, or the vertex element has no such property.
    """
    p, src, data = _read_input(path)
    if p.suffix.lower() != ".ply":
        raise MeshError(
            f"per-vertex scalars can only be read from .ply files, not {p.suffix!r}", src
        )
    parsed = _parse_ply(data, src)
    if name not in parsed.vertex_props:
        have = ", ".join(sorted(parsed.vertex_props)) or "none"
        raise MeshError(f"the vertex element has no property {name!r} (properties: {have})", src)
    return parsed.vertex_props[name]


def _read_input(path: PathLike) -> tuple[Path, str, bytes]:
    try:
        src = os.fspath(path)
    except TypeError:
        raise MeshError(f"expected a file path, got {type(path).__name__}", "path") from None
    p = Path(src)
    if not p.exists():
        raise MeshError("no such file", src)
    if p.is_dir():
        raise MeshError("is a directory, not a mesh file", src)
    ext = p.suffix.lower()
    if ext not in MESH_FORMATS:
        what = f"unknown mesh format {p.suffix!r}" if ext else "the file name has no extension"
        raise MeshError(f"{what}; supported formats: {', '.join(MESH_FORMATS)}", src)
    try:
        mode = p.stat().st_mode
    except OSError as exc:
        raise MeshError(f"cannot read the file: {exc.strerror or exc}", src) from None
    if not stat.S_ISREG(mode):
        # a FIFO would block forever, /dev/zero would never end
        kind = (
            "a named pipe (FIFO)"
            if stat.S_ISFIFO(mode)
            else "a device"
            if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
            else "a socket"
            if stat.S_ISSOCK(mode)
            else "a special file"
        )
        raise MeshError(f"not a regular file ({kind}); meshlap reads mesh files only", src)
    try:
        data = p.read_bytes()
    except PermissionError:
        raise MeshError("cannot read the file: permission denied", src) from None
    except OSError as exc:
        raise MeshError(f"cannot read the file: {exc.strerror or exc}", src) from None
    if not data or data.isspace():
        raise MeshError(
            "the file is empty" if not data else "the file contains only whitespace", src
        )
    return p, src, data


def _parse(ext: str, data: bytes, src: str) -> _Parsed:
    if ext == ".obj":
        return _parse_obj(data, src)
    if ext == ".off":
        return _parse_off(data, src)
    if ext == ".ply":
        return _parse_ply(data, src)
    return _parse_stl(data, src)


# --------------------------------------------------------------------------------------------
# text helpers


_TEXT_BYTES = bytes(range(9, 14)) + bytes(range(32, 256))  # all but control characters
# |index| at or above this cannot be a vertex index (and would overflow int64 arithmetic)
_HUGE_INDEX = 2**53


def _check_text(arr: np.ndarray, src: str, what: str, offset: int = 0) -> None:
    """Reject control bytes other than tab / newline / CR / FF / VT (binary garbage)."""
    if arr.size == 0 or not arr.tobytes().translate(None, _TEXT_BYTES):
        return
    bad = (arr < 9) | ((arr > 13) & (arr < 32))
    pos = int(np.flatnonzero(bad)[0])
    raise MeshError(
        f"binary data in a text {what} file (byte 0x{int(arr[pos]):02x} at offset "
        f"{pos + offset}); the file is corrupt or not {what}",
        src,
    )


def _line_table(arr: np.ndarray) -> tuple[IntArray, IntArray]:
    """Start and end (exclusive, before ``\\n``) byte offsets of every line."""
    nl = np.flatnonzero(arr == 10)
    starts = np.concatenate([[0], nl + 1])
    ends = np.concatenate([nl, [len(arr)]])
    if starts[-1] >= len(arr):  # file ends with a newline
        starts, ends = starts[:-1], ends[:-1]
    return starts.astype(np.int64), ends.astype(np.int64)


def _tokens_per_line(buf: np.ndarray) -> IntArray:
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


def _bulk_numbers(text: bytes, dtype: type) -> np.ndarray | None:
    """All whitespace-separated numbers of ``text``, or None if one does not parse."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (ValueError, DeprecationWarning):
            return None


def _select_lines(
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


def _strip_comment(line: str) -> str:
    i = line.find("#")
    return line if i < 0 else line[:i]


# --------------------------------------------------------------------------------------------
# OBJ


def _parse_obj(data: bytes, src: str) -> _Parsed:
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    arr = np.frombuffer(data, dtype=np.uint8)
    _check_text(arr, src, "OBJ")
    fast = _parse_obj_fast(data, arr, src)
    return fast if fast is not None else _parse_obj_general(data, src)


def _parse_obj_fast(data: bytes, arr: np.ndarray, src: str) -> _Parsed | None:
    """Bulk parser for plain `v x y z` / `f a b c ...` lines; None: use the general parser."""
    if b"\\\n" in data or b"\\\r\n" in data:  # line continuations
        return None
    starts, ends = _line_table(arr)
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

    vtext = _select_lines(data, arr, starts, ends, is_v)
    if b"#" in vtext:
        return None
    vbuf = np.frombuffer(vtext, dtype=np.uint8).copy()
    vbuf[vbuf == ord("v")] = 32
    if not np.all(_tokens_per_line(vbuf) == 3):
        return None  # w coordinates, vertex colours, missing coordinates
    V = _bulk_numbers(vbuf.tobytes(), np.float64)
    if V is None or V.size != 3 * nv:
        return None

    ftext = _select_lines(data, arr, starts, ends, is_f)
    if b"#" in ftext:
        return None
    fbuf = np.frombuffer(ftext, dtype=np.uint8).copy()
    fbuf[fbuf == ord("f")] = 32
    if b"/" in ftext:  # "a/b/c", "a//c", "a/b": keep the vertex index before the first slash
        _blank_after_slash(fbuf)
    sizes = _tokens_per_line(fbuf)
    if len(sizes) != nf:
        return None
    vals = _bulk_numbers(fbuf.tobytes(), np.int64)
    if vals is None or vals.size != int(sizes.sum()):
        return None
    if vals.size and (vals.max() >= _HUGE_INDEX or vals.min() <= -_HUGE_INDEX):
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
    return _Parsed(V=V.reshape(-1, 3), faces=faces, warnings=_ignored_warnings(ignored))


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


def _parse_obj_general(data: bytes, src: str) -> _Parsed:
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
        parts = _strip_comment(raw).split()
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
            nv_sofar = len(coords) // 3
            count = 0
            for tok in parts[1:]:
                head = tok.split("/", 1)[0]
                try:
                    i = int(head)
                except ValueError:
                    raise MeshError(
                        f"line {ln}: cannot read {tok!r} as a vertex index (face {len(sizes)})",
                        src,
                    ) from None
                if i == 0:
                    raise MeshError(
                        f"line {ln}: face {len(sizes)} refers to vertex 0 but OBJ indices "
                        "start at 1",
                        src,
                    )
                if abs(i) >= _HUGE_INDEX:
                    raise MeshError(
                        f"line {ln}: face {len(sizes)} refers to vertex {head} (far beyond "
                        "any vertex count)",
                        src,
                    )
                if i < 0:
                    if nv_sofar + i < 0:
                        raise MeshError(
                            f"line {ln}: face {len(sizes)} has relative index {i} but only "
                            f"{nv_sofar:,} vertices precede it",
                            src,
                        )
                    flat.append(nv_sofar + i + 1)  # stored 1-based, like positive ones
                else:
                    flat.append(i)
                count += 1
            sizes.append(count)
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
    return _Parsed(
        V=np.asarray(coords, dtype=np.float64).reshape(-1, 3), faces=faces, warnings=warns
    )


# --------------------------------------------------------------------------------------------
# OFF


def _parse_off(data: bytes, src: str) -> _Parsed:
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    arr = np.frombuffer(data, dtype=np.uint8)
    starts, ends = _line_table(arr)
    # header: keyword line, then counts (possibly on the same line); comments / blanks allowed
    li = 0
    tokens: list[str] = []
    keyword = None
    while li < len(starts):
        parts = _strip_comment(data[starts[li] : ends[li]].decode("latin-1")).split()
        li += 1
        if not parts:
            continue
        if keyword is None:
            keyword = parts[0]
            if keyword not in ("OFF", "COFF", "NOFF", "CNOFF", "STOFF", "NCOFF"):
                raise MeshError(
                    f"not an OFF file: the first line should be 'OFF', found {keyword[:20]!r}", src
                )
            parts = parts[1:]
            if parts and parts[0].upper() == "BINARY":
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
        nv, nf = int(tokens[0]), int(tokens[1])
    except ValueError:
        raise MeshError(
            f"OFF header counts should be integers, found {' '.join(tokens[:3])!r}", src
        ) from None
    if nv < 0 or nf < 0:
        raise MeshError(f"OFF header has negative counts ({nv} vertices, {nf} faces)", src)
    if nv == 0:
        raise MeshError("the OFF header declares 0 vertices", src)
    if nf == 0:
        raise MeshError("the OFF header declares 0 faces (a point cloud is not a mesh)", src)
    body_start = int(starts[li]) if li < len(starts) else len(data)
    body = arr[body_start:]
    _check_text(body, src, "OFF", body_start)

    if keyword == "OFF" and b"#" not in data[body_start:]:
        ntok = _tokens_per_line(body)
        ntok = ntok[ntok > 0]
        if len(ntok) == nv + nf and np.all(ntok[:nv] == 3) and np.all(ntok[nv:] == 4):
            vals = _bulk_numbers(body.tobytes(), np.float64)
            if vals is not None and vals.size == 3 * nv + 4 * nf:
                fv = vals[3 * nv :].reshape(nf, 4)
                if (
                    np.all(fv[:, 0] == 3)
                    and np.all(np.mod(fv[:, 1:], 1) == 0)
                    and np.abs(fv[:, 1:]).max() < _HUGE_INDEX
                ):
                    return _Parsed(
                        V=vals[: 3 * nv].reshape(nv, 3), faces=fv[:, 1:].astype(np.int64)
                    )
    return _parse_off_general(data[body_start:], nv, nf, src)


def _parse_off_general(body: bytes, nv: int, nf: int, src: str) -> _Parsed:
    lines = [
        parts
        for parts in (_strip_comment(x).split() for x in body.decode("latin-1").splitlines())
        if parts
    ]
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
    V = np.empty((nv, 3))
    for i in range(nv):
        parts = lines[i]
        if len(parts) < 3:
            raise MeshError(f"vertex {i} has {len(parts)} coordinates; it needs 3", src)
        try:
            V[i] = (float(parts[0]), float(parts[1]), float(parts[2]))
        except ValueError:
            raise MeshError(
                f"cannot read vertex {i} ({' '.join(parts)[:60]!r}) as numbers", src
            ) from None
    flat: list[int] = []
    sizes: list[int] = []
    for k in range(nf):
        parts = lines[nv + k]
        try:
            c = int(parts[0])
            idx = [int(t) for t in parts[1 : 1 + c]]
        except ValueError:
            raise MeshError(
                f"cannot read face {k} ({' '.join(parts)[:60]!r}) as integers", src
            ) from None
        if c < 3:
            raise MeshError(f"face {k} has {c} corners; a face needs at least 3", src)
        if len(idx) < c:
            raise MeshError(f"face {k} declares {c} corners but lists {len(idx)}", src)
        big = [i for i in idx if abs(i) >= _HUGE_INDEX]
        if big:
            raise MeshError(f"face {k} has index {big[0]} (far beyond any vertex count)", src)
        flat.extend(idx)
        sizes.append(c)
    vals = np.asarray(flat, dtype=np.int64)
    size_arr = np.asarray(sizes, dtype=np.int64)
    faces: Any = vals.reshape(-1, 3) if np.all(size_arr == 3) else Polygons(vals, size_arr)
    return _Parsed(V=V, faces=faces)


# --------------------------------------------------------------------------------------------
# PLY

_PLY_TYPES = {
    "char": "i1",
    "int8": "i1",
    "uchar": "u1",
    "uint8": "u1",
    "short": "i2",
    "int16": "i2",
    "ushort": "u2",
    "uint16": "u2",
    "int": "i4",
    "int32": "i4",
    "uint": "u4",
    "uint32": "u4",
    "float": "f4",
    "float32": "f4",
    "double": "f8",
    "float64": "f8",
}


@dataclass
class _PlyProp:
    name: str
    dtype: str  # numpy code without byte order, e.g. "f4"
    count_dtype: str | None = None  # set for list properties


@dataclass
class _PlyElement:
    name: str
    count: int
    props: list[_PlyProp] = field(default_factory=list)


def _ply_header(data: bytes, src: str) -> tuple[str, list[_PlyElement], int]:
    if not (data.startswith(b"ply\n") or data.startswith(b"ply\r\n")):
        raise MeshError("not a PLY file: it does not start with 'ply'", src)
    m = re.search(rb"end_header[ \t]*\r?\n", data)
    if m is None:
        raise MeshError("the PLY header has no 'end_header' line (truncated or not PLY)", src)
    header = data[: m.start()].decode("latin-1")
    fmt = None
    elements: list[_PlyElement] = []
    for ln, line in enumerate(header.splitlines(), 1):
        parts = line.split()
        if not parts or parts[0] in ("ply", "comment", "obj_info"):
            continue
        if parts[0] == "format":
            if fmt is not None:
                raise MeshError(f"PLY header line {ln}: a second 'format' line", src)
            if len(parts) < 2 or parts[1] not in (
                "ascii",
                "binary_little_endian",
                "binary_big_endian",
            ):
                raise MeshError(f"PLY header line {ln}: unknown format {line.strip()!r}", src)
            fmt = parts[1]
        elif parts[0] == "element":
            try:
                elements.append(_PlyElement(parts[1], int(parts[2])))
            except (IndexError, ValueError):
                raise MeshError(
                    f"PLY header line {ln}: bad element line {line.strip()!r}", src
                ) from None
            if elements[-1].count < 0:
                raise MeshError(f"PLY header line {ln}: negative element count", src)
        elif parts[0] == "property":
            if not elements:
                raise MeshError(f"PLY header line {ln}: property before any element", src)
            try:
                if parts[1] == "list":
                    elements[-1].props.append(
                        _PlyProp(parts[4], _PLY_TYPES[parts[3]], _PLY_TYPES[parts[2]])
                    )
                else:
                    elements[-1].props.append(_PlyProp(parts[2], _PLY_TYPES[parts[1]]))
            except (IndexError, KeyError):
                raise MeshError(
                    f"PLY header line {ln}: bad property line {line.strip()!r}", src
                ) from None
        else:
            raise MeshError(f"PLY header line {ln}: unknown keyword {parts[0]!r}", src)
    if fmt is None:
        raise MeshError("the PLY header has no 'format' line", src)
    return fmt, elements, m.end()


def _ply_mesh_parts(elements: list[_PlyElement], src: str) -> tuple[_PlyElement, _PlyElement]:
    by_name = {e.name: e for e in elements}
    vert = by_name.get("vertex")
    face = by_name.get("face")
    if vert is None or vert.count == 0:
        raise MeshError("the PLY file has no vertices (no 'element vertex' or count 0)", src)
    names = [p.name for p in vert.props]
    for c in "xyz":
        if c not in names:
            raise MeshError(f"the PLY vertex element has no '{c}' property", src)
        if any(p.name == c and p.count_dtype is not None for p in vert.props):
            raise MeshError(f"the PLY vertex property '{c}' is a list, not a number", src)
    if face is None or face.count == 0:
        raise MeshError("the PLY file has no faces (a point cloud is not a mesh)", src)
    lists = [p for p in face.props if p.count_dtype is not None]
    if not lists:
        raise MeshError("the PLY face element has no vertex index list", src)
    return vert, face


def _face_list_prop(face: _PlyElement) -> _PlyProp:
    lists = [p for p in face.props if p.count_dtype is not None]
    for p in lists:
        if p.name in ("vertex_indices", "vertex_index"):
            return p
    return lists[0]


def _parse_ply(data: bytes, src: str) -> _Parsed:
    fmt, elements, body_start = _ply_header(data, src)
    vert, face = _ply_mesh_parts(elements, src)
    if fmt == "ascii":
        values = _ply_read_ascii(data, body_start, elements, src)
    else:
        values = _ply_read_binary(data, body_start, elements, "<" if "little" in fmt else ">", src)
    vv = values["vertex"]
    V = np.stack([np.asarray(vv[c], dtype=np.float64) for c in "xyz"], axis=1)
    props = {
        p.name: np.array(vv[p.name], dtype=np.float64)  # a copy, not a view of the file's bytes
        for p in vert.props
        if p.count_dtype is None
    }
    lp = _face_list_prop(face)
    flat, sizes = values["face"][lp.name]
    if flat.dtype.kind == "f":
        raise MeshError("PLY face indices must be integers, not floats", src)
    flat = flat.astype(np.int64)
    faces: Any = flat.reshape(-1, 3) if np.all(sizes == 3) else Polygons(flat, sizes)
    return _Parsed(V=V, faces=faces, vertex_props=props)


def _describe_counts(elements: list[_PlyElement]) -> str:
    names = {"vertex": "vertices", "face": "faces"}
    return " and ".join(f"{e.count:,} {names.get(e.name, e.name + ' records')}" for e in elements)


def _ply_read_binary(
    data: bytes, pos: int, elements: list[_PlyElement], bo: str, src: str
) -> dict[str, dict[str, Any]]:
    """Binary PLY body: fixed-size elements via one structured ``frombuffer``; list elements
    assume the first record's list lengths for all records (checked), else a record loop."""
    out: dict[str, dict[str, Any]] = {}
    total = len(data)
    for el in elements:
        if not el.props:  # an element without properties has no data
            out[el.name] = {}
            continue
        if all(p.count_dtype is None for p in el.props):
            dt = np.dtype([(p.name, bo + p.dtype) for p in el.props])
            need = dt.itemsize * el.count
            if pos + need > total:
                raise MeshError(_truncated_msg(elements, el, total - pos, need), src)
            rec = np.frombuffer(data, dtype=dt, count=el.count, offset=pos)
            out[el.name] = {p.name: rec[p.name] for p in el.props}
            pos += need
            continue
        vals, pos = _ply_binary_list_element(data, pos, el, bo, elements, src)
        out[el.name] = vals
    rest = data[pos:]
    if rest.strip(b" \t\r\n\0"):
        raise MeshError(
            f"PLY header counts do not match the data: after the {_describe_counts(elements)} "
            f"it declares, {len(rest):,} more bytes follow",
            src,
        )
    return out


def _truncated_msg(elements: list[_PlyElement], el: _PlyElement, have: int, need: int) -> str:
    return (
        f"truncated PLY file: the header declares {_describe_counts(elements)}, but the data "
        f"ends inside the {el.name} element ({need:,} bytes needed there, {max(have, 0):,} left)"
    )


def _ply_binary_list_element(
    data: bytes, pos: int, el: _PlyElement, bo: str, elements: list[_PlyElement], src: str
) -> tuple[dict[str, Any], int]:
    total = len(data)
    if el.count == 0:
        return {
            p.name: (np.zeros(0), np.zeros(0, np.int64)) if p.count_dtype else np.zeros(0)
            for p in el.props
        }, pos
    # read the first record to learn its list lengths
    lens = []
    q = pos
    for p in el.props:
        if p.count_dtype is None:
            q += np.dtype(p.dtype).itemsize
            continue
        cdt = np.dtype(bo + p.count_dtype)
        if q + cdt.itemsize > total:
            raise MeshError(_truncated_msg(elements, el, total - pos, q + cdt.itemsize - pos), src)
        c = int(np.frombuffer(data, dtype=cdt, count=1, offset=q)[0])
        if c < 0:
            raise MeshError(f"{el.name} record 0 has a list of negative length {c}", src)
        lens.append(c)
        q += cdt.itemsize + c * np.dtype(p.dtype).itemsize
        if q > total:
            raise MeshError(_truncated_at(elements, el, 0), src)
    fields = []
    li = 0
    for p in el.props:
        if p.count_dtype is None:
            fields.append((p.name, bo + p.dtype))
        else:
            fields.append((f"__n_{p.name}", bo + p.count_dtype))
            fields.append((p.name, bo + p.dtype, (lens[li],)))
            li += 1
    dt = np.dtype(fields)
    need = dt.itemsize * el.count
    if pos + need <= total:
        rec = np.frombuffer(data, dtype=dt, count=el.count, offset=pos)
        li = 0
        uniform = True
        for p in el.props:
            if p.count_dtype is not None:
                uniform &= bool(np.all(rec[f"__n_{p.name}"] == lens[li]))
                li += 1
        if uniform:
            out: dict[str, Any] = {}
            li = 0
            for p in el.props:
                if p.count_dtype is None:
                    out[p.name] = rec[p.name]
                else:
                    out[p.name] = (
                        rec[p.name].reshape(-1),
                        np.full(el.count, lens[li], dtype=np.int64),
                    )
                    li += 1
            return out, pos + need
    # variable list lengths: one record at a time
    scal: dict[str, list[float]] = {p.name: [] for p in el.props if p.count_dtype is None}
    lists: dict[str, tuple[list[np.ndarray], list[int]]] = {
        p.name: ([], []) for p in el.props if p.count_dtype is not None
    }
    for r in range(el.count):
        for p in el.props:
            if p.count_dtype is None:
                dt1 = np.dtype(bo + p.dtype)
                if pos + dt1.itemsize > total:
                    raise MeshError(_truncated_at(elements, el, r), src)
                scal[p.name].append(np.frombuffer(data, dt1, 1, pos)[0])
                pos += dt1.itemsize
            else:
                cdt = np.dtype(bo + p.count_dtype)
                idt = np.dtype(bo + p.dtype)
                if pos + cdt.itemsize > total:
                    raise MeshError(_truncated_at(elements, el, r), src)
                c = int(np.frombuffer(data, cdt, 1, pos)[0])
                if c < 0:
                    raise MeshError(f"{el.name} record {r} has a list of negative length {c}", src)
                pos += cdt.itemsize
                if pos + c * idt.itemsize > total:
                    raise MeshError(_truncated_at(elements, el, r), src)
                lists[p.name][0].append(np.frombuffer(data, idt, c, pos))
                lists[p.name][1].append(c)
                pos += c * idt.itemsize
    out = {k: np.asarray(v) for k, v in scal.items()}
    for k, (chunks, cs) in lists.items():
        out[k] = (np.concatenate(chunks) if chunks else np.zeros(0), np.asarray(cs, np.int64))
    return out, pos


def _truncated_at(elements: list[_PlyElement], el: _PlyElement, r: int) -> str:
    return (
        f"truncated PLY file: the header declares {_describe_counts(elements)}, but the data "
        f"ends after {r:,} of the {el.count:,} {el.name} records"
    )


def _ply_read_ascii(
    data: bytes, pos: int, elements: list[_PlyElement], src: str
) -> dict[str, dict[str, Any]]:
    body = np.frombuffer(data, dtype=np.uint8)[pos:]
    _check_text(body, src, "PLY", pos)
    fast = _ply_ascii_fast(body, elements)
    if fast is not None:
        return fast
    tokens = body.tobytes().split()
    k = 0
    nt = len(tokens)
    out: dict[str, dict[str, Any]] = {}
    for el in elements:
        scal: dict[str, list[float]] = {p.name: [] for p in el.props if p.count_dtype is None}
        lists: dict[str, tuple[list[float], list[int]]] = {
            p.name: ([], []) for p in el.props if p.count_dtype is not None
        }
        for r in range(el.count if el.props else 0):  # an element without properties has no data
            for p in el.props:
                try:
                    if p.count_dtype is None:
                        scal[p.name].append(float(tokens[k]))
                        k += 1
                    else:
                        c = int(tokens[k])
                        if c < 0:
                            raise MeshError(
                                f"{el.name} record {r} has a list of negative length {c}", src
                            )
                        vals = [float(t) for t in tokens[k + 1 : k + 1 + c]]
                        if len(vals) < c:
                            raise IndexError
                        lists[p.name][0].extend(vals)
                        lists[p.name][1].append(c)
                        k += 1 + c
                except IndexError:
                    raise MeshError(
                        f"truncated PLY file: the header declares {_describe_counts(elements)}, "
                        f"but the data ends after {r:,} of the {el.count:,} {el.name} records",
                        src,
                    ) from None
                except ValueError:
                    raise MeshError(
                        f"cannot read {tokens[k].decode('latin-1')[:30]!r} as a number "
                        f"({el.name} record {r}, property {p.name!r})",
                        src,
                    ) from None
        vals_out: dict[str, Any] = {kk: np.asarray(v, dtype=np.float64) for kk, v in scal.items()}
        for kk, (vs, cs) in lists.items():
            arr = np.asarray(vs, dtype=np.float64)
            if arr.size and np.all(np.mod(arr, 1) == 0):
                if np.abs(arr).max() >= _HUGE_INDEX:
                    raise MeshError(
                        f"the {el.name} property {kk!r} has the value {np.abs(arr).max():.6g}, "
                        "far beyond any vertex count",
                        src,
                    )
                arr = arr.astype(np.int64)
            vals_out[kk] = (arr, np.asarray(cs, dtype=np.int64))
        out[el.name] = vals_out
    if k < nt:
        raise MeshError(
            f"PLY header counts do not match the data: after the {_describe_counts(elements)} "
            f"it declares, {nt - k:,} more values follow",
            src,
        )
    return out


def _ply_ascii_fast(
    body: np.ndarray, elements: list[_PlyElement]
) -> dict[str, dict[str, Any]] | None:
    """Exactly ``vertex`` (scalars) then ``face`` (one list, all triangles), one record per line."""
    if [e.name for e in elements] != ["vertex", "face"]:
        return None
    vert, face = elements
    if any(p.count_dtype for p in vert.props) or len(face.props) != 1:
        return None
    nv, nf, k = vert.count, face.count, len(vert.props)
    ntok = _tokens_per_line(body)
    ntok = ntok[ntok > 0]
    if len(ntok) != nv + nf or not np.all(ntok[:nv] == k) or not np.all(ntok[nv:] == 4):
        return None
    vals = _bulk_numbers(body.tobytes(), np.float64)
    if vals is None or vals.size != k * nv + 4 * nf:
        return None
    vv = vals[: k * nv].reshape(nv, k)
    ff = vals[k * nv :].reshape(nf, 4)
    if (
        not np.all(ff[:, 0] == 3)
        or not np.all(np.mod(ff[:, 1:], 1) == 0)
        or (nf and np.abs(ff[:, 1:]).max() >= _HUGE_INDEX)
    ):
        return None
    return {
        "vertex": {p.name: vv[:, i] for i, p in enumerate(vert.props)},
        "face": {
            face.props[0].name: (ff[:, 1:].astype(np.int64).ravel(), np.full(nf, 3, dtype=np.int64))
        },
    }


# --------------------------------------------------------------------------------------------
# STL

_STL_DTYPE = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])


def _parse_stl(data: bytes, src: str) -> _Parsed:
    n_bin = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    if n_bin >= 0 and len(data) == 84 + 50 * n_bin:
        if n_bin == 0:
            raise MeshError("the binary STL file has 0 triangles", src)
        tri = np.frombuffer(data, dtype=_STL_DTYPE, count=n_bin, offset=84)
        P = tri["v"].astype(np.float64).reshape(-1, 3)
        kind = "binary"
    elif data.lstrip()[:5].lower() == b"solid" and not _has_control_bytes(data):
        P = _stl_ascii_corners(data, src)
        kind = "ASCII"
    elif len(data) < 84:
        raise MeshError(
            f"not an STL file: it does not start with 'solid' and is too short for binary STL "
            f"({len(data)} bytes; the binary header alone is 84)",
            src,
        )
    else:
        raise MeshError(
            f"truncated or corrupt binary STL: the header declares {n_bin:,} triangles "
            f"(84 + 50·{n_bin:,} = {84 + 50 * n_bin:,} bytes) but the file has {len(data):,} bytes",
            src,
        )
    ok = np.isfinite(P).all(axis=1)
    if not ok.all():
        c = int(np.flatnonzero(~ok)[0])
        raise MeshError(
            f"triangle {c // 3} has a NaN or infinite coordinate at corner {c % 3}", src
        )
    P = P + 0.0  # -0.0 -> 0.0 so that equal positions weld
    V, first, inverse = np.unique(P, axis=0, return_index=True, return_inverse=True)
    F = inverse.reshape(-1, 3).astype(np.int64)
    repairs = [
        f"welded the {len(P):,} triangle corners of this {kind} STL into {len(V):,} vertices "
        "(identical coordinates merged)"
    ]
    return _Parsed(V=V, faces=F, vertex_map=first.astype(np.int64), repairs=repairs)


def _has_control_bytes(data: bytes) -> bool:
    return bool(data.translate(None, _TEXT_BYTES))


def _stl_ascii_corners(data: bytes, src: str) -> FloatArray:
    arr = np.frombuffer(data, dtype=np.uint8)
    _check_text(arr, src, "STL")
    lower = data.lower()
    facets = [m.start() for m in re.finditer(rb"(?m)^[ \t]*facet\b", lower)]
    verts = list(re.finditer(rb"(?m)^[ \t]*vertex\b([^\n]*)", lower))
    if not facets:
        raise MeshError("the ASCII STL file has no 'facet' (no triangles)", src)
    vpos = np.asarray([m.start() for m in verts], dtype=np.int64)
    per = np.diff(np.searchsorted(vpos, np.asarray([*facets, len(data)])))
    first_v = int(np.searchsorted(vpos, facets[0]))
    if first_v:
        raise MeshError("ASCII STL: a 'vertex' line appears before the first 'facet'", src)
    bad = np.flatnonzero(per != 3)
    if len(bad):
        k = int(bad[0])
        raise MeshError(
            f"ASCII STL facet {k} has {int(per[k])} vertices; STL facets are triangles"
            + (" (truncated file?)" if k == len(per) - 1 and per[k] < 3 else ""),
            src,
        )
    text = b"\n".join(m.group(1) for m in verts) + b"\n"
    ntok = _tokens_per_line(np.frombuffer(text, dtype=np.uint8))
    vals = _bulk_numbers(text, np.float64) if np.all(ntok == 3) else None
    if vals is None or vals.size != 3 * len(verts):
        bad_v = int(np.flatnonzero(ntok != 3)[0]) if np.any(ntok != 3) else 0
        raise MeshError(
            f"ASCII STL: cannot read the coordinates of vertex line {bad_v} of facet "
            f"{bad_v // 3} ({verts[bad_v].group(1).strip()[:40].decode('latin-1')!r})",
            src,
        )
    return vals.reshape(-1, 3)


# --------------------------------------------------------------------------------------------
# writing


def _resolved(path: PathLike) -> Path:
    return Path(os.path.abspath(os.fspath(path))).resolve(strict=False)


def _check_output_path(path: PathLike, overwrite_inputs: Iterable[PathLike]) -> Path:
    target = Path(os.fspath(path))
    if not os.fspath(path):
        raise MeshError("the output path is empty", "path")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise MeshError("the output directory does not exist", os.fspath(parent))
    if target.is_dir():
        raise MeshError("the output path is a directory", os.fspath(target))
    res = _resolved(target)
    for inp in overwrite_inputs:
        same = _resolved(inp) == res
        if not same and target.exists() and Path(os.fspath(inp)).exists():
            with contextlib.suppress(OSError):
                same = os.path.samefile(target, inp)
        if same:
            raise MeshError(
                "refusing to overwrite an input file; choose a different output path",
                os.fspath(target),
            )
    return target


def check_output_path(
    path: PathLike, overwrite_inputs: Iterable[PathLike] = (), suffixes: Iterable[str] | None = None
) -> Path:
    """Check an output path before any work is done (commands call it first, so that a
    doomed run fails in a second and leaves nothing behind).

    Parameters
    ----------
    path : str or PathLike
    overwrite_inputs : iterable of path
        Inputs the output must not replace.
    suffixes : iterable of str, optional
        Allowed extensions (lowercase, with the dot).

    Returns
    -------
    path : Path

    Raises
    ------
    MeshError
        Empty path, a missing directory (named), a directory as target, an input as target,
        or an extension not in ``suffixes``.
    """
    target = _check_output_path(path, overwrite_inputs)
    if suffixes is not None:
        allowed = tuple(suffixes)
        if target.suffix.lower() not in allowed:
            raise MeshError(
                f"unsupported output type {target.suffix or '(none)'!r}; use {', '.join(allowed)}",
                os.fspath(path),
            )
    return target


@contextlib.contextmanager
def atomic_write(
    path: PathLike,
    mode: str = "w",
    *,
    overwrite_inputs: Iterable[PathLike] = (),
    encoding: str = "utf-8",
) -> Iterator[IO[Any]]:
    """Write a file atomically: the target appears complete or not at all.

    A temporary file is created in the target's directory, written through the yielded file
    object, flushed, fsync'ed and renamed over the target with ``os.replace``. If the ``with``
    body raises, the temporary file is removed and an existing target is left untouched.

    Parameters
    ----------
    path : str or PathLike
        The file to (re)place.
    mode : {"w", "wb"}
        Text (UTF-8, ``\\n`` newlines) or binary.
    overwrite_inputs : iterable of path
        Paths that must not be written (e.g. the command's input mesh); compared after
        resolving symlinks.

    Yields
    ------
    f : file object

    Raises
    ------
    MeshError
        The directory does not exist (named), the target is a directory or one of
        ``overwrite_inputs``, or the directory is not writable.

    Examples
    --------
    >>> with atomic_write(tmp / "values.txt") as f:   # doctest: +SKIP
    ...     f.write("1.0\\n")
    """
    if mode not in ("w", "wb"):
        raise MeshError(f"mode must be 'w' or 'wb', got {mode!r}", "mode")
    target = _check_output_path(path, overwrite_inputs)
    parent = target.parent if str(target.parent) else Path(".")
    tmp = parent / f".{target.name}.{secrets.token_hex(6)}.tmp"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    except PermissionError:
        raise MeshError(
            "cannot write in this directory: permission denied", os.fspath(parent)
        ) from None
    except OSError as exc:
        raise MeshError(
            f"cannot create a file here: {exc.strerror or exc}", os.fspath(parent)
        ) from None
    if target.exists():  # keep the permissions of the file being replaced
        with contextlib.suppress(OSError):
            os.chmod(tmp, stat.S_IMODE(target.stat().st_mode))
    f: IO[Any] = (
        os.fdopen(fd, "wb") if mode == "wb" else os.fdopen(fd, "w", encoding=encoding, newline="\n")
    )
    try:
        yield f
        f.flush()
        os.fsync(f.fileno())
        f.close()
        os.replace(tmp, target)
    except BaseException:
        f.close()
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    with contextlib.suppress(OSError):  # make the rename itself durable (best effort)
        dfd = os.open(parent, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)


def save_mesh(
    path: PathLike,
    V: Any,
    F: Any,
    *,
    scalars: Any = None,
    overwrite_inputs: Iterable[PathLike] = (),
    binary: bool = True,
) -> None:
    """Write a triangle mesh as ``.obj``, ``.off`` or ``.ply`` (by extension), atomically.

    Parameters
    ----------
    path : str or PathLike
    V : (n,3) float
    F : (m,3) int
        0-based (written 1-based in OBJ).
    scalars : (n,) float, optional
        Per-vertex values, stored as the PLY vertex property ``quality`` (``double``); only
        ``.ply`` can carry them.
    overwrite_inputs : iterable of path
        Paths that must not be overwritten (the CLI passes its input file).
    binary : bool
        PLY only: ``binary_little_endian`` (default) or ``ascii``.

    Raises
    ------
    MeshError
        Unknown extension, scalars of the wrong length or on a non-PLY file, a missing output
        directory (named), or writing onto an input.

    Notes
    -----
    Coordinates are written with 17 significant digits in the text formats (and as doubles in
    binary PLY), so a write/read round trip gives back exactly the same ``V`` and ``F``.
    """
    ext = Path(os.fspath(path)).suffix.lower()
    if ext not in WRITE_FORMATS:
        raise MeshError(
            f"cannot write {ext!r} files; use one of {', '.join(WRITE_FORMATS)}"
            if ext
            else f"the output has no extension; use one of {', '.join(WRITE_FORMATS)}",
            os.fspath(path),
        )
    V, F = as_mesh(V, F)
    q = None
    if scalars is not None:
        if ext != ".ply":
            raise MeshError("only .ply files can carry per-vertex scalars", os.fspath(path))
        q = np.asarray(scalars, dtype=np.float64).ravel()
        if len(q) != len(V):
            raise MeshError(f"has {len(q):,} values for {len(V):,} vertices", "scalars")
    if ext == ".ply":
        with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
            _write_ply(f, V, F, q, binary)
        return
    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        if ext == ".obj":
            f.write(f"# written by meshlap: {len(V)} vertices, {len(F)} faces\n".encode())
            np.savetxt(f, V, fmt="v %.17g %.17g %.17g")
            np.savetxt(f, F + 1, fmt="f %d %d %d")
        else:
            f.write(f"OFF\n{len(V)} {len(F)} 0\n".encode())
            np.savetxt(f, V, fmt="%.17g %.17g %.17g")
            np.savetxt(f, F, fmt="3 %d %d %d")


def _write_ply(
    f: IO[bytes], V: FloatArray, F: IntArray, q: FloatArray | None, binary: bool
) -> None:
    props = ["x", "y", "z"] + (["quality"] if q is not None else [])
    head = [
        "ply",
        f"format {'binary_little_endian' if binary else 'ascii'} 1.0",
        "comment written by meshlap",
        f"element vertex {len(V)}",
        *(f"property double {p}" for p in props),
        f"element face {len(F)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    f.write(("\n".join(head) + "\n").encode("ascii"))
    cols = V if q is None else np.column_stack([V, q])
    if binary:
        f.write(np.ascontiguousarray(cols, dtype="<f8").tobytes())
        if len(F) and F.max() > np.iinfo(np.int32).max:
            raise MeshError("too many vertices for a PLY int32 index", "F")
        rec = np.empty(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        rec["n"] = 3
        rec["i"] = F
        f.write(rec.tobytes())
    else:
        np.savetxt(f, cols, fmt=" ".join(["%.17g"] * cols.shape[1]))
        np.savetxt(f, F, fmt="3 %d %d %d")


def save_scalars(
    path: PathLike,
    values: Any,
    *,
    V: Any = None,
    F: Any = None,
    overwrite_inputs: Iterable[PathLike] = (),
) -> None:
    """Write per-vertex (or per-face) scalars as ``.csv``, ``.npy`` or ``.ply``, atomically.

    Parameters
    ----------
    path : str or PathLike
        ``.csv``: a header line ``value`` then one value per line (17 significant digits);
        ``.npy``: a 1-D float64 array; ``.ply``: the mesh with a ``quality`` vertex property
        (needs ``V`` and ``F``).
    values : (n,) float
    V : (n,3) float, optional
    F : (m,3) int, optional
        Required for ``.ply``.
    overwrite_inputs : iterable of path
        Paths that must not be overwritten.

    Raises
    ------
    MeshError
        Unknown extension, values not 1-D, ``.ply`` without ``V``/``F``, or the output
        problems of :func:`atomic_write`.
    """
    ext = Path(os.fspath(path)).suffix.lower()
    if ext not in SCALAR_FORMATS:
        raise MeshError(
            f"cannot write scalars to {ext or 'a file without extension'!r}; use one of "
            f"{', '.join(SCALAR_FORMATS)}",
            os.fspath(path),
        )
    vals = np.asarray(values, dtype=np.float64)
    if vals.ndim != 1:
        raise MeshError(f"should be a 1-D array; shape is {vals.shape}", "values")
    if ext == ".ply":
        if V is None or F is None:
            raise MeshError("writing scalars to .ply needs the mesh (V and F)", os.fspath(path))
        save_mesh(path, V, F, scalars=vals, overwrite_inputs=overwrite_inputs)
        return
    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        if ext == ".npy":
            np.save(f, vals, allow_pickle=False)
        else:
            f.write(b"value\n")
            np.savetxt(f, vals, fmt="%.17g")
