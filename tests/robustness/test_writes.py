"""Hostile round 3, class test: no command writes anywhere the user did not name.

Each command runs in an empty current directory with its outputs in another folder, the
cache in a third (``MESHLAP_CACHE_DIR``) and ``HOME`` / config folders in a fourth; afterwards
the current directory must still be empty. The current directory is writable, so that a
silent write (a library's ``.ini`` file) shows up. A second test runs commands in a read-only
current directory: the tests run as root, for whom mode 555 is still writable, so there each
command runs as ``nobody`` (``setpriv``, where available) and must succeed.

``view --screenshot`` and ``animate`` need EGL (marked ``egl``): they once rewrote
``./imgui.ini`` (issue 22); the viewer now keeps its layout in its config folder. ``report`` is
left out (two minutes; it works inside its ``--out`` folder).
"""

from __future__ import annotations

import functools
import os
import pwd
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from meshlap_core import primitives, save_mesh

AS_NOBODY = os.geteuid() == 0 and shutil.which("setpriv") is not None


def _as_nobody() -> list[str]:
    """The ``setpriv`` prefix that runs a command as ``nobody``."""
    user = pwd.getpwnam("nobody")
    return ["setpriv", f"--reuid={user.pw_uid}", f"--regid={user.pw_gid}", "--clear-groups"]


@functools.cache
def nobody_cannot_run_meshlap() -> str | None:
    """Why ``nobody`` cannot run this checkout's meshlap (``None``: it can). A checkout
    cloned into a private folder (``mktemp -d``: mode 700) keeps its interpreter, venv and
    sources out of that user's reach; then the tests that run commands as ``nobody`` have
    nothing to test and skip, saying so."""
    if not AS_NOBODY:
        return "needs root and setpriv to run as nobody"
    try:
        res = subprocess.run(
            [*_as_nobody(), sys.executable, "-c", "import meshlap_core.cli"],
            capture_output=True,
            text=True,
            timeout=120,
            cwd="/",
        )
    except (OSError, subprocess.SubprocessError) as exc:
        return f"cannot start Python as nobody: {exc}"
    if res.returncode != 0:
        last = (res.stderr.strip().splitlines() or ["(no message)"])[-1]
        return (
            f"the user nobody cannot run {sys.executable} with this checkout (a parent "
            f"folder is private?): {last}"
        )
    return None


COMMANDS: dict[str, list[str]] = {
    "info": ["info", "{mesh}", "--json"],
    "info-missing": ["info", "missing.obj"],
    "curvature": ["curvature", "{mesh}", "--method", "k1", "--out", "{out}/k.csv"],
    "onering": ["onering", "{mesh}", "--vertex", "3", "--json"],
    "inspect": ["inspect", "{mesh}", "--vertex", "3", "--area", "voronoi"],
    "surface": [
        "surface",
        "saddle",
        "--plot",
        "{out}/kn.png",
        "--mesh",
        "{out}/s.obj",
        "--res",
        "8",
    ],
    "surface-convergence": ["surface", "sphere", "--convergence", "--res", "4,8"],
    "spectral": [
        "spectral",
        "{mesh}",
        "--k",
        "6",
        "--reconstruct",
        "2,6",
        "--out",
        "{out}/b.npz",
        "--save-reconstruction",
        "{out}/rec",
    ],
    "smooth": [
        "smooth",
        "{mesh}",
        "--method",
        "implicit",
        "--lam",
        "0.5",
        "--iters",
        "3",
        "--out",
        "{out}/s.obj",
    ],
    "denoise-eval": ["denoise-eval", "{mesh}", "--iters", "1", "--csv", "{out}/d.csv"],
}
EGL_COMMANDS: dict[str, list[str]] = {
    "view-screenshot": ["view", "{mesh}", "--screenshot", "{out}/v.png"],
    "animate": [
        "animate",
        "{mesh}",
        "--panel",
        "smoothing",
        "--iters",
        "2",
        "--size",
        "128x96",
        "--out",
        "{out}/a.gif",
    ],
}
EXIT = {"info-missing": 2}


