"""PLY reader: header, binary bodies (both byte orders) and ASCII bodies."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import MeshError
from ..validate import Polygons
from ._scan import (
    HUGE_INDEX,
    Parsed,
    bulk_numbers,
    check_text,
    shown,
    split_lines,
    to_float,
    to_int,
    tokens_per_line,
)

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
    if not (data.startswith(b"ply\n") or data.startswith(b"ply\r")):
        raise MeshError("not a PLY file: it does not start with 'ply'", src)
    m = re.search(rb"end_header[ \t]*(?:\r\n|\r|\n)", data)  # the contract's line ends
    if m is None:
        raise MeshError("the PLY header has no 'end_header' line (truncated or not PLY)", src)
    fmt = None
    elements: list[_PlyElement] = []
    for ln, raw in enumerate(split_lines(data[: m.start()]), 1):
        line = raw.decode("latin-1")
        parts = [t.decode("latin-1") for t in raw.split()]
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
                elements.append(_PlyElement(parts[1], to_int(parts[2].encode("latin-1"))))
            except (IndexError, ValueError):
                raise MeshError(
                    f"PLY header line {ln}: bad element line {line.strip()!r}", src
                ) from None
            _check_element(elements, len(data) - m.end(), ln, src)
        elif parts[0] == "property":
            if not elements:
                raise MeshError(f"PLY header line {ln}: property before any element", src)
            try:
                if parts[1] == "list":
                    prop = _PlyProp(parts[4], _PLY_TYPES[parts[3]], _PLY_TYPES[parts[2]])
                else:
                    prop = _PlyProp(parts[2], _PLY_TYPES[parts[1]])
            except (IndexError, KeyError):
                raise MeshError(
                    f"PLY header line {ln}: bad property line {line.strip()!r}", src
                ) from None
            _check_property(elements[-1], prop, ln, src)
            elements[-1].props.append(prop)
        else:
            raise MeshError(f"PLY header line {ln}: unknown keyword {parts[0]!r}", src)
    if fmt is None:
        raise MeshError("the PLY header has no 'format' line", src)
    return fmt, elements, m.end()


def _check_element(elements: list[_PlyElement], body_bytes: int, ln: int, src: str) -> None:
    """The element just declared: a new name, a count the body could hold."""
    el = elements[-1]
    if el.count < 0:
        raise MeshError(f"PLY header line {ln}: negative element count", src)
    if any(e.name == el.name for e in elements[:-1]):
        raise MeshError(f"PLY header line {ln}: a second {el.name!r} element", src)
    if el.count > body_bytes:  # every record takes at least one byte
        raise MeshError(
            f"truncated PLY file (or a wrong count): header line {ln} declares {el.count:,} "
            f"{el.name} records but only {body_bytes:,} bytes follow the header",
            src,
        )


def _check_property(el: _PlyElement, prop: _PlyProp, ln: int, src: str) -> None:
    """A property about to be added to ``el``: a new name, an integer list count type."""
    if any(p.name == prop.name for p in el.props):
        raise MeshError(
            f"PLY header line {ln}: the {el.name} element declares the property "
            f"{prop.name!r} twice",
            src,
        )
    if prop.count_dtype is not None and prop.count_dtype[0] == "f":
        raise MeshError(
            f"PLY header line {ln}: the list property {prop.name!r} has a floating-point "
            "count type; a list count must be an integer type (uchar, ushort, uint, ...)",
            src,
        )


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


def parse_ply(data: bytes, src: str) -> Parsed:
    """The PLY file ``data`` (ASCII or binary; named ``src`` in errors)."""
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
    return Parsed(V=V, faces=faces, vertex_props=props)


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
            # positional field names: a property's name never meets numpy's field namespace
            dt = np.dtype([(f"p{i}", bo + p.dtype) for i, p in enumerate(el.props)])
            need = dt.itemsize * el.count
            if pos + need > total:
                raise MeshError(_truncated_msg(elements, el, total - pos, need), src)
            rec = np.frombuffer(data, dtype=dt, count=el.count, offset=pos)
            out[el.name] = {p.name: rec[f"p{i}"] for i, p in enumerate(el.props)}
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
    fields = []  # positional names: n<i> holds the count of list property i, p<i> its values
    li = 0
    for i, p in enumerate(el.props):
        if p.count_dtype is None:
            fields.append((f"p{i}", bo + p.dtype))
        else:
            fields.append((f"n{i}", bo + p.count_dtype))
            fields.append((f"p{i}", bo + p.dtype, (lens[li],)))
            li += 1
    dt = np.dtype(fields)
    need = dt.itemsize * el.count
    if pos + need <= total:
        rec = np.frombuffer(data, dtype=dt, count=el.count, offset=pos)
        li = 0
        uniform = True
        for i, p in enumerate(el.props):
            if p.count_dtype is not None:
                uniform &= bool(np.all(rec[f"n{i}"] == lens[li]))
                li += 1
        if uniform:
            out: dict[str, Any] = {}
            li = 0
            for i, p in enumerate(el.props):
                if p.count_dtype is None:
                    out[p.name] = rec[f"p{i}"]
                else:
                    out[p.name] = (
                        rec[f"p{i}"].reshape(-1),
                        np.full(el.count, lens[li], dtype=np.int64),
                    )
                    li += 1
            return out, pos + need
    return _ply_binary_records(data, pos, el, bo, elements, src)


def _ply_binary_records(
    data: bytes, pos: int, el: _PlyElement, bo: str, elements: list[_PlyElement], src: str
) -> tuple[dict[str, Any], int]:
    """Binary list element with variable list lengths: one record at a time."""
    total = len(data)
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
    check_text(body, src, "PLY", pos)
    fast = _ply_ascii_fast(body, elements)
    if fast is not None:
        return fast
    tokens = body.tobytes().split()
    k = 0
    out: dict[str, dict[str, Any]] = {}
    for el in elements:
        out[el.name], k = _ply_ascii_element(tokens, k, el, elements, src)
    if k < len(tokens):
        raise MeshError(
            f"PLY header counts do not match the data: after the {_describe_counts(elements)} "
            f"it declares, {len(tokens) - k:,} more values follow",
            src,
        )
    return out


def _ply_ascii_element(
    tokens: list[bytes], k: int, el: _PlyElement, elements: list[_PlyElement], src: str
) -> tuple[dict[str, Any], int]:
    """The records of ``el`` from ``tokens[k:]``; returns its values and the next token."""
    scal: dict[str, list[float]] = {p.name: [] for p in el.props if p.count_dtype is None}
    lists: dict[str, tuple[list[float], list[int]]] = {
        p.name: ([], []) for p in el.props if p.count_dtype is not None
    }
    for r in range(el.count if el.props else 0):  # an element without properties has no data
        for p in el.props:
            if k >= len(tokens):
                raise MeshError(_truncated_at(elements, el, r), src)
            where = f"({el.name} record {r}, property {p.name!r})"
            if p.count_dtype is None:
                scal[p.name].append(_ascii_number(tokens[k], to_float, "a number", where, src))
                k += 1
                continue
            c = _ascii_number(tokens[k], to_int, "an integer list count", where, src)
            if c < 0:
                raise MeshError(f"{el.name} record {r} has a list of negative length {c}", src)
            items = tokens[k + 1 : k + 1 + c]
            if len(items) < c:
                raise MeshError(
                    f"{_truncated_at(elements, el, r)} ({el.name} record {r} declares a list "
                    f"of {c:,} values, {len(items):,} follow)",
                    src,
                )
            lists[p.name][0].extend(
                _ascii_number(t, to_float, "a number", where, src) for t in items
            )
            lists[p.name][1].append(c)
            k += 1 + c
    vals_out: dict[str, Any] = {kk: np.asarray(v, dtype=np.float64) for kk, v in scal.items()}
    for kk, (vs, cs) in lists.items():
        arr = np.asarray(vs, dtype=np.float64)
        if arr.size and np.all(np.mod(arr, 1) == 0):
            if np.abs(arr).max() >= HUGE_INDEX:
                raise MeshError(
                    f"the {el.name} property {kk!r} has the value {np.abs(arr).max():.6g}, "
                    "far beyond any vertex count",
                    src,
                )
            arr = arr.astype(np.int64)
        vals_out[kk] = (arr, np.asarray(cs, dtype=np.int64))
    return vals_out, k


def _ascii_number(tok: bytes, conv: Any, what: str, where: str, src: str) -> Any:
    try:
        return conv(tok)
    except ValueError:
        raise MeshError(f"cannot read {shown(tok, 30)!r} as {what} {where}", src) from None


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
    ntok = tokens_per_line(body)
    ntok = ntok[ntok > 0]
    if len(ntok) != nv + nf or not np.all(ntok[:nv] == k) or not np.all(ntok[nv:] == 4):
        return None
    vals = bulk_numbers(body.tobytes(), np.float64)
    if vals is None or vals.size != k * nv + 4 * nf:
        return None
    vv = vals[: k * nv].reshape(nv, k)
    ff = vals[k * nv :].reshape(nf, 4)
    if (
        not np.all(ff[:, 0] == 3)
        or not np.all(np.mod(ff[:, 1:], 1) == 0)
        or (nf and np.abs(ff[:, 1:]).max() >= HUGE_INDEX)
    ):
        return None
    return {
        "vertex": {p.name: vv[:, i] for i, p in enumerate(vert.props)},
        "face": {
            face.props[0].name: (ff[:, 1:].astype(np.int64).ravel(), np.full(nf, 3, dtype=np.int64))
        },
    }
