"""What reaches the terminal under hostile conditions: a stream that cannot encode Greek gets
ASCII spellings, a closed stdout or stderr keeps the exit codes (an error, not a crash), and
control characters in a file name are escaped in messages."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from meshlap_core import MeshError, primitives
from meshlap_core.cli import main

V, F = primitives.icosphere(1)


PY = shlex.quote(sys.executable)


def _sh(cmd: str, cwd: Path, **env: str) -> subprocess.CompletedProcess[str]:
    """``cmd`` in a shell (to close descriptors with ``>&-``), ``meshlap`` meaning this
    interpreter's ``-m meshlap_core.cli``."""
    full = cmd.replace("meshlap ", f"{PY} -m meshlap_core.cli ")
    return subprocess.run(
        ["/bin/sh", "-c", full],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=cwd,
        env={**os.environ, **env},
    )


@pytest.mark.parametrize(
    "env",
    [
        {"PYTHONIOENCODING": "ascii"},
        {"PYTHONIOENCODING": "latin-1"},
        {"LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"},
    ],
)
def test_a_stream_that_cannot_encode_greek_gets_ascii_spellings(mesh, tmp_path, env):
    res = _sh(f"meshlap info {mesh}", tmp_path, **env)
    assert res.returncode == 0, res.stderr
    assert "chi" in res.stdout and "Traceback" not in res.stderr


def test_the_ascii_fallback_spells_each_symbol():
    from meshlap_core.cli import ASCII_SPELLINGS

    text = "χ λ κ ≤ ≥ ν"
    assert text.encode("ascii", errors="meshlap-ascii") == b"chi lambda kappa <= >= nu"
    assert "🙂".encode("ascii", errors="meshlap-ascii") == b"?"
    assert all(v.isascii() for v in ASCII_SPELLINGS.values())


def test_closed_stderr_keeps_exit_code_2(tmp_path):
    res = _sh("meshlap info missing.obj 2>&-", tmp_path)
    assert res.returncode == 2 and res.stdout == ""


def test_closed_stdout_is_an_error_not_a_crash(mesh, tmp_path):
    res = _sh(f"meshlap inspect {mesh} --vertex 3 --json >&-", tmp_path)
    assert res.returncode == 2
    assert res.stderr.splitlines() == [
        "meshlap: error: <stdout>: standard output is closed; the output was not written"
    ]


def test_closed_stdout_on_bad_input_is_still_2(tmp_path):
    res = _sh("meshlap info missing.obj >&-", tmp_path)
    assert res.returncode == 2 and "no such file" in res.stderr


@pytest.mark.parametrize(
    "name", ["a\x1b[31mred\x1b[0m.obj", "bell\x07.obj", "rtl\u202e.obj", "cr\rline.obj"]
)
def test_control_characters_in_a_file_name_are_escaped(name, capsys, tmp_path):
    code = main(["info", str(tmp_path / name)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert err.isprintable() or (err.endswith("\n") and err[:-1].isprintable())
    assert "\x1b" not in err and "\x07" not in err and "no such file" in err


def test_printable_escapes_what_the_terminal_would_act_on():
    from meshlap_core.errors import printable

    assert printable("a\x00b\x1b[2Jc\udcff.obj") == "a\\x00b\\x1b[2Jc\\udcff.obj"
    assert printable("χ é 漢.obj") == "χ é 漢.obj"
    err = MeshError("bad", "x\x1b.obj")
    assert str(err) == "x\\x1b.obj: bad" and err.source == "x\x1b.obj"
