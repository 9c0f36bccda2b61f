"""A corpus of hostile mesh files, generated on demand (a helper for the robustness tests).

Every entry of :data:`CORPUS` writes one file into a folder (always a pytest ``tmp_path``) and
says what meshlap must do with it:

* ``expect="error"``: every command that reads the file exits 2 with one line
  ``meshlap: error: <file>: <problem>``; ``words`` are lowercase fragments one of which the
  problem must contain;
* ``expect="ok"``: the file loads; after repairs the mesh has ``n_vertices`` / ``n_faces``,
  ``repairs`` / ``warnings`` (fragments) must appear in the report.

Nothing here reads ``../shared``: the meshes come from :mod:`meshlap_core.primitives` or are
written out by hand, so a fresh clone can run the corpus.
"""

from __future__ import annotations

import gzip
import os
import struct
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from meshlap_core import primitives

Maker = Callable[[Path], Path]


@dataclass(frozen=True)
class Hostile:
    """One hostile input: how to make it and what meshlap must do with it."""

    name: str
    make: Maker
    expect: str  # "error" or "ok"
    words: tuple[str, ...] = ()  # error: one of these appears in the message (lowercase)
    n_vertices: int | None = None  # ok: after repairs
    n_faces: int | None = None
    repairs: tuple[str, ...] = ()  # ok: each fragment appears in some repair
    warnings: tuple[str, ...] = ()  # ok: each fragment appears in some warning
    manifold: bool = True  # ok: edge-manifold and consistently oriented after repair
    closed: bool = False  # ok: no boundary edge

    def build(self, folder: Path) -> Path:
        return self.make(folder)


# ------------------------------------------------------------------------------ writers


def obj_text(V, F, *, one_based: bool = True) -> str:
    """Plain OBJ text; ``F`` may be ragged (polygons) or hold any integers."""
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(V, dtype=float).tolist()]
    off = 1 if one_based else 0
    lines += ["f " + " ".join(str(int(i) + off) for i in f) for f in F]
    return "\n".join(lines) + "\n"


def off_text(V, F) -> str:
    V = np.asarray(V, dtype=float)
    lines = ["OFF", f"{len(V)} {len(F)} 0"]
    lines += [f"{x!r} {y!r} {z!r}" for x, y, z in V.tolist()]
    lines += [f"{len(f)} " + " ".join(str(int(i)) for i in f) for f in F]
    return "\n".join(lines) + "\n"


def ply_binary(
    V,
    F,
    *,
    byte_order: str = "<",
    n_vertices_header: int | None = None,
    n_faces_header: int | None = None,
    index_type: str = "int",
) -> bytes:
    """Binary PLY with ``double`` coordinates and a ``uchar``-counted index list."""
    V = np.asarray(V, dtype=float)
    F = np.asarray(F, dtype=np.int64)
    fmt = "binary_little_endian" if byte_order == "<" else "binary_big_endian"
    nv = len(V) if n_vertices_header is None else n_vertices_header
    nf = len(F) if n_faces_header is None else n_faces_header
    head = (
        f"ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty double x\nproperty double y\n"
        f"property double z\nelement face {nf}\nproperty list uchar {index_type} "
        "vertex_indices\nend_header\n"
    ).encode("ascii")
    body = np.ascontiguousarray(V, dtype=byte_order + "f8").tobytes()
    idt = {"int": "i4", "float": "f4"}[index_type]
    rec = np.empty(len(F), dtype=[("n", "u1"), ("i", byte_order + idt, (F.shape[1],))])
    rec["n"] = F.shape[1]
    rec["i"] = F
    return head + body + rec.tobytes()


def ply_ascii(V, F, *, n_faces_header: int | None = None) -> str:
    V = np.asarray(V, dtype=float)
    nf = len(F) if n_faces_header is None else n_faces_header
    head = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(V)}",
        "property float x",
        "property float y",
        "property float z",
        f"element face {nf}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    lines = head + [f"{x!r} {y!r} {z!r}" for x, y, z in V.tolist()]
    lines += [f"{len(f)} " + " ".join(str(int(i)) for i in f) for f in F]
    return "\n".join(lines) + "\n"


