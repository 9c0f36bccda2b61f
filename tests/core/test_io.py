"""Tests of meshlap_core.io: parsers (OBJ/OFF/PLY/STL), writers, atomic writes, bad files.

Bad files are written by hand into ``tmp_path``; binary PLY/STL inputs are produced here with
numpy/struct (independently of the module's own writer). libigl's readers serve as the
reference on well-formed files.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import igl
import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.errors import MeshError
from meshlap_core.io import (
    atomic_write,
    load_mesh,
    load_vertex_scalars,
    save_mesh,
    save_scalars,
)
from meshlap_core.validate import duplicate_faces

SQUARE_OBJ = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n"
SQUARE_V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


def write(path: Path, text: str | bytes) -> Path:
    path.write_bytes(text.encode() if isinstance(text, str) else text)
    return path


def binary_ply(V, F, *, endian="<", coord="f4", index="i4", count="u1", extra=b"") -> bytes:
    """A binary PLY written by hand (variable-length face lists allowed)."""
    fmt = "binary_little_endian" if endian == "<" else "binary_big_endian"
    names = {
        "f4": "float",
        "f8": "double",
        "i4": "int",
        "u4": "uint",
        "u1": "uchar",
        "u2": "ushort",
    }
    head = (
        f"ply\nformat {fmt} 1.0\ncomment hand-made\nelement vertex {len(V)}\n"
        f"property {names[coord]} x\nproperty {names[coord]} y\nproperty {names[coord]} z\n"
        f"property uchar red\n"
        f"element face {len(F)}\nproperty list {names[count]} {names[index]} vertex_indices\n"
        "end_header\n"
    ).encode()
    vrec = np.zeros(len(V), dtype=[("p", endian + coord, (3,)), ("r", "u1")])
    vrec["p"] = V
    vrec["r"] = 200
    body = vrec.tobytes()
    for f in F:
        body += np.array([len(f)], dtype=endian + count).tobytes()
        body += np.asarray(f, dtype=endian + index).tobytes()
    return head + body + extra


def binary_stl(V, F, header=b"hand-made binary stl") -> bytes:
    out = header.ljust(80, b" ") + struct.pack("<I", len(F))
    for f in F:
        out += struct.pack("<3f", 0.0, 0.0, 0.0)
        for i in f:
            out += struct.pack("<3f", *V[i])
        out += b"\0\0"
    return out


def ascii_stl(V, F) -> str:
    lines = ["solid hand"]
    for f in F:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += ["      vertex " + " ".join(repr(float(x)) for x in V[i]) for i in f]
        lines += ["    endloop", "  endfacet"]
    return "\n".join([*lines, "endsolid hand", ""])


def same_triangles(A: np.ndarray, FA: np.ndarray, B: np.ndarray, FB: np.ndarray) -> bool:
    """Same set of triangles as point triples (vertex numbering may differ)."""

    def key(V, F):
        return sorted(tuple(map(tuple, V[f].round(6).tolist())) for f in F)

    return key(A, FA) == key(B, FB)


# ---------------------------------------------------------------------------- OBJ


def test_obj_plain_matches_hand_values(tmp_path):
    mesh = load_mesh(write(tmp_path / "sq.obj", SQUARE_OBJ))
    assert np.array_equal(mesh.V, SQUARE_V) and np.array_equal(mesh.F, SQUARE_F)
    assert mesh.source == str(tmp_path / "sq.obj")
    assert mesh.report.repairs == [] and mesh.vertex_map.tolist() == [0, 1, 2, 3]


def test_obj_crlf_vn_vt_slashes(tmp_path):
    text = (
        "# comment\r\nmtllib x.mtl\r\nv 0 0 0\r\nvn 0 0 1\r\nvt 0 0\r\nv 1 0 0\r\nvn 0 0 1\r\n"
        "v 1 1 0\r\nvt 1 1\r\nv 0 1 0\r\ng grp\r\nusemtl m\r\ns off\r\n"
        "f 1/1/1 2/2/1 3/1/2\r\nf 1//1 3//2 4//2\r\n"
    )
    mesh = load_mesh(write(tmp_path / "crlf.OBJ", text))  # extension case-insensitive
    assert np.array_equal(mesh.V, SQUARE_V) and np.array_equal(mesh.F, SQUARE_F)


def test_obj_slash_forms_and_negative_indices(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1/4 2/5 3/6\nv 0 1 0\nf -4/1/1 -2/2/2 -1//3\n"
    mesh = load_mesh(write(tmp_path / "neg.obj", text))
    assert np.array_equal(mesh.V, SQUARE_V) and np.array_equal(mesh.F, SQUARE_F)
    plain = load_mesh(
        write(
            tmp_path / "neg_plain.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nv 0 1 0\nf -4 -2 -1\n"
        )
    )
    assert np.array_equal(plain.F, SQUARE_F)


def test_obj_fast_and_general_paths_agree(tmp_path):
    V, F = primitives.torus_mesh(10, 7)
    body = "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())
    faces = "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F.tolist())
    fast = load_mesh(write(tmp_path / "fast.obj", body + faces))
    # an indented line and a comment after a face force the line-by-line parser
    slow = load_mesh(write(tmp_path / "slow.obj", " " + body + faces[:-1] + " # last face\n"))
    assert np.array_equal(fast.V, V) and np.array_equal(fast.F, F)
    assert np.array_equal(slow.V, V) and np.array_equal(slow.F, F)
    assert fast.report.repairs == slow.report.repairs == []


def test_obj_polygons_triangulated_and_reported(tmp_path):
    text = (
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 3 0.5 0\nf 1 2 3 4\nf 2 5 7 6 3\n"
    )
    mesh = load_mesh(write(tmp_path / "poly.obj", text))
    assert mesh.F.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 6], [1, 6, 5], [1, 5, 2]]
    assert mesh.face_map.tolist() == [0, 0, 1, 1, 1]
    assert mesh.report.repairs == [
        "triangulated 2 polygons with more than 3 corners into 5 triangles (fan triangulation)"
    ]
    # same result from the slow path (slashes)
    slow = load_mesh(write(tmp_path / "poly2.obj", text.replace("f 1 2 3 4", "f 1/1 2/1 3/1 4/1")))
    assert np.array_equal(slow.F, mesh.F)


def test_obj_vertex_colours_and_w_ignored(tmp_path):
    text = "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1.0\nf 1 2 3\nf 1 3 4\n"
    mesh = load_mesh(write(tmp_path / "col.obj", text))
    assert np.array_equal(mesh.V, SQUARE_V)


def test_obj_line_elements_ignored_with_warning(tmp_path):
    mesh = load_mesh(write(tmp_path / "l.obj", SQUARE_OBJ + "l 1 2\nl 2 3\n"))
    assert "ignored 2 line elements ('l' lines)" in mesh.report.warnings


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        (SQUARE_OBJ + "f 1 2 9\n", "line 7: face 2 refers to vertex 9 but the file has 4 vertices"),
        (SQUARE_OBJ + "f 0 1 2\n", "line 7: face 2 refers to vertex 0 but OBJ indices start at 1"),
        (SQUARE_OBJ + "f 1 2\n", "line 7: face 2 has 2 corners; a face needs at least 3"),
        (SQUARE_OBJ + "f 1/1 2/2\n", "line 7: face 2 has 2 corners"),
        (SQUARE_OBJ + "f 1 -7 2\n", "line 7: face 2 has relative index -7 but only 4 vertices"),
        (SQUARE_OBJ + "f 1 -7/1 2\n", "relative index -7 but only 4 vertices precede it"),
        (SQUARE_OBJ + "f 1 x 2\n", "line 7: cannot read 'x' as a vertex index"),
        ("v 0 0\n" + SQUARE_OBJ, "line 1: a vertex needs 3 coordinates, found 2"),
        ("v 0 0 zero\n" + SQUARE_OBJ, "line 1: cannot read 'v 0 0 zero' as vertex coordinates"),
        ("f 1 2 3\n", "no vertices: the file has no 'v' lines"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces: the file has no 'f' lines"),
        ("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", "vertex 2 has a NaN or infinite coordinate"),
        ("v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n", "vertex 1 has coordinate 1e+300"),
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "all 1 face are degenerate"),
        (b"v 0 0 0\n\x00\x01\x02\xff\xfe" * 20, "binary data in a text OBJ file"),
    ],
)
def test_obj_bad_files(tmp_path, text, needle):
    path = write(tmp_path / "bad.obj", text)
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    msg = str(info.value)
    assert msg.startswith(f"{path}: ")
    assert needle in msg


# ---------------------------------------------------------------------------- file-level errors


def test_missing_directory_unknown_empty(tmp_path):
    with pytest.raises(MeshError, match=r"nope\.obj: no such file"):
        load_mesh(tmp_path / "nope.obj")
    with pytest.raises(MeshError, match="is a directory, not a mesh file"):
        load_mesh(tmp_path)
    with pytest.raises(MeshError, match=r"m\.xyz: unknown mesh format '\.xyz'; supported formats"):
        load_mesh(write(tmp_path / "m.xyz", SQUARE_OBJ))
    with pytest.raises(MeshError, match="no extension"):
        load_mesh(write(tmp_path / "mesh", SQUARE_OBJ))
    with pytest.raises(MeshError, match=r"empty\.ply: the file is empty"):
        load_mesh(write(tmp_path / "empty.ply", b""))
    with pytest.raises(MeshError, match="contains only whitespace"):
        load_mesh(write(tmp_path / "blank.obj", "\n\r\n  \n"))


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs a non-root POSIX user")
def test_unreadable_file(tmp_path):
    path = write(tmp_path / "locked.obj", SQUARE_OBJ)
    path.chmod(0)
    try:
        with pytest.raises(MeshError, match=r"locked\.obj: cannot read the file: permission"):
            load_mesh(path)
    finally:
        path.chmod(0o644)


def test_obj_interleaved_blocks_and_no_final_newline(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\no second\nv 0 1 0\nf 1 3 4"
    mesh = load_mesh(write(tmp_path / "inter.obj", text))
    assert np.array_equal(mesh.V, SQUARE_V) and np.array_equal(mesh.F, SQUARE_F)
    with pytest.raises(MeshError, match="line 2: a vertex needs 3 coordinates, found 0"):
        load_mesh(write(tmp_path / "lone.obj", SQUARE_OBJ.replace("v 1 0 0", "v")))


def test_unreadable_file_simulated(tmp_path, monkeypatch):
    path = write(tmp_path / "locked.obj", SQUARE_OBJ)

    real_open = os.open

    def deny(p, flags, *args):  # the reader opens the file with os.open (non-blocking)
        if os.fspath(p) == str(path):
            raise PermissionError(13, "Permission denied", str(p))
        return real_open(p, flags, *args)

    monkeypatch.setattr(os, "open", deny)
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    assert str(info.value) == f"{path}: cannot read the file: permission denied"


# ---------------------------------------------------------------------------- OFF


def test_off_comments_and_polygons(tmp_path):
    text = (
        "OFF\n# a comment\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0.5 0\n"
        "4 0 1 2 3\n3 1 4 2  255 0 0\n"
    )
    mesh = load_mesh(write(tmp_path / "p.off", text))
    assert mesh.F.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 2]]
    assert "triangulated 1 polygon" in mesh.report.repairs[0]


def test_off_counts_on_header_line_and_coff(tmp_path):
    mesh = load_mesh(
        write(tmp_path / "a.off", "OFF 4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
    )
    assert np.array_equal(mesh.V, SQUARE_V) and np.array_equal(mesh.F, SQUARE_F)
    mesh = load_mesh(
        write(
            tmp_path / "c.off",
            "COFF\n4 2 0\n0 0 0 255 0 0 255\n"
            "1 0 0 0 255 0 255\n1 1 0 0 0 0 255\n"
            "0 1 0 9 9 9 255\n3 0 1 2\n3 0 2 3\n",
        )
    )
    assert np.array_equal(mesh.V, SQUARE_V) and np.array_equal(mesh.F, SQUARE_F)


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        (
            "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n",
            "truncated OFF file: the header declares 4 vertices and 2 faces, but the file has only "
            "4 vertex lines and 1 face lines",
        ),
        (
            "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
            "declares 5 vertices and 2 faces, but the file has only 5 vertex lines and 1 face",
        ),
        (
            "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
            "OFF header counts do not match the data: it declares 4 vertices and 1 faces, but "
            "1 more non-empty lines follow the last face",
        ),
        (
            "OFF\n4 2\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 7\n",
            "face 1 has index 7 but the mesh has 4 vertices",
        ),
        (
            "OFF\n4 2\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n2 0 2\n",
            "face 1 has 2 corners; a face needs at least 3",
        ),
        (
            "OFF\n4 2\n0 0 0\n1 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
            "vertex 1 has 2 coordinates; it needs 3",
        ),
        ("PLY\n4 2\n", "not an OFF file: the first line should be 'OFF', found 'PLY'"),
        ("OFF\n", "truncated OFF header"),
        ("OFF\nfour two\n", "OFF header counts should be integers"),
        ("OFF\n0 0 0\n", "declares 0 vertices"),
        ("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "declares 0 faces"),
        (b"OFF\n3 1 0\n0 0 0\n1 0 0\n\x00\x07\x08\x00\n3 0 1 2\n", "binary data in a text OFF"),
    ],
)
def test_off_bad_files(tmp_path, text, needle):
    path = write(tmp_path / "bad.off", text)
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    assert str(info.value).startswith(f"{path}: ")
    assert needle in str(info.value)


# ---------------------------------------------------------------------------- PLY


@pytest.mark.parametrize("endian", ["<", ">"])
def test_binary_ply_hand_made(tmp_path, endian):
    V, F = primitives.icosphere(1)
    data = binary_ply(V, F, endian=endian, coord="f4")
    mesh = load_mesh(write(tmp_path / "b.ply", data))
    assert np.array_equal(mesh.F, F)
    assert np.array_equal(mesh.V, V.astype(np.float32).astype(np.float64))
    ref_V, ref_F = igl.read_triangle_mesh(str(tmp_path / "b.ply"))
    assert np.allclose(mesh.V, ref_V) and np.array_equal(mesh.F, ref_F)


def test_binary_ply_mixed_polygons_and_uint_indices(tmp_path):
    V = np.vstack([SQUARE_V, [[2, 0.5, 0]]])
    F = [[0, 1, 2, 3], [1, 4, 2]]
    mesh = load_mesh(
        write(tmp_path / "q.ply", binary_ply(V, F, coord="f8", index="u4", count="u1"))
    )
    assert mesh.F.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 2]]
    assert np.array_equal(mesh.V, V)


def test_ascii_ply_general_path_extra_element(tmp_path):
    text = (
        "ply\r\nformat ascii 1.0\r\ncomment x\r\nelement vertex 4\r\nproperty float x\r\n"
        "property float y\r\nproperty float z\r\nproperty float quality\r\nelement face 2\r\n"
        "property list uchar int vertex_indices\r\nproperty uchar red\r\nelement edge 1\r\n"
        "property int vertex1\r\nproperty int vertex2\r\nend_header\r\n"
        "0 0 0 0.5\r\n1 0 0 1.5\r\n1 1 0 2.5\r\n0 1 0 3.5\r\n3 0 1 2 255\r\n3 0 2 3 0\r\n0 1\r\n"
    )
    path = write(tmp_path / "a.ply", text)
    mesh = load_mesh(path)
    assert np.array_equal(mesh.V, SQUARE_V) and np.array_equal(mesh.F, SQUARE_F)
    assert load_vertex_scalars(path).tolist() == [0.5, 1.5, 2.5, 3.5]
    with pytest.raises(MeshError, match="no property 'curv'"):
        load_vertex_scalars(path, "curv")


PLY_HEAD = (
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
    "end_header\n"
)
PLY_BODY = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"


@pytest.mark.parametrize(
    ("data", "needle"),
    [
        (
            PLY_HEAD + PLY_BODY[:-8],
            "truncated PLY file: the header declares 4 vertices and "
            "2 faces, but the data ends after 1 of the 2 face records",
        ),
        (
            PLY_HEAD + PLY_BODY + "3 1 2 3\n",
            "PLY header counts do not match the data: after the "
            "4 vertices and 2 faces it declares, 4 more values",
        ),
        (PLY_HEAD.replace("end_header\n", ""), "no 'end_header' line"),
        ("plx\n" + PLY_HEAD[4:] + PLY_BODY, "not a PLY file"),
        (PLY_HEAD.replace("ascii", "binary_middle_endian") + PLY_BODY, "unknown format"),
        (PLY_HEAD.replace("float z", "float w") + PLY_BODY, "vertex element has no 'z'"),
        (
            PLY_HEAD.replace("element face 2", "element face 0") + PLY_BODY[:24],
            "no faces (a point cloud is not a mesh)",
        ),
        (PLY_HEAD.replace("float x", "quaternion x") + PLY_BODY, "bad property line"),
        (
            PLY_HEAD + PLY_BODY.replace("3 0 2 3", "3 0 2 4"),
            "face 1 has index 4 but the mesh has 4 vertices",
        ),
        (
            PLY_HEAD + PLY_BODY.replace("1 1 0", "1 1 abc"),
            "cannot read 'abc' as a number (vertex record 2, property 'z')",
        ),
        (PLY_HEAD + PLY_BODY.replace("1 1 0", "1 1 nan"), "vertex 2 has a NaN"),
    ],
)
def test_ascii_ply_bad_files(tmp_path, data, needle):
    path = write(tmp_path / "bad.ply", data)
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    assert str(info.value).startswith(f"{path}: ")
    assert needle in str(info.value)


def test_binary_ply_truncated_and_lying(tmp_path):
    V, F = primitives.icosphere(0)
    good = binary_ply(V, F)  # face records are 1 + 3*4 = 13 bytes: cutting 40 leaves 16 whole
    with pytest.raises(
        MeshError,
        match=r"truncated PLY file: the header declares 12 vertices "
        r"and 20 faces, but the data ends after 16 of the 20 face",
    ):
        load_mesh(write(tmp_path / "t.ply", good[:-40]))
    with pytest.raises(MeshError, match=r"truncated PLY file.*ends inside the vertex element"):
        load_mesh(write(tmp_path / "t2.ply", good[: good.index(b"end_header") + 50]))
    with pytest.raises(
        MeshError,
        match=r"after the 12 vertices and 20 faces it declares, "
        r"7 more bytes follow",
    ):
        load_mesh(write(tmp_path / "l.ply", binary_ply(V, F, extra=b"garbage")))
    ok = load_mesh(write(tmp_path / "nl.ply", binary_ply(V, F, extra=b"\n")))  # lenient
    assert np.array_equal(ok.F, F)


# ---------------------------------------------------------------------------- STL


def test_binary_stl_welded_and_reported(tmp_path):
    V, F = primitives.cube()
    mesh = load_mesh(write(tmp_path / "cube.stl", binary_stl(V, F)))
    assert mesh.n_vertices == 8 and mesh.n_faces == 12
    assert mesh.report.repairs == [
        "welded the 36 triangle corners of this binary STL into 8 vertices "
        "(identical coordinates merged)"
    ]
    assert same_triangles(mesh.V, mesh.F, V, F)
    assert mesh.report.is_closed and mesh.report.consistently_oriented
    # vertex_map points at a triangle corner with that position
    corners = V[F].reshape(-1, 3)
    assert np.array_equal(corners[mesh.vertex_map], mesh.V)


def test_binary_stl_whose_header_starts_with_solid(tmp_path):
    V, F = primitives.cube()
    mesh = load_mesh(write(tmp_path / "s.stl", binary_stl(V, F, header=b"solid lies")))
    assert mesh.n_vertices == 8 and same_triangles(mesh.V, mesh.F, V, F)


def test_ascii_stl(tmp_path):
    V, F = primitives.icosphere(1)
    mesh = load_mesh(write(tmp_path / "a.stl", ascii_stl(V, F).replace("\n", "\r\n")))
    assert mesh.n_vertices == len(V) and mesh.n_faces == len(F)
    assert same_triangles(mesh.V, mesh.F, V, F)
    assert "ASCII STL" in mesh.report.repairs[0]


@pytest.mark.parametrize(
    ("data", "needle"),
    [
        (
            lambda: binary_stl(*primitives.cube())[:-30],
            "truncated or corrupt binary STL: the header declares 12 triangles (84 + 50·12 = 684 "
            "bytes) but the file has 654 bytes",
        ),
        (lambda: b"\x01" * 40, "too short for binary STL (40 bytes"),
        (
            lambda: ascii_stl(*primitives.cube()).rsplit("vertex", 1)[0],
            "ASCII STL facet 11 has 2 vertices; STL facets are triangles (truncated file?)",
        ),
        (lambda: "solid x\nendsolid x\n", "no 'facet'"),
        (
            lambda: ascii_stl(SQUARE_V, SQUARE_F).replace("vertex 1.0 1.0 0.0", "vertex 1.0 1.0"),
            "cannot read the coordinates of vertex line 2 of facet 0",
        ),
        (
            lambda: binary_stl(np.array([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]]), [[0, 1, 2]]),
            "triangle 0 has a NaN or infinite coordinate at corner 2",
        ),
        (lambda: binary_stl(SQUARE_V, np.zeros((0, 3), int)), "0 triangles"),
    ],
)
def test_stl_bad_files(tmp_path, data, needle):
    path = write(tmp_path / "bad.stl", data())
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    assert str(info.value).startswith(f"{path}: ")
    assert needle in str(info.value)


# ---------------------------------------------------------------------------- round trips


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply", ".OBJ"])
@pytest.mark.parametrize("prim", ["torus", "bumpy", "grid"])
def test_round_trip_exact(tmp_path, ext, prim):
    V, F = {
        "torus": primitives.torus_mesh(9, 5),
        "bumpy": primitives.bumpy_sphere(2),
        "grid": primitives.grid(5, 4),
    }[prim]
    path = tmp_path / f"m{ext}"
    save_mesh(path, V, F)
    mesh = load_mesh(path)
    assert np.array_equal(mesh.V, V) and np.array_equal(mesh.F, F)
    assert mesh.report.repairs == []
    if ext.lower() != ".ply":  # libigl reads what we write (its PLY reader wants float)
        ref_V, ref_F = igl.read_triangle_mesh(str(path))
        assert np.array_equal(ref_V, V) and np.array_equal(ref_F, F)


def test_ascii_ply_round_trip_with_quality(tmp_path):
    V, F = primitives.icosphere(1)
    q = np.linspace(-1, 1, len(V)) ** 3
    for binary in (True, False):
        path = tmp_path / f"q{int(binary)}.ply"
        save_mesh(path, V, F, scalars=q, binary=binary)
        mesh = load_mesh(path)
        assert np.array_equal(mesh.V, V) and np.array_equal(mesh.F, F)
        assert np.array_equal(load_vertex_scalars(path), q)
        head = path.read_bytes()[:400]
        assert b"property double quality" in head
        assert (b"binary_little_endian" in head) == binary


def test_save_scalars_formats(tmp_path):
    vals = np.array([0.1, -2.5e-17, 3.0, 1e300])
    save_scalars(tmp_path / "s.csv", vals)
    lines = (tmp_path / "s.csv").read_text().splitlines()
    assert lines[0] == "value" and [float(x) for x in lines[1:]] == vals.tolist()
    save_scalars(tmp_path / "s.npy", vals)
    assert np.array_equal(np.load(tmp_path / "s.npy"), vals)
    V, F = primitives.icosphere(0)
    k = np.arange(len(V), dtype=float)
    save_scalars(tmp_path / "s.ply", k, V=V, F=F)
    assert np.array_equal(load_vertex_scalars(tmp_path / "s.ply"), k)
    with pytest.raises(MeshError, match="needs the mesh"):
        save_scalars(tmp_path / "t.ply", k)
    with pytest.raises(MeshError, match=r"cannot write scalars to '\.txt'"):
        save_scalars(tmp_path / "t.txt", k)
    with pytest.raises(MeshError, match="1-D"):
        save_scalars(tmp_path / "t.csv", np.ones((3, 2)))


def test_save_mesh_errors(tmp_path):
    V, F = primitives.icosphere(0)
    with pytest.raises(MeshError, match=r"cannot write '\.stl' files"):
        save_mesh(tmp_path / "m.stl", V, F)
    missing = tmp_path / "no" / "such"
    with pytest.raises(MeshError) as info:
        save_mesh(missing / "m.obj", V, F)
    assert str(info.value) == f"{missing}: the output directory does not exist"
    with pytest.raises(MeshError, match=r"only \.ply files can carry per-vertex scalars"):
        save_mesh(tmp_path / "m.obj", V, F, scalars=np.zeros(len(V)))
    with pytest.raises(MeshError, match=r"scalars: has 3 values for 12 vertices"):
        save_mesh(tmp_path / "m.ply", V, F, scalars=np.zeros(3))
    with pytest.raises(MeshError, match="face 0 has index 99"):
        save_mesh(tmp_path / "m.obj", V, np.array([[0, 1, 99]]))
    (tmp_path / "d.obj").mkdir()
    with pytest.raises(MeshError, match=r"d\.obj: the output path is a directory"):
        save_mesh(tmp_path / "d.obj", V, F)
    with pytest.raises(MeshError, match="the output has no extension"):
        save_mesh(tmp_path / "mesh", V, F)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.obj"]  # nothing half-written


def test_save_refuses_to_overwrite_inputs(tmp_path, monkeypatch):
    V, F = primitives.icosphere(0)
    src = tmp_path / "in.obj"
    save_mesh(src, V, F)
    before = src.read_bytes()
    monkeypatch.chdir(tmp_path)
    for target in (src, Path("in.obj"), tmp_path / "sub" / ".." / "in.obj"):
        (tmp_path / "sub").mkdir(exist_ok=True)
        with pytest.raises(MeshError, match="refusing to overwrite an input file"):
            save_mesh(target, V, F, overwrite_inputs=[str(src)])
    link = tmp_path / "link.obj"
    link.symlink_to(src)
    with pytest.raises(MeshError, match="refusing to overwrite"):
        save_mesh(link, V, F, overwrite_inputs=[src])
    with pytest.raises(MeshError, match="refusing to overwrite"):
        save_scalars(tmp_path / "in.csv", [1.0], overwrite_inputs=[tmp_path / "in.csv"])
    assert src.read_bytes() == before


# ---------------------------------------------------------------------------- atomic_write


def test_atomic_write_failure_keeps_old_file(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old contents\n")
    with pytest.raises(RuntimeError, match="boom"), atomic_write(target) as f:
        f.write("new partial contents\n")
        raise RuntimeError("boom")
    assert target.read_text() == "old contents\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.csv"]  # temp file removed


def test_atomic_write_failure_in_writer_keeps_old_mesh(tmp_path, monkeypatch):
    V, F = primitives.icosphere(1)
    target = tmp_path / "m.ply"
    save_mesh(target, V, F)
    before = target.read_bytes()

    def broken(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("meshlap_core.io.write._write_ply", broken)
    with pytest.raises(MeshError, match=r"m\.ply: cannot write the file: no space left on device"):
        save_mesh(target, V * 2, F)
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["m.ply"]


def test_atomic_write_success_replaces_and_keeps_mode(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    target.chmod(0o640)
    with atomic_write(target) as f:
        f.write("new\n")
    assert target.read_text() == "new\n"
    assert (target.stat().st_mode & 0o777) == 0o640
    with atomic_write(tmp_path / "b.bin", "wb") as f:
        f.write(b"\x00\x01")
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
    with pytest.raises(MeshError, match="mode must be"):
        with atomic_write(tmp_path / "x", "a"):
            pass


# ---------------------------------------------------------------------------- real meshes


@pytest.mark.shared
def test_dragon_repair_counts(shared_mesh):
    """dragon.obj: counts computed independently with plain Python sets (README: 43
    unreferenced vertices, 1,489 extra duplicate faces in 1,405 groups, 2,534 non-manifold
    edges in the file as given, 16 non-manifold vertices, 7 components)."""
    path = shared_mesh("dragon.obj")
    nv = 0
    faces = []
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            nv += 1
        elif line.startswith("f "):
            faces.append(tuple(int(t) - 1 for t in line.split()[1:]))
    used = {i for f in faces for i in f}
    groups: dict[frozenset, int] = {}
    for f in faces:
        groups[frozenset(f)] = groups.get(frozenset(f), 0) + 1
    n_dup = sum(c - 1 for c in groups.values())
    assert nv - len(used) == 43
    assert n_dup == 1489 and sum(c > 1 for c in groups.values()) == 1405

    def nonmanifold_edges(face_list):
        count: dict[tuple[int, int], int] = {}
        for a, b, c in face_list:
            for e in ((a, b), (b, c), (c, a)):
                k = (min(e), max(e))
                count[k] = count.get(k, 0) + 1
        return sum(c > 2 for c in count.values())

    unique_faces = list({frozenset(f): f for f in reversed(faces)}.values())
    raw_nm, dedup_nm = nonmanifold_edges(faces), nonmanifold_edges(unique_faces)
    assert raw_nm == 2534

    mesh = load_mesh(path)
    r = mesh.report
    assert r.repairs == [
        "removed 1,489 duplicate faces (same three vertices as an earlier face, in any order)",
        "removed 43 unreferenced vertices",
    ]
    assert mesh.n_vertices == nv - 43 and mesh.n_faces == len(faces) - 1489
    assert r.n_nonmanifold_edges == dedup_nm  # duplicates removed, so fewer than 2,534
    assert any(w.startswith(f"{dedup_nm:,} non-manifold edges") for w in r.warnings)
    assert r.n_nonmanifold_vertices == int((~igl.is_vertex_manifold(mesh.F)).sum()) == 16
    assert r.n_components == 7
    assert not duplicate_faces(mesh.F, mesh.n_vertices).any()
    raw = load_mesh(path, repair=False)
    assert raw.report.n_nonmanifold_edges == 2534 and raw.n_faces == len(faces)
    assert raw.report.repairs == []


@pytest.mark.shared
@pytest.mark.parametrize("name", ["armadillo.obj", "bunny.obj", "armadillo_s.obj"])
def test_real_files_match_libigl(shared_mesh, name):
    """Interleaved vn lines, `f a//b` faces, CRLF: same arrays as libigl's reader."""
    path = shared_mesh(name)
    mesh = load_mesh(path)
    V, F = igl.read_triangle_mesh(str(path))
    assert np.array_equal(mesh.V, V) and np.array_equal(mesh.F, F)
    assert mesh.report.repairs == [] and mesh.report.is_closed


