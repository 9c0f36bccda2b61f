"""Robustness (issue 8) through the real entry point, in child processes with a timeout.

What only a separate process can show: nothing hangs (a FIFO or ``/dev/zero`` given as MESH),
no Python traceback reaches the terminal, and ``view --screenshot`` (polyscope, EGL) fails in
one line on a bad file and renders the hostile-but-valid ones. The in-process tests in
``test_commands.py`` cover the whole corpus; here a few representatives run for real.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support import hostile

TIMEOUT = 120  # seconds; every run here takes a few


def meshlap(*argv, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    """``python -m meshlap_core.cli ARGV`` in ``cwd`` (a TimeoutExpired fails the test)."""
    return subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
        cwd=cwd,
        env={**os.environ, "MESHLAP_CACHE_DIR": str(cwd / "cache"), **(env or {})},
        stdin=subprocess.DEVNULL,
    )


def assert_one_line(res: subprocess.CompletedProcess, *names: str) -> str:
    assert res.returncode == 2, (res.returncode, res.stderr)
    assert "Traceback" not in res.stderr
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("meshlap: error: "), res.stderr
    assert all(n in lines[0] for n in names), (names, lines[0])
    return lines[0]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs POSIX FIFOs and /dev/zero")
@pytest.mark.parametrize("case", hostile.SPECIAL, ids=lambda h: h.name)
def test_special_files_do_not_hang(tmp_path, case):
    """A FIFO would block the reader forever and /dev/zero never ends: both are refused."""
    path = case.build(tmp_path)
    res = meshlap("info", path, cwd=tmp_path)
    line = assert_one_line(res, str(path))
    assert any(w in line for w in case.words)


@pytest.mark.parametrize(
    "argv",
    [
        ["curvature", "{bad}", "--out", "{tmp}/k.csv"],
        ["smooth", "{bad}", "--out", "{tmp}/s.obj"],
        ["denoise-eval", "{bad}", "--csv", "{tmp}/t.csv"],
        ["surface", "helicoid", "--u", "99"],
        ["onering", "{good}", "--vertex", "4"],
    ],
    ids=["curvature", "smooth", "denoise-eval", "surface", "onering-vertex"],
)
def test_no_traceback_from_the_entry_point(tmp_path, argv):
    bad = hostile.build("truncated.ply", tmp_path)
    good = hostile.build("relative.obj", tmp_path)
    res = meshlap(*[a.format(bad=bad, good=good, tmp=tmp_path) for a in argv], cwd=tmp_path)
    assert_one_line(res)
    assert res.stdout == ""
    assert not any(tmp_path.glob("[kst].*")) and not any(tmp_path.glob(".*.tmp"))


# ------------------------------------------------------------------------ view --screenshot


def test_view_bad_file_keeps_the_existing_screenshot(tmp_path):
    """A bad MESH fails before polyscope starts (no EGL needed); the old PNG stays."""
    shot = tmp_path / "shot.png"
    shot.write_bytes(b"previous screenshot")
    for name in ("garbage.ply", "index_oob.obj", "empty.obj"):
        bad = hostile.build(name, tmp_path)
        res = meshlap("view", bad, "--screenshot", shot, cwd=tmp_path)
        assert_one_line(res, bad.name)
        assert shot.read_bytes() == b"previous screenshot"
    missing = tmp_path / "nowhere" / "shot.png"
    res = meshlap("view", bad, "--screenshot", missing, cwd=tmp_path)
    assert "does not exist" in assert_one_line(res)


@functools.cache
@pytest.mark.egl
@pytest.mark.parametrize(
    ("name", "panel"),
    [("nonmanifold_edge.obj", "curvature"), ("single_triangle.obj", "smoothing")],
)
def test_view_screenshot_of_hostile_but_valid_meshes(tmp_path, name, panel):
    import matplotlib.image as mpimg

    mesh = hostile.build(name, tmp_path)
    shot = tmp_path / "shot.png"
    shot.write_bytes(b"previous screenshot")  # replaced by a complete PNG
    res = meshlap("view", mesh, "--screenshot", shot, "--panel", panel, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "Traceback" not in res.stderr
    img = mpimg.imread(shot)
    assert img.ndim == 3 and img.shape[0] > 100 and img.shape[1] > 100
    assert not any(tmp_path.glob(".*.tmp"))