@pytest.fixture
def places() -> Iterator[dict[str, Path]]:
    """cwd (empty, 555), out, cache, home: under /tmp so that ``nobody`` can reach them."""
    base = Path(tempfile.mkdtemp(prefix="meshlap-nowrite-", dir="/tmp"))
    base.chmod(0o755)
    dirs = {name: base / name for name in ("cwd", "out", "cache", "home")}
    for d in dirs.values():
        d.mkdir()
        d.chmod(0o777)
    mesh = base / "sphere.obj"
    save_mesh(mesh, *primitives.icosphere(1))
    mesh.chmod(0o644)
    dirs["mesh"] = mesh
    try:
        yield dirs
    finally:
        shutil.rmtree(base, ignore_errors=True)


def _env(places: dict[str, Path]) -> dict[str, str]:
    home = places["home"]
    return {
        "HOME": str(home),
        "XDG_CONFIG_HOME": str(home / ".config"),
        "XDG_CACHE_HOME": str(home / ".cache"),
        "MPLCONFIGDIR": str(home / "mpl"),
        "MESHLAP_CACHE_DIR": str(places["cache"]),
    }


def _run(argv: list[str], places: dict[str, Path]) -> subprocess.CompletedProcess[str]:
    args = [a.format(mesh=places["mesh"], out=places["out"]) for a in argv]
    env = {**os.environ, **_env(places)}
    prefix: list[str] = []
    if AS_NOBODY:
        if (why := nobody_cannot_run_meshlap()) is not None:
            pytest.skip(why)
        prefix = _as_nobody()
    return subprocess.run(
        [*prefix, sys.executable, "-m", "meshlap_core.cli", *args],
        capture_output=True,
        text=True,
        timeout=180,
        cwd=places["cwd"],
        env=env,
    )


def _check(name: str, argv: list[str], places: dict[str, Path]) -> None:
    res = _run(argv, places)
    assert res.returncode == EXIT.get(name, 0), res.stderr
    assert sorted(os.listdir(places["cwd"])) == [], "wrote into the current directory"
    leftovers = [p for p in places["out"].rglob("*") if ".tmp" in p.name]
    assert leftovers == []


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_commands_write_only_where_named(name, places, monkeypatch, capsys):
    """In-process (fast): the same environment, ``main`` run with the empty cwd."""
    from meshlap_core.cli import main

    home = places["home"]
    monkeypatch.chdir(places["cwd"])
    for key, value in _env(places).items():
        monkeypatch.setenv(key, value)
    args = [a.format(mesh=places["mesh"], out=places["out"]) for a in COMMANDS[name]]
    code = main(args)
    err = capsys.readouterr().err
    assert code == EXIT.get(name, 0), err
    assert sorted(os.listdir(places["cwd"])) == [], "wrote into the current directory"
    assert [p for p in places["out"].rglob("*") if ".tmp" in p.name] == []
    if name == "spectral":
        assert list(places["cache"].iterdir()), "the basis goes to the cache folder"
    assert not (home / ".cache").exists() or name == "spectral"


@pytest.mark.egl
@pytest.mark.parametrize("name", sorted(EGL_COMMANDS))
def test_rendering_commands_write_only_where_named(name, places):
    _check(name, EGL_COMMANDS[name], places)


@pytest.mark.skipif(not AS_NOBODY, reason="needs root and setpriv to run as nobody")
@pytest.mark.parametrize("name", ["spectral", "surface", "info-missing"])
def test_commands_work_in_a_read_only_directory(name, places):
    if (why := nobody_cannot_run_meshlap()) is not None:
        pytest.skip(why)
    places["cwd"].chmod(0o555)
    _check(name, COMMANDS[name], places)


@pytest.mark.skipif(not AS_NOBODY, reason="needs root and setpriv to run as nobody")
def test_a_checkout_nobody_cannot_reach_is_a_skip_with_its_reason(tmp_path, monkeypatch):
    """A clone in a private folder (``mktemp -d``, mode 700): the interpreter is out of
    nobody's reach, so the as-nobody tests skip saying why instead of failing."""
    private = tmp_path / "private"
    private.mkdir(mode=0o700)
    (private / "python").symlink_to(sys.executable)
    monkeypatch.setattr(sys, "executable", str(private / "python"))
    nobody_cannot_run_meshlap.cache_clear()
    try:
        why = nobody_cannot_run_meshlap()
    finally:
        nobody_cannot_run_meshlap.cache_clear()
    assert why is not None and "nobody cannot run" in why and str(private) in why