@pytest.mark.shared
def test_stanford_bunny_unreferenced(shared_mesh):
    mesh = load_mesh(shared_mesh("stanford_bunny.obj"))
    assert mesh.report.repairs == ["removed 1,113 unreferenced vertices"]
    assert mesh.report.n_boundary_edges == 223
    assert mesh.n_vertices - mesh.report.n_edges + mesh.n_faces == -3


@pytest.mark.parametrize("fmt", ["obj", "off", "ply-bin", "ply-ascii", "stl-bin", "stl-ascii"])
def test_corrupted_files_raise_mesherror_only(tmp_path, fmt):
    """Truncations, flipped bytes and inserted garbage: a Mesh or a MeshError, nothing else."""
    V, F = primitives.icosphere(1)
    ext = fmt.split("-")[0]
    if fmt == "stl-bin":
        data = binary_stl(V, F)
    elif fmt == "stl-ascii":
        data = ascii_stl(V, F).encode()
    else:
        save_mesh(tmp_path / f"src.{ext}", V, F, binary=fmt != "ply-ascii")
        data = (tmp_path / f"src.{ext}").read_bytes()
    rng = np.random.default_rng(11)
    outcomes = set()
    for t in range(36):
        b = bytearray(data)
        if t % 3 == 0:
            b = b[: int(rng.integers(0, len(b)))]
        elif t % 3 == 1:
            for _ in range(int(rng.integers(1, 5))):
                b[int(rng.integers(0, len(b)))] = int(rng.integers(0, 256))
        else:
            i = int(rng.integers(0, len(b)))
            b[i:i] = rng.integers(0, 256, size=int(rng.integers(1, 20))).astype(np.uint8).tobytes()
        path = write(tmp_path / f"bad.{ext}", bytes(b))
        try:
            mesh = load_mesh(path)
            assert mesh.F.shape[1] == 3 and np.isfinite(mesh.V).all()
            outcomes.add("mesh")
        except MeshError as exc:
            assert str(exc).startswith(f"{path}: ")
            outcomes.add("error")
    assert "error" in outcomes
