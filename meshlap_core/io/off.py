"""OFF reader (ASCII; the ``OFF``/``COFF``/``NOFF``/... keywords): bulk path for triangle
files with one record per line, per-line general path for the rest."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import MeshError
from ..validate import Polygons
from ._scan import (
    HUGE_INDEX,
    Parsed,
    bulk_numbers,
    check_text,
    line_table,
    strip_comment,
    tokens_per_line,
)


def _parse_off(data: bytes, src: str) -> Parsed:
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    arr = np.frombuffer(data, dtype=np.uint8)
    starts, ends = line_table(arr)
    # header: keyword line, then counts (possibly on the same line); comments / blanks allowed
    li = 0
    tokens: list[str] = []
    keyword = None
    while li < len(starts):
        parts = strip_comment(data[starts[li] : ends[li]].decode("latin-1")).split()
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
    check_text(body, src, "OFF", body_start)

    if keyword == "OFF" and b"#" not in data[body_start:]:
        ntok = tokens_per_line(body)
        ntok = ntok[ntok > 0]
        if len(ntok) == nv + nf and np.all(ntok[:nv] == 3) and np.all(ntok[nv:] == 4):
            vals = bulk_numbers(body.tobytes(), np.float64)
            if vals is not None and vals.size == 3 * nv + 4 * nf:
                fv = vals[3 * nv :].reshape(nf, 4)
                if (
                    np.all(fv[:, 0] == 3)
                    and np.all(np.mod(fv[:, 1:], 1) == 0)
                    and np.abs(fv[:, 1:]).max() < HUGE_INDEX
                ):
                    return Parsed(V=vals[: 3 * nv].reshape(nv, 3), faces=fv[:, 1:].astype(np.int64))
    return _parse_off_general(data[body_start:], nv, nf, src)


def _parse_off_general(body: bytes, nv: int, nf: int, src: str) -> Parsed:
    lines = [
        parts
        for parts in (strip_comment(x).split() for x in body.decode("latin-1").splitlines())
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
        big = [i for i in idx if abs(i) >= HUGE_INDEX]
        if big:
            raise MeshError(f"face {k} has index {big[0]} (far beyond any vertex count)", src)
        flat.extend(idx)
        sizes.append(c)
    vals = np.asarray(flat, dtype=np.int64)
    size_arr = np.asarray(sizes, dtype=np.int64)
    faces: Any = vals.reshape(-1, 3) if np.all(size_arr == 3) else Polygons(vals, size_arr)
    return Parsed(V=V, faces=faces)
