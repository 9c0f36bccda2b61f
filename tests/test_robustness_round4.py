"""Hostile round 4 on the commands added in wave 3 (``geodesic``, ``heat``, ``filter``,
``curvature --estimator``, ``curvature-study``, ``exercises init``): every case that crashed,
hung, blew up or said something misleading, each with the fix's promise. Commands run in
process (``main``) unless a native library could crash the interpreter: those run in a
subprocess, so that a segfault fails the test instead of killing pytest.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from meshlap_core.cli import main


def _error(capsys) -> str:
    """The last line on stderr (the command's one error line)."""
    err = capsys.readouterr().err.strip()
    return err.splitlines()[-1] if err else ""


# ------------------------------------------------------------------ exercises init


def test_exercises_init_refuses_an_empty_folder_name(tmp_path, monkeypatch, capsys):
    """``exercises init ''`` once wrote into the current folder (``Path('')`` is ``.``)."""
    monkeypatch.chdir(tmp_path)
    assert main(["exercises", "init", ""]) == 2
    line = _error(capsys)
    assert line.startswith("meshlap: error: DIR:") and "empty" in line
    assert os.listdir(tmp_path) == []
    assert main(["exercises", "init", "  "]) == 2 and os.listdir(tmp_path) == []
    assert main(["exercises", "init", "sub"]) == 0 and (Path("sub") / "exercises.py").is_file()
