"""Hostile round 4, class test: the one rule for outputs.

Every output flag of every command is pointed at a name in the case folder that is already
taken by a symbolic link (to a "victim" file), a device node, a FIFO or a directory:

- a link is replaced by the new file itself, never written through: the victim keeps its
  bytes and mode, and the new file has the mode the umask gives (not the victim's);
- a device node, a FIFO or a directory is refused (exit 2, one line naming the path and what
  it is) and left as it was: nothing is written into it, and no command waits on a FIFO.

No temporary file is left behind. Device nodes need root (``os.mknod``); elsewhere those cases
skip saying so. ``view --screenshot`` and ``animate --out`` run in a subprocess on EGL
(marked ``egl``); ``report --out`` (a folder, two minutes of work) is in the folder test.
"""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from meshlap_core import primitives, save_mesh
from meshlap_core.cli import main

STUDY = ["curvature-study", "--surfaces", "sphere", "--estimators", "cotan", "--levels", "6,8"]
ANIMATE = ["animate", "{mesh}", "--panel", "smoothing", "--iters", "2", "--size", "96x64"]

# (command, output flag) -> (argv with {mesh}, {out}, {case}, {student}; suffix; exit code)
OUTPUTS: dict[str, tuple[list[str], str, int]] = {
    "curvature --out": (["curvature", "{mesh}", "--out", "{out}"], ".csv", 0),
    "curvature --directions": (
        ["curvature", "{mesh}", "--estimator", "rusinkiewicz", "--directions", "{out}"],
        ".npy",
        0,
    ),
    "curvature-study --csv": (
        [*STUDY, "--csv", "{out}"],
        ".csv",
        0,
    ),
    "curvature-study --figure": (
        [*STUDY, "--figure", "{out}"],
        ".png",
        0,
    ),
    "denoise-eval --csv": (["denoise-eval", "{mesh}", "--iters", "1", "--csv", "{out}"], ".csv", 0),
    "filter --out": (
        ["filter", "{mesh}", "--k", "10", "--low-pass", "5", "--no-cache", "--out", "{out}"],
        ".obj",
        0,
    ),
    "geodesic --out": (["geodesic", "{mesh}", "--vertex", "0", "--out", "{out}"], ".npy", 0),
    "geodesic --curves": (
        ["geodesic", "{mesh}", "--vertex", "0", "--isolines", "3", "--curves", "{out}"],
        ".obj",
        0,
    ),
    "heat --out": (["heat", "{mesh}", "--vertex", "0", "--t", "0.01", "--out", "{out}"], ".npy", 0),
    "heat --curves": (
        ["heat", "{mesh}", "--vertex", "0", "--t", "0.01", "--isolines", "3", "--curves", "{out}"],
        ".obj",
        0,
    ),
    "smooth --out": (["smooth", "{mesh}", "--iters", "1", "--out", "{out}"], ".obj", 0),
    "spectral --out": (
        ["spectral", "{mesh}", "--k", "6", "--no-cache", "--out", "{out}"],
        ".npz",
        0,
    ),
    "surface --plot": (["surface", "saddle", "--plot", "{out}"], ".png", 0),
    "surface --mesh": (["surface", "saddle", "--res", "8", "--mesh", "{out}"], ".obj", 0),
    # the file is DIR/exercises.py: {out} is that name in the case folder
    "exercises init": (["exercises", "init", "{case}", "--force"], "exercises.py", 0),
    # the stub's task is not implemented: exit 3, and the report is still written
    "check --junit": (
        ["check", "{student}", "--task", "uniform_laplacian", "--junit", "{out}"],
        ".xml",
        3,
    ),
}
EGL_OUTPUTS: dict[str, tuple[list[str], str, int]] = {
    "view --screenshot": (["view", "{mesh}", "--screenshot", "{out}"], ".png", 0),
    "animate --out": (
        [*ANIMATE, "--out", "{out}"],
        ".gif",
        0,
    ),
}
KINDS = ["link", "device", "fifo", "directory"]
UMASK = 0o022
VICTIM_MODE = 0o604  # unusual, so that a mode copied through the link shows


@pytest.fixture
def case(tmp_path: Path, monkeypatch) -> Iterator[dict[str, Path]]:
    """The case folder (the outputs), a mesh and a student file beside it, a set umask, and
    every cache and config folder in tmp."""
    places = {"case": tmp_path / "case", "mesh": tmp_path / "sphere.obj"}
    places["case"].mkdir()
    save_mesh(places["mesh"], *primitives.icosphere(2))
    student = tmp_path / "student"
    student.mkdir()
    assert main(["exercises", "init", str(student)]) == 0
    places["student"] = student / "exercises.py"
    for key, sub in (("MESHLAP_CACHE_DIR", "cache"), ("XDG_CONFIG_HOME", "config")):
        monkeypatch.setenv(key, str(tmp_path / sub))
    monkeypatch.setenv("MPLCONFIGDIR", str(tmp_path / "mpl"))
    old = os.umask(UMASK)
    try:
        yield places
    finally:
        os.umask(old)


def _argv(template: list[str], places: dict[str, Path], out: Path) -> list[str]:
    return [
        a.format(mesh=places["mesh"], out=out, case=places["case"], student=places["student"])
        for a in template
    ]


def _out_path(places: dict[str, Path], suffix: str) -> Path:
    name = suffix if not suffix.startswith(".") else f"out{suffix}"
    return places["case"] / name


