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
    V, F = primitives.torus(12, 6)
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
]


def build(name: str, folder: Path) -> Path:
    """Write the corpus entry ``name`` into ``folder`` and return its path."""
    for h in (*CORPUS, *SPECIAL):
        if h.name == name:
            return h.build(folder)
    raise KeyError(name)


# round 2: spectral (built lazily by the CORPUS entries above)
def _two_scales(small: float, big: float) -> str:
    """Two icospheres of radii ``small`` and ``big`` side by side (round 2: the spectrum of a
    pencil whose components differ in scale by many orders)."""
    V, F = primitives.icosphere(1)
    return obj_text(np.vstack([V * small, V * big + [3.0 * big, 0, 0]]), np.vstack([F, F + len(V)]))
