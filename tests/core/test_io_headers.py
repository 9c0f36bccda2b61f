"""Header–body consistency (issue 14, item 3) and bounded reads (item 6, io).

A header is checked against its body, never guessed: duplicate names, float list-count types,
impossible counts and bodies with more or fewer records than declared are refused naming the
count declared and the count found; names that a parser might use for itself are read as
written. Reads stop at the size a file reports (or 64 MB for a file reporting size 0).
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np
import pytest

from meshlap_core.errors import MeshError
from meshlap_core.io import load_mesh, load_vertex_scalars
from meshlap_core.io.load import UNSIZED_READ_LIMIT, read_bounded

TRI_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])


def write(path: Path, data: str | bytes) -> Path:
    path.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
    return path


def ply(fmt: str, vprops: list[str], fprops: list[str], body: bytes, nv=3, nf=1) -> bytes:
    head = [f"ply\nformat {fmt} 1.0\nelement vertex {nv}"]
    head += [f"property {p}" for p in vprops] + [f"element face {nf}"]
    head += [f"property {p}" for p in fprops] + ["end_header\n"]
    return "\n".join(head).encode() + body


XYZ = ["float x", "float y", "float z"]
LIST = "list uchar int vertex_indices"
TRI_ASCII = b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
TRI_BIN = TRI_V.astype("<f4").tobytes() + struct.pack("<Biii", 3, 0, 1, 2)


# ---------------------------------------------------------------------------- PLY headers


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian"])
def test_ply_duplicate_property_refused(tmp_path, fmt):
    if fmt == "ascii":
        body = b"0 0 0 5\n1 0 0 5\n0 1 0 5\n3 0 1 2\n"
    else:
        V = np.column_stack([TRI_V, [5, 5, 5]]).astype("<f4")
        body = V.tobytes() + struct.pack("<Biii", 3, 0, 1, 2)
    path = write(tmp_path / "d.ply", ply(fmt, [*XYZ, "float x"], [LIST], body))
    with pytest.raises(
        MeshError, match="line 7: the vertex element declares the property 'x' twice"
    ):
        load_mesh(path)


def test_ply_duplicate_element_refused(tmp_path):
    data = ply("ascii", XYZ, [LIST], TRI_ASCII).replace(
        b"end_header", b"element face 1\nproperty list uchar int vertex_indices\nend_header"
    )
    with pytest.raises(MeshError, match="a second 'face' element"):
        load_mesh(write(tmp_path / "e.ply", data))


def test_ply_names_the_parser_might_use_are_read_as_written(tmp_path):
    """Properties called like the reader's internal fields (list counts, positions) are data."""
    rec = np.zeros(3, dtype=[("p", "<f4", (3,)), ("a", "<f4"), ("b", "<f4")])
    rec["p"], rec["a"], rec["b"] = TRI_V, [1, 2, 3], [4, 5, 6]
    faces = struct.pack("<BiiiB", 3, 0, 1, 2, 9)
    data = ply(
        "binary_little_endian",
        [*XYZ, "float p0", "float n0"],
        [LIST, "uchar __n_vertex_indices"],
        rec.tobytes() + faces,
    )
    path = write(tmp_path / "n.ply", data)
    mesh = load_mesh(path)
    assert mesh.F.tolist() == [[0, 1, 2]] and np.array_equal(mesh.V, TRI_V)
    assert load_vertex_scalars(path, "p0").tolist() == [1, 2, 3]
    assert load_vertex_scalars(path, "n0").tolist() == [4, 5, 6]


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian"])
def test_ply_float_list_count_type_refused(tmp_path, fmt):
    body = (
        b"0 0 0\n1 0 0\n0 1 0\nnan 0 1 2\n"
        if fmt == "ascii"
        else TRI_V.astype("<f4").tobytes() + struct.pack("<fiii", float("nan"), 0, 1, 2)
    )
    path = write(tmp_path / "f.ply", ply(fmt, XYZ, ["list float int vertex_indices"], body))
    with pytest.raises(MeshError, match="floating-point count type"):
        load_mesh(path)


