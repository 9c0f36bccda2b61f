"""The wall between a student's process and the checker: the harness imports no meshlap
module, nothing crossing back is unpickled, every reply and answer is checked before it is
believed, and nothing the student started outlives the check."""

from __future__ import annotations

import ast
import io
import json
import os
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

from meshlap_core.exercises import geodesic_task as geo
from meshlap_core.exercises.isolation import TOKEN_ENV, sweep
from meshlap_core.exercises.meshes import Case
from meshlap_core.exercises.plain import (
    BadAnswer,
    Tampered,
    parse_reply,
    read_answer,
    unpack,
)
from meshlap_core.primitives import icosphere

PACKAGE = Path(__file__).resolve().parents[2] / "meshlap_core" / "exercises"
STDLIB = set(sys.stdlib_module_names) | {"__future__"}


def test_the_harness_imports_no_meshlap_module():
    """The harness is the only code beside the student's: its imports are the standard
    library's (numpy, scipy and libigl are loaded by name, before the student's clock)."""
    tree = ast.parse((PACKAGE / "harness.py").read_text())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, "a relative import in the harness"
            names.add((node.module or "").split(".")[0])
    assert names <= STDLIB | {"numpy", "scipy"}, names - STDLIB


def test_nothing_from_the_student_is_ever_unpickled():
    """No module of the checker imports pickle, and every ``np.load`` refuses pickles."""
    for path in PACKAGE.glob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                assert all("pickle" not in a.name for a in node.names), path.name
            func = node.func if isinstance(node, ast.Call) else None
            if (
                isinstance(func, ast.Attribute)
                and func.attr == "load"
                and getattr(func.value, "id", "") in ("np", "numpy")
            ):
                kw = {k.arg: k.value for k in node.keywords}
                assert isinstance(kw.get("allow_pickle"), ast.Constant), path.name
                assert kw["allow_pickle"].value is False, path.name


def _npz(path: Path, **arrays) -> Path:
    np.savez(path, **arrays)
    return path


def test_an_answer_is_read_as_plain_numbers_or_refused(tmp_path):
    good = _npz(tmp_path / "good.npz", value=np.arange(6.0).reshape(2, 3))
    assert np.array_equal(
        read_answer(good, "array", 1 << 20)["value"], np.arange(6.0).reshape(2, 3)
    )
    objects = tmp_path / "objects.npz"
    np.savez(objects, value=np.array([{"a": 1}], dtype=object))  # a pickle inside
    compressed = tmp_path / "compressed.npz"
    np.savez_compressed(compressed, value=np.zeros(10))
    bomb = tmp_path / "bomb.npz"  # a header that promises 8 TB over 8 bytes of data
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buf, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)}
    )
    with zipfile.ZipFile(bomb, "w") as z:
        z.writestr("value.npy", buf.getvalue() + bytes(8))
    cases = [
        (objects, "array", "not numbers"),
        (compressed, "array", "compressed"),
        (bomb, "array", "shape"),
        (good, "pair", "members"),
        (_npz(tmp_path / "big.npz", value=np.zeros(1000)), "array", "size cap"),
        (tmp_path / "missing.npz", "array", "no answer file"),
    ]
    for path, tag, why in cases:
        with pytest.raises(ValueError, match=why):
            read_answer(path, tag, 4000 if "big" in path.name else 1 << 20)


def test_a_sparse_answer_is_checked_entry_by_entry():
    ok = {"data": np.ones(2), "indices": np.array([0, 1]), "indptr": np.array([0, 1, 2]),
          "shape": np.array([2, 2])}  # fmt: skip
    assert unpack("sparse", ok).toarray().tolist() == [[1.0, 0.0], [0.0, 1.0]]
    for broken in (
        {**ok, "indices": np.array([0, 5])},  # a column out of range
        {**ok, "indptr": np.array([0, 2, 1])},  # a row pointer going back
        {**ok, "shape": np.array([2, 2, 2])},
        {**ok, "indices": np.array([0.5, 1.0])},
    ):
        assert isinstance(unpack("sparse", broken), BadAnswer)
    assert unpack("none", {}).key == "no_answer"


def test_a_reply_is_believed_only_in_its_exact_form():
    good = {"ev": "answer", "id": 3, "tag": "array", "hot": [["f.py", 12, 4]], "nonce": "ab"}
    assert parse_reply(json.dumps(good).encode()) == good
    for bad in (
        b"not json",
        json.dumps({"ev": "finished", "nonce": "ab"}).encode(),  # no such reply
        json.dumps({**good, "extra": 1}).encode(),
        json.dumps({k: v for k, v in good.items() if k != "nonce"}).encode(),
        json.dumps({**good, "id": "3"}).encode(),
        json.dumps({**good, "id": True}).encode(),
        json.dumps({**good, "tag": "pickle"}).encode(),
        json.dumps({**good, "hot": [["f.py", "12", 4]]}).encode(),
        b"[" * 300_000,
    ):
        with pytest.raises(Tampered):
            parse_reply(bad)


def _descendants_alive(token: str) -> list[int]:
    found = []
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            try:
                with open(f"{entry.path}/environ", "rb") as f:
                    if f"{TOKEN_ENV}={token}".encode() in f.read():
                        with open(f"{entry.path}/stat") as s:
                            if s.read().rsplit(")", 1)[1].split()[0] != "Z":
                                found.append(int(entry.name))
            except OSError:
                continue
    return found


def test_the_end_of_a_check_kills_every_process_that_carries_its_token():
    """A worker whose child left the process group (``setsid``) and whose grandchild was
    orphaned: killing the worker's group alone leaves them running (the old end of a check);
    the sweep finds them by the token in their environment."""
    token = "test-sweep-token"
    script = (
        "import os, time\n"
        "if os.fork() == 0:\n"
        "    os.setsid()\n"
        "    if os.fork() == 0:\n"
        "        time.sleep(60)\n"
        "    os._exit(0)\n"
        "time.sleep(60)\n"
    )
    env = dict(os.environ, **{TOKEN_ENV: token})
    proc = subprocess.Popen([sys.executable, "-c", script], env=env, start_new_session=True)
    deadline = time.monotonic() + 30
    while len(_descendants_alive(token)) < 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert len(_descendants_alive(token)) >= 2  # the worker and its setsid child's child
    sweep(proc.pid, token)
    proc.wait(10)
    assert _descendants_alive(token) == []


def test_a_second_piece_is_not_called_heat_underflow():
    """A mesh of two separate spheres: the heat never reaches the second by topology, not by
    underflow (before, the note blamed the heat's underflow)."""
    V, F = icosphere(2)
    V2 = np.vstack([V, V + np.array([5.0, 0.0, 0.0])])
    F2 = np.vstack([F, F + len(V)])
    case = Case("two", V2, F2, "two spheres")
    ((_, args),) = geo.heat_calls(case)
    reason = geo.heat_not_judged(case, args)
    assert "2 separate pieces" in reason and "underflow" not in reason


def test_a_killed_checkers_temporary_folder_is_removed_by_the_next(tmp_path, monkeypatch):
    """A viewer killed during a check never runs its exit handler: its session's folder (the
    battery's inputs) is removed by the next session, not left in /tmp."""
    import tempfile

    from meshlap_core.exercises.worker import PREFIX, Session

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    orphan = tmp_path / f"{PREFIX}{dead.pid}-abc"
    (orphan / "in").mkdir(parents=True)
    alive = tmp_path / f"{PREFIX}{os.getpid()}-def"
    alive.mkdir()
    with Session("process") as session:
        assert session.root.parent == tmp_path
        assert not orphan.exists() and alive.exists()
