"""Hostile round 3, class test: every file the core reads goes through one reader
(:mod:`meshlap_core.io.reader`), which refuses directories, FIFOs, devices and files over the
size limit of their kind before a byte is parsed, naming the file.

The first test reads the source of ``meshlap_core`` (``ast``): no module but the reader opens
a file for reading. The others give the reader and its users (the mesh loader, the JSON reader,
the spectral cache) each kind of file that is not what it claims to be.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import meshlap_core
from meshlap_core import MeshError, load_mesh, primitives
from meshlap_core.io.reader import (
    JSON_SIZE_LIMIT,
    MESH_SIZE_LIMIT,
    SIZE_LIMITS,
    open_input,
    read_input,
    read_json,
)
from tests.support import hostile

CORE = Path(meshlap_core.__file__).parent
READER = CORE / "io" / "reader.py"
# reads that are not of a user's file, each with its reason
ALLOWED = {
    ("linalg/slicing.py", "open"): "/proc/stat, the kernel's CPU counters (not a user's file)",
    ("io/atomic.py", "open"): "the output's directory, opened to fsync the rename",
    ("exercises/harness.py", "open"): "/proc/self/statm and /dev/null in the grading harness, "
    "which runs beside a student's file and imports no meshlap module (not a user's file)",
    ("exercises/harness.py", "np.load"): "a call's inputs, written by the checker itself",
    ("exercises/isolation.py", "open"): "/proc: a worker's CPU time, parent and token (not a "
    "user's file)",
    ("pictures/turntable_gif.py", "read_bytes"): "the GIF it has just written into its own "
    "temporary folder (not a user's file)",
    ("pictures/window.py", "read_text"): "the window process's log, written into the window's own "
    "temporary folder (not a user's file)",
}
# calls that read a file by name
READ_CALLS = {"read_text", "read_bytes", "load", "loadtxt", "genfromtxt", "fromfile", "imread"}


def _mode_of(call: ast.Call) -> str:
    """The mode of an ``open(...)`` call ("r" when not given or not a literal)."""
    args = list(call.args[1:2]) + [k.value for k in call.keywords if k.arg == "mode"]
    if args and isinstance(args[0], ast.Constant) and isinstance(args[0].value, str):
        return args[0].value
    return "r"


def _flags_write(call: ast.Call) -> bool:
    """Whether an ``os.open(path, flags)`` call names a write flag."""
    text = ast.unparse(call.args[1]) if len(call.args) > 1 else ""
    return any(f in text for f in ("O_WRONLY", "O_RDWR", "O_CREAT"))


def _from_memory(call: ast.Call) -> bool:
    """Whether the call reads bytes already in memory (``f(io.BytesIO(data))``)."""
    first = call.args[0] if call.args else None
    return isinstance(first, ast.Call) and ast.unparse(first.func).endswith("BytesIO")


def _reads(tree: ast.AST) -> list[tuple[int, str]]:
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call) or _from_memory(node):
            continue
        fn = node.func
        if isinstance(fn, ast.Name):
            name, owner = fn.id, ""
        elif isinstance(fn, ast.Attribute):
            name, owner = fn.attr, ast.unparse(fn.value)
        else:
            continue
        if name == "open" and owner in ("", "io", "builtins", "gzip", "codecs"):
            if not any(c in _mode_of(node) for c in "wax"):
                found.append((node.lineno, "open"))
        elif name == "open" and owner == "os" and not _flags_write(node):
            found.append((node.lineno, "open"))
        elif name == "load" and owner == "json":
            found.append((node.lineno, "json.load"))
        elif name in READ_CALLS and name != "load":
            found.append((node.lineno, name))
        elif name == "load" and owner in ("np", "numpy"):
            found.append((node.lineno, "np.load"))
        elif name == "ZipFile" and node.args and isinstance(node.args[0], ast.Constant):
            found.append((node.lineno, "ZipFile"))
    return found


def test_no_module_but_the_reader_opens_files_for_reading():
    offenders = []
    for path in sorted(CORE.rglob("*.py")):
        if path == READER:
            continue
        rel = path.relative_to(CORE).as_posix()
        for line, what in _reads(ast.parse(path.read_text(encoding="utf-8"))):
            if (rel, what) not in ALLOWED:
                offenders.append(f"{rel}:{line}: {what}")
    assert offenders == [], "read files through meshlap_core.io.reader"


def test_the_scan_finds_reads():
    """The scan itself: it sees each kind of read it looks for."""
    src = (
        "open(p)\nopen(p, 'rb')\nos.open(p, os.O_RDONLY)\njson.load(f)\nnp.load(p)\n"
        "Path(p).read_text()\nPath(p).read_bytes()\nnp.fromfile(p)\n"
        "open(p, 'w')\nos.open(p, os.O_WRONLY | os.O_CREAT)\njson.loads(s)\n"
        "mpimg.imread(io.BytesIO(data))\n"
    )
    assert [line for line, _ in _reads(ast.parse(src))] == [1, 2, 3, 4, 5, 6, 7, 8]


def test_the_limits_are_stated_in_the_docs():
    doc = (Path(__file__).parents[2] / "docs" / "bad-input.md").read_text(encoding="utf-8")
    assert "8 GiB" in doc and "16 MiB" in doc
    assert MESH_SIZE_LIMIT == 8 * 2**30 and JSON_SIZE_LIMIT == 16 * 2**20
    assert SIZE_LIMITS["cache file"] == 8 * 2**30


# ------------------------------------------------------------------ the reader's refusals
def _fifo(tmp_path: Path) -> Path:
    path = tmp_path / "pipe.json"
    os.mkfifo(path)
    return path


def _device(tmp_path: Path) -> Path:
    path = tmp_path / "zero.json"
    path.symlink_to("/dev/zero")
    return path


def _directory(tmp_path: Path) -> Path:
    path = tmp_path / "folder.json"
    path.mkdir()
    return path


KINDS = {
    "fifo": (_fifo, "not a regular file (a named pipe (FIFO))"),
    "device": (_device, "not a regular file (a device)"),
    "directory": (_directory, "is a directory"),
}


@pytest.mark.parametrize("what", ["mesh file", "session file", "cache file"])
@pytest.mark.parametrize("kind", sorted(KINDS))
def test_non_regular_files_are_refused_naming_the_file(tmp_path, kind, what):
    make, words = KINDS[kind]
    path = make(tmp_path)
    for read in (read_input, open_input):
        with pytest.raises(MeshError) as info:
            read(path, what=what)
        assert str(info.value).startswith(f"{path}: ") and words in str(info.value)
        assert "no such file" not in str(info.value)  # a directory or device exists


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_the_loader_says_what_a_mesh_path_is(tmp_path, kind):
    make, _ = KINDS[kind]
    path = make(tmp_path).rename(tmp_path / f"{kind}.obj")
    with pytest.raises(MeshError, match=r"is a directory|not a regular file") as info:
        load_mesh(path)
    assert str(path) in str(info.value) and "no such file" not in str(info.value)


@pytest.mark.parametrize(
    ("what", "limit"), [("mesh file", MESH_SIZE_LIMIT), ("session file", JSON_SIZE_LIMIT)]
)
def test_files_over_the_limit_are_refused_before_reading(tmp_path, what, limit):
    name = "big.obj" if what == "mesh file" else "big.json"
    path = hostile.sparse_file(tmp_path, name, limit + 1)
    with pytest.raises(MeshError, match="may be at most") as info:
        read_input(path, what=what)
    assert str(path) in str(info.value)
    ok = hostile.sparse_file(tmp_path, "ok.bin", 1000)
    assert read_input(ok, what=what) == bytes(1000)


def test_an_oversize_mesh_is_refused_by_every_command_at_once(tmp_path):
    path = hostile.build("oversize.obj", tmp_path)
    for argv in (["info"], ["curvature", "--method", "cotan"], ["spectral", "--k", "2"]):
        res = subprocess.run(
            [sys.executable, "-m", "meshlap_core.cli", argv[0], str(path), *argv[1:]],
            capture_output=True,
            text=True,
            timeout=60,
            cwd=tmp_path,
        )
        assert res.returncode == 2 and res.stdout == ""
        assert res.stderr.count("\n") == 1 and "may be at most 8 GiB" in res.stderr


# ------------------------------------------------------------------ JSON documents
def test_deep_json_is_bad_input(tmp_path):
    path = hostile.deep_json(tmp_path)
    with pytest.raises(MeshError, match="nested too deeply") as info:
        read_json(path)
    assert str(info.value).startswith(f"{path}: ")


def test_a_5000_digit_integer_is_bad_input(tmp_path):
    path = hostile.long_int_json(tmp_path)
    with pytest.raises(MeshError, match="more than 4300 digits") as info:
        read_json(path)
    assert str(info.value).startswith(f"{path}: ") and "set_int_max_str_digits" not in str(
        info.value
    )


def test_read_json_reads_json_and_names_what_is_wrong(tmp_path):
    good = tmp_path / "s.json"
    good.write_text('{"version": 1, "panel": "spectral", "k": [1, 2.5]}')
    assert read_json(good) == {"version": 1, "panel": "spectral", "k": [1, 2.5]}
    bad = tmp_path / "b.json"
    bad.write_text('{"version": 1,\n "k": }')
    with pytest.raises(MeshError, match=r"not JSON \(Expecting value at line 2, column 7\)"):
        read_json(bad)
    latin = tmp_path / "l.json"
    latin.write_bytes('{"n": "é"}'.encode("latin-1"))
    with pytest.raises(MeshError, match="not UTF-8"):
        read_json(latin)


def test_a_json_fifo_does_not_hang(tmp_path):
    """``--session`` pointed at a FIFO or /dev/zero: refused at once, nothing read."""
    for make in (_fifo, _device):
        with pytest.raises(MeshError, match="not a regular file"):
            read_json(make(tmp_path))


# ------------------------------------------------------------------ the cache reads through it
def test_the_cache_reader_refuses_special_files(tmp_path):
    from meshlap_core.spectral.cache import load_entry

    for make in (_fifo, _device, _directory):
        with pytest.raises(MeshError, match=r"not a regular file|is a directory"):
            load_entry(make(tmp_path), 12)


def test_every_reader_entry_point_uses_the_reader(tmp_path, monkeypatch):
    """Behavioural: the mesh loader, the cache and read_json all open through
    :func:`open_input` (counted while each reads a good file)."""
    import meshlap_core.io.reader as reader
    from meshlap_core import SpectralBasis

    seen: list[str] = []
    real = reader.open_input

    def spy(path, **kw):
        seen.append(kw.get("what", "mesh file"))
        return real(path, **kw)

    monkeypatch.setattr(reader, "open_input", spy)
    V, F = primitives.icosphere(1)
    mesh = tmp_path / "m.obj"
    meshlap_core.save_mesh(mesh, V, F)
    load_mesh(mesh)
    SpectralBasis.compute(V, F, 3, cache_dir=tmp_path / "cache")
    SpectralBasis.compute(V, F, 3, cache_dir=tmp_path / "cache")  # read back from the cache
    basis_file = tmp_path / "b.npz"
    SpectralBasis.compute(V, F, 3, cache=False).save(basis_file)
    SpectralBasis.load(basis_file, V, F)
    session = tmp_path / "s.json"
    session.write_text("{}")
    read_json(session)
    assert seen.count("mesh file") == 1 and seen.count("session file") == 1
    assert seen.count("cache file") >= 2
    assert np.isfinite(V).all()