@pytest.mark.parametrize(
    ("face", "needle"),
    [
        (b"inf 0 1 2", "cannot read 'inf' as an integer list count (face record 0"),
        (b"nan 0 1 2", "cannot read 'nan' as an integer list count"),
        (b"2.5 0 1 2", "cannot read '2.5' as an integer list count"),
        (b"-3 0 1 2", "face record 0 has a list of negative length -3"),
        (b"99999999999999999999 0 1 2", "declares a list of 99,999,999,999,999,999,999 values, 3"),
    ],
)
def test_ply_ascii_list_counts_checked(tmp_path, face, needle):
    body = b"0 0 0\n1 0 0\n0 1 0\n" + face + b"\n"
    with pytest.raises(MeshError) as info:
        load_mesh(write(tmp_path / "c.ply", ply("ascii", XYZ, [LIST], body)))
    assert needle in str(info.value)


def test_ply_element_counts_checked(tmp_path):
    data = ply("ascii", XYZ, [LIST], TRI_ASCII, nv=10**12)
    with pytest.raises(
        MeshError, match=r"declares 1,000,000,000,000 vertex records but only \d+ bytes"
    ):
        load_mesh(write(tmp_path / "big.ply", data))
    for count in (b"nan", b"inf", b"1e3", b"1_0", b"-1"):
        data = ply("ascii", XYZ, [LIST], TRI_ASCII).replace(b"vertex 3", b"vertex " + count)
        with pytest.raises(MeshError, match="line 3"):
            load_mesh(write(tmp_path / "c.ply", data))
    with pytest.raises(MeshError, match="2 more values follow"):
        load_mesh(write(tmp_path / "m.ply", ply("ascii", XYZ, [LIST], TRI_ASCII + b"1 2\n")))
    data = ply("binary_little_endian", XYZ, [LIST], TRI_BIN, nf=2)
    with pytest.raises(MeshError, match="truncated PLY file: the header declares 3 vertices and 2"):
        load_mesh(write(tmp_path / "t.ply", data))


# ---------------------------------------------------------------------------- OFF bodies

TETRA_V = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
TETRA_F = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"


def test_off_face_read_as_vertex_is_refused_with_counts(tmp_path):
    """The header promises 5 vertices and 3 faces; the body has 4 and 4 (was: a face lost)."""
    path = write(tmp_path / "a.off", "OFF\n5 3 0\n" + TETRA_V + TETRA_F)
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    msg = str(info.value)
    assert "declares 5 vertices and 3 faces, but the body has 4 vertex lines and 4 face" in msg


def test_off_vertex_read_as_face_is_refused_with_counts(tmp_path):
    path = write(tmp_path / "b.off", "OFF\n4 5 0\n" + TETRA_V + "0.5 0.5 0.5\n" + TETRA_F)
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    assert "declares 4 vertices and 5 faces, but the body has 5 vertex lines and 4 face" in str(
        info.value
    )


def test_off_vertex_and_face_fields_checked(tmp_path):
    with pytest.raises(MeshError, match="vertex 1 has 4 numbers; OFF vertex lines have 3"):
        load_mesh(
            write(tmp_path / "w.off", "OFF\n4 4 0\n0 0 0\n1 0 0 1.5\n0 1 0\n0 0 1\n" + TETRA_F)
        )
    bad_colour = TETRA_F.replace("3 0 2 1\n", "3 0 2 1 3 0 1 2 3 4\n")
    with pytest.raises(MeshError, match="face 0 has 6 numbers after its 3 indices"):
        load_mesh(write(tmp_path / "c.off", "OFF\n4 4 0\n" + TETRA_V + bad_colour))
    mesh = load_mesh(
        write(tmp_path / "rgba.off", "OFF\n4 4 0\n" + TETRA_V + TETRA_F.replace("\n", " 1 0 0 1\n"))
    )
    assert mesh.F.shape == (4, 3)


# ---------------------------------------------------------------------------- bounded reads


def test_read_bounded_reads_regular_files_whole(tmp_path):
    data = os.urandom(3 * 2**20 + 5)
    assert read_bounded(write(tmp_path / "x.bin", data), "x") == data


@pytest.mark.skipif(not Path("/proc/self/pagemap").exists(), reason="needs Linux procfs")
def test_file_reporting_size_zero_that_streams_is_refused(tmp_path):
    """/proc/self/pagemap reports size 0 and streams gigabytes: refused after the limit."""
    link = tmp_path / "stream.obj"
    link.symlink_to("/proc/self/pagemap")
    assert os.stat(link).st_size == 0
    with pytest.raises(MeshError, match=f"streams more than {UNSIZED_READ_LIMIT // 2**20} MB"):
        load_mesh(link)


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux procfs")
def test_small_procfs_file_is_read(tmp_path):
    """A size-0 file with a finite body (procfs) is read whole."""
    data = read_bounded("/proc/self/status", "status")
    assert data.startswith(b"Name:")
