"""The tokenizer contract (issue 14, item 2): one reading of every byte, whichever path reads it.

* a property test (hypothesis) feeds the bulk and the per-line OBJ parsers the same generated
  files, plain and hostile (non-ASCII line separators in comments, bare CR line ends,
  continuations, numbers only Python accepts, glued tokens, slash forms), and checks that they
  give identical meshes or identical errors;
* every format refuses a non-literal number naming where it is, and reads U+0085, U+2028,
  U+2029 in comments as comment text.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from meshlap_core.errors import MeshError
from meshlap_core.io import load_mesh
from meshlap_core.io.obj import parse_obj, parse_obj_bulk, parse_obj_lines

SRC = "gen.obj"

# ------------------------------------------------------------------ generated OBJ files

GOOD_NUMBERS = ["0", "1", "-1", "0.5", "-.25", "5.", "+2", "1e-3", "2.5E+2", "007", "3"]
BAD_NUMBERS = [
    "1_0",
    "\u0663",  # ARABIC-INDIC DIGIT THREE
    "\uff13",  # FULLWIDTH DIGIT THREE
    "\u22121",  # MINUS SIGN
    "0x10",
    "1.0v2.0",
    "3f2",
    "1e",
    "--1",
    ".",
    "nan",
    "inf",
    "-Infinity",
    "1\u00a02",  # no-break space inside a token
]
GOOD_CORNERS = ["1", "2", "3", "4", "-1", "-2", "1/1", "2/1/1", "3//2", "+4", "1/-1/2"]
BAD_CORNERS = ["1/", "/1", "1///2", "1/2/3/4", "1/a", "3f2", "1_0", "\uff12", "0", "9", "-9", "1.5"]
SEPARATORS = ["\u2028", "\u2029", "\u0085", "\u000b", "\u000c"]


def _numbers(draw, k: int, hostile: bool) -> list[str]:
    pool = GOOD_NUMBERS + (BAD_NUMBERS if hostile else [])
    return [draw(st.sampled_from(pool)) for _ in range(k)]


@st.composite
def obj_line(draw, hostile: bool) -> str:
    kind = draw(
        st.sampled_from(
            ["v", "v", "v", "f", "f", "f", "comment", "blank", "l", "vt", "g"]
            + (["indent", "inline", "sep", "glued", "extra", "short"] if hostile else [])
        )
    )
    if kind == "v":
        return "v " + " ".join(_numbers(draw, 3, hostile))
    if kind == "f":
        pool = GOOD_CORNERS + (BAD_CORNERS if hostile else [])
        n = draw(st.integers(3 if not hostile else 1, 5))
        return "f " + " ".join(draw(st.sampled_from(pool)) for _ in range(n))
    if kind == "comment":
        return "# note " + draw(st.sampled_from(["", *SEPARATORS])) + "v 9 9 9"
    if kind == "blank":
        return draw(st.sampled_from(["", " ", "\t"]))
    if kind == "l":
        return "l 1 2"
    if kind == "vt":
        return "vt 0.5 0.5"
    if kind == "g":
        return "g part"
    if kind == "indent":
        return "  v 0 0 1"
    if kind == "inline":
        return "f 1 2 3 # comment"
    if kind == "sep":
        sep = draw(st.sampled_from(SEPARATORS))
        return draw(st.sampled_from([f"v 1 2{sep}3", f"v{sep}1 2 3", f"f 1 2{sep}3"]))
    if kind == "glued":
        return draw(st.sampled_from(["v 1.0v2.0 0.0", "f 1 3f2", "v 1 2 3v", "f1 2 3"]))
    if kind == "extra":
        return "v 1 2 3 " + draw(st.sampled_from(["1", "0.5 0.5 0.5", "x", "1_0"]))
    return draw(st.sampled_from(["v 1 2", "f 1 2", "f", "v"]))


@st.composite
def obj_file(draw) -> bytes:
    hostile = draw(st.booleans())
    base = ["v 0 0 0", "v 1 0 0", "v 0 1 0", "v 0 0 1"]
    lines = base + draw(st.lists(obj_line(hostile), min_size=1, max_size=12))
    if draw(st.booleans()):
        lines = draw(st.permutations(lines))
    ends = ["\n", "\r\n"] + (["\r"] if hostile else [])
    text = ""
    for line in lines:
        cont = hostile and draw(st.integers(0, 9)) == 0  # a continuation
        text += line + ("\\" if cont else "") + draw(st.sampled_from(ends))
    if draw(st.booleans()):  # no line end after the last line, maybe a continuation
        text = text.rstrip("\r\n") + ("\\" if hostile and draw(st.booleans()) else "")
    return text.encode("utf-8")


def _outcome(fn, data: bytes):
    try:
        return ("ok", fn(data))
    except MeshError as exc:
        return ("error", str(exc))


def _same_parse(a, b) -> bool:
    if not np.array_equal(a.V, b.V, equal_nan=True) or a.warnings != b.warnings:
        return False
    if isinstance(a.faces, np.ndarray) != isinstance(b.faces, np.ndarray):
        return False
    if isinstance(a.faces, np.ndarray):
        return np.array_equal(a.faces, b.faces)
    return np.array_equal(a.faces.indices, b.faces.indices) and np.array_equal(
        a.faces.sizes, b.faces.sizes
    )


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(obj_file())
def test_bulk_and_line_obj_parsers_agree(data):
    """Wherever the bulk path answers, the per-line path gives the identical mesh; so
    ``parse_obj`` (bulk, else per-line) gives one reading of every file."""
    general = _outcome(lambda d: parse_obj_lines(d, SRC), data)
    bulk = parse_obj_bulk(data)
    if bulk is not None:
        assert general[0] == "ok", (data, general)
        assert _same_parse(bulk, general[1]), data
    full = _outcome(lambda d: parse_obj(d, SRC), data)
    assert full[0] == general[0]
    if full[0] == "ok":
        assert _same_parse(full[1], general[1])
    else:
        assert full[1] == general[1]


def test_bulk_path_reads_plain_files():
    """The property above is not vacuous: plain files (also CRLF, slashes, relative indices,
    comment lines) are read by the bulk path."""
    plain = "# c\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1/1 3/2/1 4//2\nf -4 -1 -2\n"
    for text in (plain, plain.replace("\n", "\r\n")):
        bulk = parse_obj_bulk(text.encode())
        assert bulk is not None
        assert bulk.faces.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 2]]
        assert np.array_equal(bulk.V[3], [0.0, 0, 1])


def test_bulk_path_in_threads_reads_the_blocks_in_order(monkeypatch):
    """A big file's blocks are parsed on two threads: the same mesh as the per-line path,
    the blocks in file order (tiny blocks here, so many of each kind run at once), and a
    refused block anywhere still hands the file to the per-line path."""
    from meshlap_core.io import obj

    rng = np.random.default_rng(7)
    V = rng.normal(size=(300, 3))
    F = rng.integers(1, 301, size=(500, 3))
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in V] + [
        f"f {a} {b}/2 {c}//3" for a, b, c in F
    ]
    text = ("\n".join(lines) + "\n").encode()
    monkeypatch.setattr(obj, "_PARALLEL_BYTES", 0)
    monkeypatch.setattr(obj, "_BLOCK", 256)
    bulk = parse_obj_bulk(text)
    assert bulk is not None and _same_parse(bulk, parse_obj_lines(text, SRC))
    assert np.array_equal(bulk.V, V) and np.array_equal(bulk.faces, F - 1)
    bad = text.replace(b"v ", b"v 1 ", 1)  # one vertex line with 4 numbers, in the first block
    assert parse_obj_bulk(bad) is None
    bad = text[: len(text) - 20] + text[len(text) - 20 :].replace(b"f ", b"f x", 1)
    assert parse_obj_bulk(bad) is None


# ------------------------------------------------------------------ the contract, by format


def write(path: Path, text: str | bytes) -> Path:
    path.write_bytes(text.encode("utf-8") if isinstance(text, str) else text)
    return path


TETRA_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.mark.parametrize("sep", SEPARATORS[:3])
def test_obj_comment_with_unicode_separator_stays_a_comment(tmp_path, sep):
    text = f"# made by a tool {sep}v 5 5 5\n" + TETRA_OBJ.replace("\n", f"\n# {sep}f 1 2 3\n")
    mesh = load_mesh(write(tmp_path / "c.obj", text))
    assert mesh.V.shape == (4, 3) and mesh.F.shape == (4, 3)
    assert np.array_equal(mesh.V, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])


@pytest.mark.parametrize(
    ("line", "token"),
    [
        ("v 1_0 0 0", "1_0"),
        ("v \u0663 0 0", "\u0663"),
        ("v \uff11 0 0", "\uff11"),
        ("v 1.0v2.0 0.0", "1.0v2.0"),
        ("f 1 3f2 4", "3f2"),
        ("f 1 2 \uff13", "\uff13"),
    ],
)
def test_obj_non_literal_numbers_are_refused_naming_the_line(tmp_path, line, token):
    text = TETRA_OBJ + line + "\n"
    with pytest.raises(MeshError) as info:
        load_mesh(write(tmp_path / "n.obj", text))
    msg = str(info.value)
    assert "line 9:" in msg and token in msg


def test_obj_bare_cr_line_ends_read_as_lines(tmp_path):
    mesh = load_mesh(write(tmp_path / "cr.obj", TETRA_OBJ.replace("\n", "\r")))
    assert mesh.F.shape == (4, 3) and mesh.V.shape == (4, 3)


def test_obj_last_line_continuation_is_read_as_written(tmp_path):
    text = TETRA_OBJ.rstrip("\n").rsplit("\n", 1)[0] + "\nf 2 3 \\\n4\\"
    mesh = load_mesh(write(tmp_path / "k.obj", text))
    assert mesh.F.shape == (4, 3)
    assert sorted(mesh.F[-1].tolist()) == [1, 2, 3]
    mesh = load_mesh(write(tmp_path / "k2.obj", TETRA_OBJ.rstrip("\n") + " \\"))
    assert mesh.F.shape == (4, 3)


def test_obj_nan_inf_reach_the_validator(tmp_path):
    with pytest.raises(MeshError, match=r"NaN|infinite|finite"):
        load_mesh(write(tmp_path / "nan.obj", TETRA_OBJ.replace("v 1 0 0", "v nan 0 0")))


@pytest.mark.parametrize("bad", ["1_0", "\uff11", "0x1"])
def test_off_ply_stl_refuse_non_literal_numbers(tmp_path, bad):
    off = f"OFF\n4 1 0\n0 0 0\n{bad} 0 0\n0 1 0\n0 0 1\n3 0 1 2\n"
    with pytest.raises(MeshError, match="vertex 1"):
        load_mesh(write(tmp_path / "a.off", off))
    ply = (
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        f"0 0 0\n{bad} 0 0\n0 1 0\n3 0 1 2\n"
    )
    with pytest.raises(MeshError, match="vertex record 1"):
        load_mesh(write(tmp_path / "a.ply", ply))
    stl = f"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex {bad} 0 0\n"
    stl += "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n"
    with pytest.raises(MeshError, match="vertex line 1"):
        load_mesh(write(tmp_path / "a.stl", stl))


def test_off_counts_and_faces_need_integer_literals(tmp_path):
    with pytest.raises(MeshError, match="integers"):
        load_mesh(write(tmp_path / "h.off", "OFF\n1_0 1 0\n0 0 0\n"))
    text = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2.0\n"
    with pytest.raises(MeshError, match="face 0"):
        load_mesh(write(tmp_path / "f.off", text))


def test_off_and_ply_comment_with_unicode_separator(tmp_path):
    off = "OFF\n# caf\u00e9 \u0085 1 2 3\n3 1 0\n0 0 0\n1 0 0\n0 1 0 # \u2028 9\n3 0 1 2\n"
    mesh = load_mesh(write(tmp_path / "c.off", off))
    assert mesh.F.tolist() == [[0, 1, 2]]
    ply = (
        "ply\nformat ascii 1.0\ncomment note \u0085 element vertex 9\nelement vertex 3\n"
        "property float x\nproperty float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
    )
    mesh = load_mesh(write(tmp_path / "c.ply", ply))
    assert mesh.F.tolist() == [[0, 1, 2]]


def test_off_and_ply_bare_cr_line_ends(tmp_path):
    off = "OFF\r3 1 0\r0 0 0\r1 0 0\r0 1 0\r3 0 1 2\r"
    assert load_mesh(write(tmp_path / "cr.off", off)).F.tolist() == [[0, 1, 2]]
    ply = (
        "ply\rformat ascii 1.0\relement vertex 3\rproperty float x\rproperty float y\r"
        "property float z\relement face 1\rproperty list uchar int vertex_indices\rend_header\r"
        "0 0 0\r1 0 0\r0 1 0\r3 0 1 2\r"
    )
    mesh = load_mesh(write(tmp_path / "cr.ply", ply))
    assert mesh.F.tolist() == [[0, 1, 2]] and np.array_equal(
        mesh.V, [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    )