def stl_binary(V, F, n_header: int | None = None) -> bytes:
    V = np.asarray(V, dtype=float)
    F = np.asarray(F, dtype=np.int64)
    rec = np.zeros(len(F), dtype=[("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    with np.errstate(over="ignore"):  # huge coordinates overflow float32 on purpose
        rec["v"] = V[F]
    n = len(F) if n_header is None else n_header
    return b"meshlap hostile corpus".ljust(80, b" ") + struct.pack("<I", n) + rec.tobytes()


def ply_with(
    fmt: str, vertex_props: list[str], face_props: list[str], body: bytes, *, nv: int, nf: int
) -> bytes:
    """A PLY file with the header written property by property (``"float x"``,
    ``"list uchar int vertex_indices"``) and ``body`` as given (round 2: io)."""
    head = [f"ply\nformat {fmt} 1.0\nelement vertex {nv}"]
    head += [f"property {p}" for p in vertex_props]
    head += [f"element face {nf}"] + [f"property {p}" for p in face_props] + ["end_header\n"]
    return "\n".join(head).encode("ascii") + body


TETRA_BIN = (  # the tetrahedron below as float32 vertices and uchar/int32 triangle records
    np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype="<f4").tobytes(),
    b"".join(struct.pack("<Biii", 3, *f) for f in [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
)
XYZ = ["float x", "float y", "float z"]
INDICES = "list uchar int vertex_indices"


# ------------------------------------------------------------------------------ round 2: io


def _tetra_obj_lines() -> list[str]:
    return obj_text(*tetra()).splitlines()


def _dup_prop_ascii() -> bytes:
    body = b"0 0 0 7\n1 0 0 7\n0 1 0 7\n0 0 1 7\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
    return ply_with("ascii", [*XYZ, "float x"], [INDICES], body, nv=4, nf=4)


def _dup_prop_binary() -> bytes:
    V = np.frombuffer(TETRA_BIN[0], dtype="<f4").reshape(4, 3)
    body = np.column_stack([V, V[:, :1]]).astype("<f4").tobytes() + TETRA_BIN[1]
    return ply_with("binary_little_endian", [*XYZ, "float x"], [INDICES], body, nv=4, nf=4)


def _internal_names_ply() -> bytes:
    """Property names a parser might use for itself (list counts, positional fields)."""
    V = np.frombuffer(TETRA_BIN[0], dtype="<f4").reshape(4, 3)
    rec = np.zeros(4, dtype=[("p", "<f4", (3,)), ("a", "u1"), ("b", "u1")])
    rec["p"] = V
    faces = b"".join(chunk + b"\x05" for chunk in _face_records())
    return ply_with(
        "binary_little_endian",
        [*XYZ, "uchar p0", "uchar n0"],
        [INDICES, "uchar __n_vertex_indices"],
        rec.tobytes() + faces,
        nv=4,
        nf=4,
    )


def _face_records() -> list[bytes]:
    return [TETRA_BIN[1][i : i + 13] for i in range(0, len(TETRA_BIN[1]), 13)]


def _float_count_nan() -> bytes:
    faces = b"".join(struct.pack("<fiii", float("nan"), 0, 1, 2) for _ in range(4))
    return ply_with(
        "binary_little_endian",
        XYZ,
        ["list float int vertex_indices"],
        TETRA_BIN[0] + faces,
        nv=4,
        nf=4,
    )


def _float_count_inf_ascii() -> bytes:
    body = b"0 0 0\n1 0 0\n0 1 0\n0 0 1\ninf 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
    return ply_with("ascii", XYZ, ["list float int vertex_indices"], body, nv=4, nf=4)


def _ascii_tetra_ply(first_face: str) -> bytes:
    body = f"0 0 0\n1 0 0\n0 1 0\n0 0 1\n{first_face}\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
    return ply_with("ascii", XYZ, [INDICES], body.encode(), nv=4, nf=4)


def _off_counts(nv: int, nf: int, extra_vertex: bool) -> str:
    """Tetrahedron OFF whose header counts disagree with its body."""
    V, F = tetra()
    lines = ["OFF", f"{nv} {nf} 0"] + [f"{x!r} {y!r} {z!r}" for x, y, z in V.tolist()]
    if extra_vertex:
        lines.append("0.25 0.25 0.25")
    lines += ["3 " + " ".join(str(int(i)) for i in f) for f in F]
    return "\n".join(lines) + "\n"


def _obj_token(old: str, new: str) -> Callable[[], str]:
    return lambda: "\n".join(_tetra_obj_lines()).replace(old, new, 1) + "\n"


def _unicode_comments_obj() -> str:
    lines = _tetra_obj_lines()
    out = []
    for i, line in enumerate(lines):
        sep = "\u2028\u2029\u0085"[i % 3]
        out += [line, f"# note{sep}f 1 2 3{sep}v 9 9 9"]
    return "\n".join(out) + "\n"


def _continued_last_face() -> str:
    lines = _tetra_obj_lines()
    last = lines[-1].split()
    return "\n".join([*lines[:-1], " ".join(last[:3]) + " \\", last[3] + " \\"])


def _slash_faces() -> str:
    V, F = primitives.cube()
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in V.tolist()] + ["vt 0 0", "vn 0 0 1"]
    lines += [f"f {a + 1}/1/1 {b + 1}/1/1 {c + 1}//1" for a, b, c in F.tolist()]
    return "\n".join(lines) + "\n"


def _unicode_comments_off() -> str:
    return off_text(*tetra()).replace("OFF\n", "OFF\n# caf\u00e9\u0085 3 0 1 2\n", 1)


def _stream(folder: Path) -> Path:
    """A file that reports size 0 but streams (procfs); 'no such file' where there is none."""
    path = folder / "stream.obj"
    path.symlink_to("/proc/self/pagemap")
    return path


def _write(folder: Path, name: str, data: str | bytes) -> Path:
    path = folder / name
    if isinstance(data, str):
        path.write_text(data, encoding="utf-8", newline="")
    else:
        path.write_bytes(data)
    return path


def _text(name: str, data: Callable[[], str | bytes]) -> Maker:
    return lambda folder: _write(folder, name, data())


# ------------------------------------------------------------------------------ meshes


def tetra() -> tuple[np.ndarray, np.ndarray]:
    """A closed, consistently (outward) oriented tetrahedron."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return V, F


TRI_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
TRI_F = np.array([[0, 1, 2]])


def _random_bytes(n: int, seed: int) -> bytes:
    return np.random.default_rng(seed).integers(0, 256, n, dtype=np.uint8).tobytes()


def _quads() -> str:
    """A 3 x 3 vertex grid as 4 quads (fan-triangulated into 8 triangles)."""
    V, _ = primitives.grid(3, 3)
    quads = [
        [i * 3 + j, (i + 1) * 3 + j, (i + 1) * 3 + j + 1, i * 3 + j + 1]
        for i in range(2)
        for j in range(2)
    ]
    return obj_text(V, quads)


def _pentagon_off() -> str:
    t = np.linspace(0, 2 * np.pi, 6)[:-1]
    V = np.stack([np.cos(t), np.sin(t), np.zeros(5)], axis=1)
    return off_text(V, [[0, 1, 2, 3, 4]])


def _with_collinear() -> str:
    V, F = primitives.grid(3, 3)  # 9 vertices, 8 faces; 0, 1, 2 lie on the line x = 0
    return obj_text(V, [*F.tolist(), [0, 1, 2]])


def _with_duplicate_faces() -> str:
    V, F = primitives.cube()
    F = F.tolist()
    return obj_text(V, [*F, F[0], F[3][::-1], F[5][1:] + F[5][:1]])


def _duplicate_vertices() -> str:
    # two triangles meeting along an edge whose end points are written twice (not welded)
    V = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]
    return obj_text(V, [[0, 1, 2], [3, 5, 4]])


def _nonmanifold_edge() -> str:
    V = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]]
    return obj_text(V, [[0, 1, 2], [1, 0, 3], [0, 1, 4]])


def _bowtie() -> str:
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]]
    return obj_text(V, [[0, 1, 2], [0, 3, 4]])


def _inconsistent() -> str:
    V, F = primitives.grid(4, 4)
    F = F.copy()
    F[4] = F[4, ::-1]
    return obj_text(V, F)


def _components() -> str:
    V1, F1 = tetra()
    V2, F2 = primitives.icosphere(1)
    V2 = V2 + np.array([5.0, 0, 0])
    V3 = TRI_V + np.array([0, 5.0, 0])
    V = np.vstack([V1, V2, V3])
    F = np.vstack([F1, F2 + 4, TRI_F + 4 + len(V2)])
    return obj_text(V, F)


def _isolated() -> str:
    V, F = primitives.cube()
    extra = np.array([[5.0, 5, 5], [6, 6, 6], [7, 7, 7]])
    return obj_text(np.vstack([extra[:1], V, extra[1:]]), F + 1)


def _relative_indices() -> str:
    V, F = tetra()
    lines = [f"v {x} {y} {z}" for x, y, z in V.tolist()]
    lines += ["f " + " ".join(str(int(i) - 4) for i in f) for f in F]
    return "\n".join(lines) + "\n"


def _crlf_bom() -> bytes:
    return b"\xef\xbb\xbf" + obj_text(*tetra()).replace("\n", "\r\n").encode()


def _needles() -> str:
    """A grid whose middle column is squeezed to width 1e-9 (needle triangles) — valid."""
    V, F = primitives.grid(5, 5)
    V = V.copy()
    V[:, 0] = np.where(V[:, 0] > 0.6, V[:, 0] - 0.25 + 1e-9, V[:, 0])
    return obj_text(V, F)


def _caps() -> str:
    """A closed tetrahedron-like surface with a cap: one vertex pushed 1e-9 off an edge."""
    V = np.array([[0, 0, 0], [2, 0, 0], [1, 1e-9, 0], [1, -1, 1], [1, 1, 1]], dtype=float)
    # a cap (angle ~ pi at vertex 2) in a closed double pyramid
    F = np.array([[0, 1, 2], [0, 2, 4], [2, 1, 4], [1, 0, 3], [0, 4, 3], [4, 1, 3]])
    return obj_text(V, F)


def _near_zero_area() -> str:
    """A torus where one vertex is moved so that two faces have area ~1e-11 of their size."""
    V, F = primitives.torus_mesh(12, 6)
    V = V.copy()
    a, b, c = F[0]
    V[c] = V[a] + (V[b] - V[a]) * 0.5 + 1e-11 * np.cross(V[b] - V[a], [0, 0, 1.0])
    return obj_text(V, F)


def _scaled(scale: float) -> Callable[[], str]:
    def make() -> str:
        V, F = primitives.icosphere(1)
        return obj_text(V * scale, F)

    return make


def _huge_count_off() -> str:
    return "OFF\n999999999 999999999 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"


def _fifo(folder: Path) -> Path:
    path = folder / "fifo.obj"
    os.mkfifo(path)
    return path


def _dev_zero(folder: Path) -> Path:
    path = folder / "devzero.obj"
    path.symlink_to("/dev/zero")
    return path


def _directory(folder: Path) -> Path:
    path = folder / "meshdir.obj"
    path.mkdir()
    return path


def _oversize(folder: Path) -> Path:
    """A sparse mesh file one byte over the mesh-file limit (no disk space used)."""
    from meshlap_core.io.reader import MESH_SIZE_LIMIT

    path = folder / "oversize.obj"
    with open(path, "wb") as f:
        f.write(b"v 0 0 0\n")
        f.truncate(MESH_SIZE_LIMIT + 1)
    return path


def _cube_ply_binary() -> bytes:
    return ply_binary(*primitives.cube())


CORPUS: list[Hostile] = [
    # ---- files that are not meshes at all
    Hostile("empty.obj", _text("empty.obj", lambda: ""), "error", ("empty",)),
    Hostile("blank.off", _text("blank.off", lambda: "  \n\n\t\n"), "error", ("whitespace",)),
    Hostile(
        "comments.obj",
        _text("comments.obj", lambda: "# nothing\n# here\n"),
        "error",
        ("no vertices",),
    ),
    Hostile(
        "comments.off",
        _text("comments.off", lambda: "# OFF\n# 3 1 0\n"),
        "error",
        ("not an off file",),
    ),
    Hostile(
        "comments.ply",
        _text("comments.ply", lambda: "ply\nformat ascii 1.0\ncomment nothing\nend_header\n"),
        "error",
        ("no vertices",),
    ),
    Hostile(
        "garbage.obj",
        _text("garbage.obj", lambda: _random_bytes(4096, 1)),
        "error",
        ("binary data",),
    ),
    Hostile(
        "garbage.off",
        _text("garbage.off", lambda: _random_bytes(4096, 2)),
        "error",
        ("not an off file", "binary data"),
    ),
    Hostile(
        "garbage.ply",
        _text("garbage.ply", lambda: _random_bytes(4096, 3)),
        "error",
        ("not a ply file",),
    ),
    Hostile(
        "garbage.stl", _text("garbage.stl", lambda: _random_bytes(4096, 4)), "error", ("corrupt",)
    ),
    Hostile(
        "utf16.obj",
        _text("utf16.obj", lambda: obj_text(*tetra()).encode("utf-16")),
        "error",
        ("binary data",),
    ),
    Hostile(
        "gzipped.obj",
        _text("gzipped.obj", lambda: gzip.compress(obj_text(*tetra()).encode(), mtime=0)),
        "error",
        ("binary data",),
    ),
    Hostile(
        "points.obj",
        _text("points.obj", lambda: "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        "error",
        ("no faces",),
    ),
    Hostile(
        "wrong_ext.xyz",
        _text("wrong_ext.xyz", lambda: obj_text(*tetra())),
        "error",
        ("unknown mesh format",),
    ),
    Hostile("meshdir.obj", _directory, "error", ("directory",)),
    # ---- truncated and lying headers
    Hostile(
        "truncated.off",
        _text("truncated.off", lambda: off_text(*tetra())[:40]),
        "error",
        ("truncated",),
    ),
    Hostile(
        "lying.off",
        _text("lying.off", lambda: off_text(*tetra()).replace("4 4 0", "3 1 0")),
        "error",
        ("do not match",),
    ),
    Hostile("huge_counts.off", _text("huge_counts.off", _huge_count_off), "error", ("truncated",)),
    Hostile(
        "truncated.ply",
        _text("truncated.ply", lambda: _cube_ply_binary()[:300]),
        "error",
        ("truncated",),
    ),
    Hostile(
        "lying_vertices.ply",
        _text(
            "lying_vertices.ply",
            lambda: ply_binary(*primitives.cube(), n_vertices_header=2**31 - 1),
        ),
        "error",
        ("truncated",),
    ),
    Hostile(
        "lying_faces.ply",
        _text("lying_faces.ply", lambda: ply_binary(*primitives.cube(), n_faces_header=2**31 - 1)),
        "error",
        ("truncated",),
    ),
    Hostile(
        "lying_ascii.ply",
        _text("lying_ascii.ply", lambda: ply_ascii(*primitives.cube(), n_faces_header=2)),
        "error",
        ("do not match",),
    ),
    Hostile(
        "no_end_header.ply",
        _text("no_end_header.ply", lambda: ply_ascii(*tetra()).replace("end_header", "end_heade")),
        "error",
        ("end_header",),
    ),
    Hostile(
        "ascii_says_binary.ply",
        _text(
            "ascii_says_binary.ply",
            lambda: _cube_ply_binary().replace(b"binary_little_endian", b"ascii"),
        ),
        "error",
        ("binary data",),
    ),
    Hostile(
        "float_index.ply",
        _text("float_index.ply", lambda: ply_binary(*tetra(), index_type="float")),
        "error",
        ("integers",),
    ),
    Hostile(
        "truncated.stl",
        _text("truncated.stl", lambda: stl_binary(*primitives.cube())[:-30]),
        "error",
        ("truncated",),
    ),
    Hostile(
        "lying.stl",
        _text("lying.stl", lambda: stl_binary(*primitives.cube(), n_header=2**32 - 1)),
        "error",
        ("corrupt",),
    ),
    # ---- bad numbers
    Hostile(
        "nan.obj",
        _text("nan.obj", lambda: obj_text(*tetra()).replace("v 0.0 0.0 1.0", "v 0 nan 1")),
        "error",
        ("nan",),
    ),
    Hostile(
        "inf.off",
        _text("inf.off", lambda: off_text(*tetra()).replace("1.0 0.0 0.0", "1.0 inf 0.0")),
        "error",
        ("infinite",),
    ),
    Hostile(
        "huge.ply",
        _text("huge.ply", lambda: ply_binary(tetra()[0] * 1e300, tetra()[1])),
        "error",
        ("overflow",),
    ),
    Hostile(
        "huge.stl",
        _text("huge.stl", lambda: stl_binary(tetra()[0] * 1e39, tetra()[1])),
        "error",
        ("infinite",),
    ),  # 1e39 overflows float32 to inf
    # ---- bad indices
    Hostile(
        "index_oob.obj",
        _text("index_oob.obj", lambda: obj_text(*tetra()) + "f 1 2 9\n"),
        "error",
        ("vertex 9",),
    ),
    Hostile(
        "index_oob.off",
        _text("index_oob.off", lambda: off_text(tetra()[0], [[0, 1, 2], [0, 1, 7]])),
        "error",
        ("index 7",),
    ),
    Hostile(
        "index_negative.off",
        _text("index_negative.off", lambda: off_text(tetra()[0], [[0, 1, 2], [0, 1, -1]])),
        "error",
        ("index -1",),
    ),
    Hostile(
        "index_oob.ply",
        _text("index_oob.ply", lambda: ply_binary(tetra()[0], [[0, 1, 2], [0, 1, 4]])),
        "error",
        ("index 4",),
    ),
    Hostile(
        "zero_index.obj",
        _text("zero_index.obj", lambda: obj_text(*tetra(), one_based=False)),
        "error",
        ("start at 1",),
    ),
    Hostile(
        "negative_oob.obj",
        _text("negative_oob.obj", lambda: "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -9\n"),
        "error",
        ("relative index",),
    ),
    Hostile(
        "face1.obj",
        _text("face1.obj", lambda: obj_text(*tetra()) + "f 1\n"),
        "error",
        ("at least 3",),
    ),
    Hostile(
        "face2.off",
        _text("face2.off", lambda: off_text(tetra()[0], [[0, 1, 2], [0, 1]])),
        "error",
        ("at least 3",),
    ),
    Hostile(
        "face2.ply",
        _text("face2.ply", lambda: ply_ascii(tetra()[0], [[0, 1, 2], [0, 1]])),
        "error",
        ("at least 3",),
    ),
    Hostile(
        "all_degenerate.obj",
        _text(
            "all_degenerate.obj",
            lambda: obj_text([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]], [[0, 1, 2], [1, 2, 3]]),
        ),
        "error",
        ("degenerate",),
    ),
    Hostile(
        "all_repeated.off",
        _text("all_repeated.off", lambda: off_text(tetra()[0], [[0, 0, 1], [2, 3, 3]])),
        "error",
        ("degenerate",),
    ),
    # ---- files that load (repaired and/or with warnings)
    Hostile(
        "single_triangle.obj",
        _text("single_triangle.obj", lambda: obj_text(TRI_V, TRI_F)),
        "ok",
        n_vertices=3,
        n_faces=1,
    ),
    Hostile(
        "quads.obj",
        _text("quads.obj", _quads),
        "ok",
        n_vertices=9,
        n_faces=8,
        repairs=("triangulated",),
    ),
    Hostile(
        "pentagon.off",
        _text("pentagon.off", _pentagon_off),
        "ok",
        n_vertices=5,
        n_faces=3,
        repairs=("triangulated",),
    ),
    Hostile(
        "collinear.obj",
        _text("collinear.obj", _with_collinear),
        "ok",
        n_vertices=9,
        n_faces=8,
        repairs=("degenerate",),
    ),
    Hostile(
        "duplicate_faces.obj",
        _text("duplicate_faces.obj", _with_duplicate_faces),
        "ok",
        n_vertices=8,
        n_faces=12,
        repairs=("duplicate face",),
        closed=True,
    ),
    Hostile(
        "duplicate_vertices.obj",
        _text("duplicate_vertices.obj", _duplicate_vertices),
        "ok",
        n_vertices=6,
        n_faces=2,
        warnings=("same position",),
    ),
    Hostile(
        "nonmanifold_edge.obj",
        _text("nonmanifold_edge.obj", _nonmanifold_edge),
        "ok",
        n_vertices=5,
        n_faces=3,
        warnings=("non-manifold edge",),
        manifold=False,
    ),
    Hostile(
        "bowtie.obj",
        _text("bowtie.obj", _bowtie),
        "ok",
        n_vertices=5,
        n_faces=2,
        warnings=("non-manifold vert",),
    ),
    Hostile(
        "inconsistent.obj",
        _text("inconsistent.obj", _inconsistent),
        "ok",
        n_vertices=16,
        n_faces=18,
        warnings=("not consistently oriented",),
        manifold=False,
    ),
    Hostile(
        "components.obj", _text("components.obj", _components), "ok", n_vertices=49, n_faces=85
    ),
    Hostile(
        "isolated.obj",
        _text("isolated.obj", _isolated),
        "ok",
        n_vertices=8,
        n_faces=12,
        repairs=("3 unreferenced",),
        closed=True,
    ),
    Hostile(
        "relative.obj",
        _text("relative.obj", _relative_indices),
        "ok",
        n_vertices=4,
        n_faces=4,
        closed=True,
    ),
    Hostile(
        "crlf_bom.obj", _text("crlf_bom.obj", _crlf_bom), "ok", n_vertices=4, n_faces=4, closed=True
    ),
    Hostile(
        "bigendian.ply",
        _text("bigendian.ply", lambda: ply_binary(*primitives.cube(), byte_order=">")),
        "ok",
        n_vertices=8,
        n_faces=12,
        closed=True,
    ),
    Hostile(
        "cube.stl",
        _text("cube.stl", lambda: stl_binary(*primitives.cube())),
        "ok",
        n_vertices=8,
        n_faces=12,
        repairs=("welded",),
        closed=True,
    ),
    # ---- numerically degenerate but valid geometry
    Hostile(
        "needles.obj",
        _text("needles.obj", _needles),
        "ok",
        n_vertices=25,
        n_faces=32,
        warnings=("nearly degenerate",),
    ),
    Hostile(
        "cap.obj",
        _text("cap.obj", _caps),
        "ok",
        n_vertices=5,
        n_faces=6,
        warnings=("nearly degenerate",),
        closed=True,
    ),
    Hostile(
        "near_zero_area.obj",
        _text("near_zero_area.obj", _near_zero_area),
        "ok",
        n_vertices=72,
        n_faces=144,
        warnings=("nearly degenerate",),
        closed=True,
    ),
    Hostile(
        "tiny_scale.obj",
        _text("tiny_scale.obj", _scaled(1e-60)),
        "ok",
        n_vertices=42,
        n_faces=80,
        closed=True,
    ),
    Hostile(
        "large_scale.obj",
        _text("large_scale.obj", _scaled(1e60)),
        "ok",
        n_vertices=42,
        n_faces=80,
        closed=True,
    ),
    # round 2: surfaces
    Hostile(
        "surface_sphere_poles.obj",
        _text(
            "surface_sphere_poles.obj",
            lambda: obj_text(*_surface_mesh("sphere", (12, 10))),
        ),
        "ok",
        n_vertices=112,
        n_faces=220,
        closed=True,
    ),
    Hostile(
        "surface_disc_pole.obj",
        _text(
            "surface_disc_pole.obj",
            lambda: obj_text(*_surface_mesh("helicoid", 8, c=0.0)),
        ),
        "ok",
        n_vertices=65,
        n_faces=120,
    ),
    # round 2: io
    Hostile(
        "dup_prop_ascii.ply", _text("dup_prop_ascii.ply", _dup_prop_ascii), "error", ("twice",)
    ),
    Hostile(
        "dup_prop_binary.ply", _text("dup_prop_binary.ply", _dup_prop_binary), "error", ("twice",)
    ),
    Hostile(
        "internal_names.ply",
        _text("internal_names.ply", _internal_names_ply),
        "ok",
        n_vertices=4,
        n_faces=4,
        closed=True,
    ),
    Hostile(
        "float_count_nan.ply",
        _text("float_count_nan.ply", _float_count_nan),
        "error",
        ("count type",),
    ),
    Hostile(
        "float_count_inf.ply",
        _text("float_count_inf.ply", _float_count_inf_ascii),
        "error",
        ("count type",),
    ),
    Hostile(
        "inf_count.ply",
        _text("inf_count.ply", lambda: _ascii_tetra_ply("inf 0 2 1")),
        "error",
        ("integer list count",),
    ),
    Hostile(
        "negative_count.ply",
        _text("negative_count.ply", lambda: _ascii_tetra_ply("-3 0 2 1")),
        "error",
        ("negative length",),
    ),
    Hostile(
        "huge_list_count.ply",
        _text("huge_list_count.ply", lambda: _ascii_tetra_ply("99999999999999999999 0 2 1")),
        "error",
        ("declares a list of 99,999,999,999,999,999,999 values",),
    ),
    Hostile(
        "off_face_as_vertex.off",
        _text("off_face_as_vertex.off", lambda: _off_counts(5, 3, False)),
        "error",
        ("declares 5 vertices and 3 faces, but the body has 4 vertex lines and 4 face",),
    ),
    Hostile(
        "off_vertex_as_face.off",
        _text("off_vertex_as_face.off", lambda: _off_counts(4, 5, True)),
        "error",
        ("declares 4 vertices and 5 faces, but the body has 5 vertex lines and 4 face",),
    ),
    Hostile(
        "underscore_digits.obj",
        _text("underscore_digits.obj", _obj_token("v 1.0", "v 1_0")),
        "error",
        ("line 2: cannot read 'v 1_0",),
    ),
    Hostile(
        "fullwidth_digits.obj",
        _text("fullwidth_digits.obj", _obj_token("v 1.0", "v \uff11.0")),
        "error",
        ("line 2: cannot read",),
    ),
    Hostile(
        "arabic_digits.off",
        _text("arabic_digits.off", lambda: off_text(*tetra()).replace("\n1.0", "\n\u0661.0", 1)),
        "error",
        ("cannot read vertex 1",),
    ),
    Hostile(
        "glued_face.obj",
        _text("glued_face.obj", _obj_token("f 1 3 2", "f 1 3f2")),
        "error",
        ("cannot read '3f2'",),
    ),
    Hostile(
        "glued_vertex.obj",
        _text("glued_vertex.obj", _obj_token("v 1.0 0.0 0.0", "v 1.0v2.0 0.0")),
        "error",
        ("line 2: a vertex needs 3 coordinates, found 2",),
    ),
    Hostile(
        "unicode_separators.obj",
        _text("unicode_separators.obj", _unicode_comments_obj),
        "ok",
        n_vertices=4,
        n_faces=4,
        closed=True,
    ),
    Hostile(
        "unicode_separators.off",
        _text("unicode_separators.off", _unicode_comments_off),
        "ok",
        n_vertices=4,
        n_faces=4,
        closed=True,
    ),
    Hostile(
        "bare_cr.obj",
        _text("bare_cr.obj", lambda: obj_text(*tetra()).replace("\n", "\r")),
        "ok",
        n_vertices=4,
        n_faces=4,
        closed=True,
    ),
    Hostile(
        "continued_last_face.obj",
        _text("continued_last_face.obj", _continued_last_face),
        "ok",
        n_vertices=4,
        n_faces=4,
        closed=True,
    ),
    Hostile(
        "slash_faces.obj",
        _text("slash_faces.obj", _slash_faces),
        "ok",
        n_vertices=8,
        n_faces=12,
        closed=True,
    ),
    Hostile("stream.obj", _stream, "error", ("streams more than", "no such file")),
    # round 2: topology
    Hostile(
        "touching_spheres.obj",
        _text("touching_spheres.obj", lambda: obj_text(*touching_spheres())),
        "ok",
        n_vertices=83,
        n_faces=160,
        warnings=("1 non-manifold vertex",),
        closed=True,
    ),
    Hostile(
        "two_tetrahedra_vertex.obj",
        _text("two_tetrahedra_vertex.obj", lambda: obj_text(*tetrahedra_sharing_vertex(2))),
        "ok",
        n_vertices=7,
        n_faces=8,
        warnings=("1 non-manifold vertex",),
        closed=True,
    ),
    Hostile(
        "three_tetrahedra_vertex.off",
        _text("three_tetrahedra_vertex.off", lambda: off_text(*tetrahedra_sharing_vertex(3))),
        "ok",
        n_vertices=10,
        n_faces=12,
        warnings=("1 non-manifold vertex",),
        closed=True,
    ),
    Hostile(
        "glued_torus.obj",
        _text("glued_torus.obj", lambda: obj_text(*glued_torus())),
        "ok",
        n_vertices=8 * 6 - 1,
        n_faces=2 * 8 * 6,
        warnings=("1 non-manifold vertex",),
        closed=True,
    ),
    Hostile(
        "sphere_touching_disk.obj",
        _text("sphere_touching_disk.obj", lambda: obj_text(*sphere_touching_disk())),
        "ok",
        n_vertices=42 + 16 - 1,
        n_faces=80 + 18,
        warnings=("1 non-manifold vertex",),
    ),
    Hostile(
        "inside_out_sphere.obj",
        _text("inside_out_sphere.obj", lambda: obj_text(*inside_out_sphere())),
        "ok",
        n_vertices=162,
        n_faces=320,
        closed=True,
    ),
    # round 2: spectral
    Hostile(
        "two_scales_1e-6_1e6.obj",
        _text("two_scales_1e-6_1e6.obj", lambda: _two_scales(1e-6, 1e6)),
        "ok",
        n_vertices=84,
        n_faces=160,
        closed=True,
    ),
    Hostile(
        "two_scales_1e-12_1.obj",
        _text("two_scales_1e-12_1.obj", lambda: _two_scales(1e-12, 1.0)),
        "ok",
        n_vertices=84,
        n_faces=160,
        closed=True,
    ),
]

BY_NAME: dict[str, Hostile] = {h.name: h for h in CORPUS}
ERRORS: list[Hostile] = [h for h in CORPUS if h.expect == "error"]
LOADABLE: list[Hostile] = [h for h in CORPUS if h.expect == "ok"]

# special files: reading them naively hangs (FIFO) or never ends (/dev/zero); tested in a
# subprocess with a timeout
SPECIAL: list[Hostile] = [
    Hostile("fifo.obj", _fifo, "error", ("not a regular file",)),
    Hostile("devzero.obj", _dev_zero, "error", ("not a regular file",)),
    Hostile("oversize.obj", _oversize, "error", ("may be at most",)),
]


def build(name: str, folder: Path) -> Path:
    """Write the corpus entry ``name`` into ``folder`` and return its path."""
    for h in (*CORPUS, *SPECIAL):
        if h.name == name:
            return h.build(folder)
    raise KeyError(name)


# round 2: surfaces (called lazily by the CORPUS entries above)
def _surface_mesh(name: str, res, **params: float) -> tuple[np.ndarray, np.ndarray]:
    """A grid mesh of a parametric surface, its pole edges collapsed to fans."""
    from meshlap_core.surfaces import get_surface, mesh_surface

    m = mesh_surface(get_surface(name, **params), res)
    return m.V, m.F


# ------------------------------------------------------------------------------ round 2: topology
# meshes whose vertices have several fans (one-rings used to hang on them), and an inside-out
# sphere (volume change used to take the sign of the signed volume)


def glue(V: np.ndarray, F: np.ndarray, keep: int, drop: int) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertex ``drop`` into ``keep`` (faces of ``drop`` now use ``keep``)."""
    F = np.where(F == drop, keep, F)
    F = F - (F > drop)
    return np.delete(V, drop, axis=0), F


def first_face_at(V: np.ndarray, F: np.ndarray, v: int) -> tuple[np.ndarray, np.ndarray]:
    """Reorder faces so the first face has vertex ``v`` as its first corner (the robustness
    tests ask for the one-ring of ``F[0, 0]``)."""
    F = np.array(F)
    f = int(np.flatnonzero((F == v).any(axis=1))[0])
    F[[0, f]] = F[[f, 0]]
    F[0] = np.roll(F[0], -int(np.flatnonzero(F[0] == v)[0]))
    return V, F


def touching_spheres() -> tuple[np.ndarray, np.ndarray]:
    """Two outward icospheres touching at one shared vertex (two closed fans there)."""
    V, F = primitives.icosphere(1)
    top = int(np.argmax(V[:, 2]))
    V2 = V * np.array([1.0, 1.0, -1.0]) + np.array([0.0, 0.0, 2.0 * V[top, 2]])
    n = len(V)
    W, G = glue(np.vstack([V, V2]), np.vstack([F, F[:, ::-1] + n]), top, top + n)
    return first_face_at(W, G, top)


def _tetra_at(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outward tetrahedron with apex 0 at the origin and its base towards ``direction``."""
    d = direction / np.linalg.norm(direction)
    p = np.cross(d, [0.3, 0.5, 0.7])
    p /= np.linalg.norm(p)
    q = np.cross(d, p)
    t = 2 * np.pi * np.arange(3) / 3
    base = d + 0.5 * (np.cos(t)[:, None] * p + np.sin(t)[:, None] * q)
    V = np.vstack([np.zeros(3), base])
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    if np.linalg.det(V[1:] - V[0]) > 0:  # base counter-clockwise seen from the apex: inward
        F = F[:, ::-1]
    return V, F


def tetrahedra_sharing_vertex(k: int) -> tuple[np.ndarray, np.ndarray]:
    """``k`` closed tetrahedra sharing only their apex, vertex 0 (``k`` closed fans)."""
    dirs = [np.array(d, float) for d in ([1, 0, 0], [-1, 0.2, 0], [0, -1, 0.3], [0.1, 1, 1])]
    Vs, Fs = [], []
    for j in range(k):
        V, F = _tetra_at(dirs[j])
        Fs.append(np.where(F == 0, 0, F + 3 * j))
        Vs.append(V[1:] if j else V)
    return first_face_at(np.vstack(Vs), np.vstack(Fs), 0)


def glued_torus() -> tuple[np.ndarray, np.ndarray]:
    """An 8 x 6 torus with two far-apart vertices glued (two closed fans at one vertex)."""
    V, F = primitives.torus_mesh(8, 6)
    far = int(np.argmax(np.linalg.norm(V - V[0], axis=1)))
    V, F = glue(V, F, 0, far)
    return first_face_at(V, F, 0)


def sphere_touching_disk() -> tuple[np.ndarray, np.ndarray]:
    """An icosphere whose south pole is a boundary vertex of a 4 x 4 grid: a closed and an open
    fan at one vertex."""
    V, F = primitives.icosphere(1)
    bottom = int(np.argmin(V[:, 2]))
    Vg, Fg = primitives.grid(4, 4)
    Vg = Vg - Vg[1] + V[bottom]  # grid vertex 1 is on the grid's boundary
    n = len(V)
    W, G = glue(np.vstack([V, Vg]), np.vstack([F, Fg + n]), bottom, 1 + n)
    return first_face_at(W, G, bottom)


def inside_out_sphere() -> tuple[np.ndarray, np.ndarray]:
    """An icosphere with every face reversed: closed, consistently but inward oriented."""
    V, F = primitives.icosphere(2)
    return V, F[:, ::-1].copy()


# round 2: spectral (built lazily by the CORPUS entries above)
def _two_scales(small: float, big: float) -> str:
    """Two icospheres of radii ``small`` and ``big`` side by side (round 2: the spectrum of a
    pencil whose components differ in scale by many orders)."""
    V, F = primitives.icosphere(1)
    return obj_text(np.vstack([V * small, V * big + [3.0 * big, 0, 0]]), np.vstack([F, F + len(V)]))


# ------------------------------------------------------------------------------ round 3
# JSON documents that break a naive json.loads, sparse files over the size limits, and spectral
# cache entries built to exhaust memory or print numpy's pickle advice (generated, never stored)


def deep_json(folder: Path, depth: int = 100_000) -> Path:
    """``[[[[...]]]]`` nested ``depth`` deep (json.loads raises RecursionError)."""
    path = folder / "deep.json"
    path.write_text("[" * depth + "]" * depth)
    return path


def long_int_json(folder: Path, digits: int = 5000) -> Path:
    """A session-like object with an integer of ``digits`` digits (beyond Python's limit)."""
    path = folder / "longint.json"
    path.write_text('{"version": 1, "seed": ' + "7" * digits + "}")
    return path


def sparse_file(folder: Path, name: str, size: int) -> Path:
    """A file reporting ``size`` bytes that takes no disk space (``truncate``)."""
    path = folder / name
    with open(path, "wb") as f:
        f.truncate(size)
    return path


def _npy_header(shape: tuple[int, ...], dtype: str = "<f8") -> bytes:
    """A version-1.0 ``.npy`` header declaring ``shape`` (the data is not included)."""
    import io

    buf = io.BytesIO()
    header = {"descr": dtype, "fortran_order": False, "shape": shape}
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue()


def npz_bomb(path: Path, n: int, declared_bytes: int = 8 * 2**30, sent: int = 9 * 2**20) -> Path:
    """A cache entry whose ``vectors`` member declares ``declared_bytes`` of float64 (shape
    ``(n, declared_bytes // 8 // n)``) but holds ``sent`` bytes of zeros, deflated: a file of a
    few kB that a loader trusting the header would answer with an 8 GB allocation."""
    import zipfile

    cols = declared_bytes // 8 // n
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("vectors.npy", _npy_header((n, cols)) + bytes(sent))
    return path


def random_entry(path: Path, size: int = 4096, seed: int = 3) -> Path:
    """Random bytes where a cache entry should be (numpy would suggest allow_pickle)."""
    path.write_bytes(np.random.default_rng(seed).bytes(size))
    return path