def _occupy(out: Path, kind: str) -> Path | None:
    """Put a ``kind`` at ``out``; returns the victim file of a link."""
    if kind == "link":
        victim = out.with_name("victim" + (out.suffix or ".txt"))
        victim.write_bytes(b"victim")
        victim.chmod(VICTIM_MODE)
        out.symlink_to(victim.name)
        return victim
    if kind == "device":
        if os.geteuid() != 0:
            pytest.skip("making a device node (os.mknod) needs root")
        os.mknod(out, stat.S_IFCHR | 0o666, os.makedev(1, 3))  # a /dev/null
    elif kind == "fifo":
        os.mkfifo(out)
    else:
        out.mkdir()
    return None


class _Hang(Exception):
    pass


def _run_in_process(argv: list[str], seconds: int = 120) -> int:
    """``main(argv)``, interrupted (a test failure, not a stuck run) if it blocks, e.g. on a
    FIFO that nobody reads."""

    def hang(signum, frame):
        raise _Hang(f"{' '.join(argv)} did not return within {seconds} s (blocked?)")

    old = signal.signal(signal.SIGALRM, hang)
    signal.alarm(seconds)
    try:
        return main(argv)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _check_outcome(kind, out, victim, code, err, want_code, places):
    leftovers = [p.name for p in places["case"].iterdir() if ".tmp" in p.name]
    assert leftovers == [], "temporary files left behind"
    if kind == "link":
        assert code == want_code, err
        assert out.is_file() and not out.is_symlink(), "the link was written through"
        assert victim.read_bytes() == b"victim", "the link's target was overwritten"
        assert stat.S_IMODE(victim.stat().st_mode) == VICTIM_MODE
        assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~UMASK, "mode not from the umask"
        assert out.stat().st_size > 0
        return
    assert code == 2, err
    line = err.strip().splitlines()[-1] if err.strip() else ""
    assert line.startswith("meshlap: error:") and out.name in line, err
    what = {"device": "device", "fifo": "FIFO", "directory": "directory"}[kind]
    assert what in line, err
    mode = os.lstat(out).st_mode
    test = {"device": stat.S_ISCHR, "fifo": stat.S_ISFIFO, "directory": stat.S_ISDIR}[kind]
    assert test(mode), f"the {kind} was replaced"
    if kind == "directory":
        assert list(out.iterdir()) == [], "wrote into the directory"


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("flag", sorted(OUTPUTS))
def test_every_output_flag_replaces_a_link_and_refuses_special_files(flag, kind, case, capsys):
    template, suffix, want = OUTPUTS[flag]
    out = _out_path(case, suffix)
    victim = _occupy(out, kind)
    code = _run_in_process(_argv(template, case, out))
    err = capsys.readouterr().err
    _check_outcome(kind, out, victim, code, err, want, case)


@pytest.mark.egl
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("flag", sorted(EGL_OUTPUTS))
def test_rendering_outputs_replace_a_link_and_refuse_special_files(flag, kind, case):
    template, suffix, want = EGL_OUTPUTS[flag]
    out = _out_path(case, suffix)
    victim = _occupy(out, kind)
    res = subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", *_argv(template, case, out)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=case["case"].parent,
    )
    _check_outcome(kind, out, victim, res.returncode, res.stderr, want, case)


@pytest.mark.parametrize("kind", ["device", "fifo", "file"])
@pytest.mark.parametrize(
    "flag",
    [
        ["spectral", "{mesh}", "--k", "6", "--no-cache", "--save-reconstruction", "{out}"],
        ["report", "--out", "{out}"],
    ],
    ids=["spectral --save-reconstruction", "report --out"],
)
def test_folder_outputs_refuse_a_special_file_or_a_file(flag, kind, case, capsys):
    """``--save-reconstruction`` and ``report --out`` name a folder: a device, a FIFO or a
    file there is refused before any work (a link to a folder is a folder)."""
    out = case["case"] / "folder"
    if kind == "file":
        out.write_bytes(b"not a folder")
    else:
        _occupy(out, kind)
    code = _run_in_process(_argv(flag, case, out))
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("meshlap: error:") and "folder" in err.splitlines()[-1], err
    assert not os.path.isdir(out)


@pytest.mark.parametrize("kind", KINDS)
def test_the_viewers_writers_follow_the_same_rule(kind, case, polyscope_mock):
    """The viewer's own writers: a session file (``write_session``), the Export section's
    files (``save_mesh`` / ``save_scalars``) and a screenshot PNG (``scene.write_png``): a
    link is replaced, a device, FIFO or directory refused and left as it was."""
    import numpy as np
    from meshlap_app.scene import write_png
    from meshlap_app.state.session import Session, write_session

    from meshlap_core.errors import MeshError
    from meshlap_core.io import save_scalars

    V, F = primitives.icosphere(1)
    writers = {
        ".json": lambda p: write_session(p, Session()),
        ".ply": lambda p: save_mesh(p, V, F, scalars=V[:, 0]),
        ".csv": lambda p: save_scalars(p, V[:, 0]),
        ".png": lambda p: write_png(p, np.zeros((4, 4, 4), dtype=np.uint8)),
    }
    for suffix, write in writers.items():
        out = case["case"] / f"app{suffix}"
        victim = _occupy(out, kind)
        if kind == "link":
            write(out)
            _check_outcome(kind, out, victim, 0, "", 0, case)
        else:
            with pytest.raises(MeshError) as err:
                write(out)
            _check_outcome(kind, out, None, 2, f"meshlap: error: {err.value}", 2, case)
