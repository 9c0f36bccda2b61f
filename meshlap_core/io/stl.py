"""STL reader (binary and ASCII): corners welded into shared vertices."""

from __future__ import annotations

import re

import numpy as np

from ..errors import MeshError
from ..types import FloatArray
from ._scan import (
    TEXT_BYTES,
    Parsed,
    bulk_numbers,
    check_text,
    has_bare_cr,
    shown,
    to_float,
    tokens_per_line,
)

_STL_DTYPE = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])


def parse_stl(data: bytes, src: str) -> Parsed:
    """The STL file ``data`` (binary when its size says so, else ASCII; named ``src`` in errors)."""
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
    return Parsed(V=V, faces=F, vertex_map=first.astype(np.int64), repairs=repairs)


def _has_control_bytes(data: bytes) -> bool:
    return bool(data.translate(None, TEXT_BYTES))


def _stl_ascii_corners(data: bytes, src: str) -> FloatArray:
    arr = np.frombuffer(data, dtype=np.uint8)
    check_text(arr, src, "STL")
    lower = data.lower()
    if has_bare_cr(lower):  # a bare CR ends a line too
        lower = lower.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
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
    ntok = tokens_per_line(np.frombuffer(text, dtype=np.uint8))
    vals = bulk_numbers(text, np.float64) if np.all(ntok == 3) else None
    if vals is not None and vals.size == 3 * len(verts):
        return vals.reshape(-1, 3)
    out = np.empty((len(verts), 3))  # per line: nan/inf, or the first line that is no number
    for i, m in enumerate(verts):
        parts = m.group(1).split()
        try:
            if len(parts) != 3:
                raise ValueError
            out[i] = [to_float(t) for t in parts]
        except ValueError:
            raise MeshError(
                f"ASCII STL: cannot read the coordinates of vertex line {i} of facet "
                f"{i // 3} ({shown(m.group(1), 40)!r})",
                src,
            ) from None
    return out
