"""Hostile round 3, class test: faults injected around every writer of the core.

Each writer (``save_mesh``, ``save_scalars``, the spectral basis file and cache entry, the
κₙ(θ) plot, the GIF writer, the denoising CSV, and the atomic layer itself in text and binary
mode) is run over an existing file while one step of the atomic write fails with ENOSPC,
EACCES, EROFS or EPIPE: the open of the temporary file, a write, the flush, the fsync or the
rename. Every time the old file must be intact, no temporary file may be left, and the error
must be a :class:`MeshError` naming the target and the cause in words.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from meshlap_core import MeshError, SpectralBasis, primitives, save_mesh, save_scalars
from meshlap_core.io import atomic_write
from meshlap_core.io.animation import FrameWriter

V, F = primitives.icosphere(1)
OLD = b"old contents, not to be lost\n"
CAUSES = {
    errno.ENOSPC: "no space left on device",
    errno.EACCES: "permission denied",
    errno.EROFS: "read-only file system",
    errno.EPIPE: "broken pipe",
}
STEPS = ("open", "write", "flush", "fsync", "rename")


@pytest.fixture(scope="module")
def basis() -> SpectralBasis:
    return SpectralBasis.compute(V, F, 4, cache=False)


def _frames(path: Path) -> None:
    w = FrameWriter(path, fps=10)
    try:
        for i in range(3):
            w.add(np.full((32, 48, 3), 40 * i, dtype=np.uint8))
        w.close()
    except BaseException:
        w.abort()
        raise


def _cache_entry(basis: SpectralBasis) -> Callable[[Path], None]:
    def write(path: Path) -> None:
        basis._cache_path = path
        basis.info.messages.clear()
        basis._write_cache()  # a failed cache write is a message, never an exception
        basis._cache_path = None
        failed = [m for m in basis.info.messages if "could not write the cache file" in m]
        if failed:
            raise MeshError(failed[0])

    return write


def _plot(path: Path) -> None:
    from meshlap_core.surfaces.plot import plot_normal_curvature

    plot_normal_curvature("saddle", 0.1, 0.2, path)


def _denoise_csv(path: Path) -> None:
    from meshlap_core.cli import main

    clean = path.parent / "clean.obj"
    if not clean.exists():
        save_mesh(clean, V, F)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        args = ["--iters", "1", "--noise", "0.01", "--lam", "0.5", "--methods", "explicit"]
        code = main(["denoise-eval", str(clean), *args, "--csv", str(path)])
    if code != 0:  # progress lines, then exactly one error line
        lines = [x for x in err.getvalue().splitlines() if x.startswith("meshlap: error:")]
        assert code == 2 and len(lines) == 1, err.getvalue()
        raise MeshError(lines[0])


def _text(path: Path) -> None:
    with atomic_write(path, "w") as f:
        f.write("new\n" * 1000)


def _binary(path: Path) -> None:
    with atomic_write(path, "wb") as f:
        f.write(b"\x00new" * 1000)


WRITERS: dict[str, tuple[str, Callable[[Any], Callable[[Path], None]]]] = {
    "save_mesh obj": ("m.obj", lambda b: lambda p: save_mesh(p, V, F)),
    "save_mesh ply": ("m.ply", lambda b: lambda p: save_mesh(p, V, F)),
    "save_mesh off": ("m.off", lambda b: lambda p: save_mesh(p, V, F)),
    "save_scalars csv": ("s.csv", lambda b: lambda p: save_scalars(p, np.arange(len(V)))),
    "save_scalars npy": ("s.npy", lambda b: lambda p: save_scalars(p, np.arange(len(V)))),
    "basis save": ("basis.npz", lambda b: lambda p: b.save(p)),
    "cache entry": ("spectral-x.npz", _cache_entry),
    "kn plot": ("kn.png", lambda b: _plot),
    "gif frames": ("a.gif", lambda b: _frames),
    "denoise csv": ("sweep.csv", lambda b: _denoise_csv),
    "atomic text": ("t.txt", lambda b: _text),
    "atomic binary": ("b.bin", lambda b: _binary),
}


class _FailingFile(io.RawIOBase):
    """Wraps a file being written; ``write`` or ``flush`` raises the injected error."""

    def __init__(self, real: Any, step: str, code: int) -> None:
        self.real, self.step, self.code = real, step, code

    def _fail(self) -> None:
        raise OSError(self.code, os.strerror(self.code))

    def write(self, data: Any) -> int:
        if self.step == "write":
            self._fail()
        return self.real.write(data)

    def flush(self) -> None:
        if self.step == "flush":
            self._fail()
        self.real.flush()

    def close(self) -> None:
        self.real.close()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.real, name)

    def fileno(self) -> int:
        return self.real.fileno()

    def tell(self) -> int:
        return self.real.tell()

    def seek(self, *args: Any) -> int:
        return self.real.seek(*args)

    def seekable(self) -> bool:
        return self.real.seekable()

    def writable(self) -> bool:
        return True

    @property
    def closed(self) -> bool:  # type: ignore[override]
        return self.real.closed


def _inject(monkeypatch: pytest.MonkeyPatch, step: str, code: int) -> None:
    """Make one step of every atomic write fail with ``code`` (reads are left alone)."""
    real_open, real_fdopen = os.open, os.fdopen
    real_replace = os.replace

    def fail(*args: Any) -> None:
        raise OSError(code, os.strerror(code))

    def open_(path: Any, flags: int, *args: Any) -> int:
        if step == "open" and flags & os.O_CREAT and flags & os.O_EXCL:
            fail()
        return real_open(path, flags, *args)

    def fdopen(fd: int, mode: str = "r", *args: Any, **kw: Any) -> Any:
        real = real_fdopen(fd, mode, *args, **kw)
        if "w" in mode and step in ("write", "flush"):
            return _FailingFile(real, step, code)
        return real

    monkeypatch.setattr(os, "open", open_)
    monkeypatch.setattr(os, "fdopen", fdopen)
    if step == "fsync":
        monkeypatch.setattr(os, "fsync", lambda fd: fail())
    if step == "rename":
        monkeypatch.setattr(
            os, "replace", lambda a, b: fail() if ".tmp" in str(a) else real_replace(a, b)
        )


@pytest.mark.parametrize("code", sorted(CAUSES), ids=[CAUSES[c] for c in sorted(CAUSES)])
@pytest.mark.parametrize("step", STEPS)
@pytest.mark.parametrize("writer", sorted(WRITERS))
def test_a_failing_write_keeps_the_old_file_and_says_why(
    writer, step, code, tmp_path, monkeypatch, basis, capsys
):
    name, make = WRITERS[writer]
    write = make(basis)
    folder = tmp_path / "out"
    folder.mkdir()
    target = folder / name
    target.write_bytes(OLD)
    if writer == "denoise csv":
        save_mesh(folder / "clean.obj", V, F)
    before = sorted(p.name for p in folder.iterdir())
    _inject(monkeypatch, step, code)
    with pytest.raises(MeshError) as info:
        write(target)
    monkeypatch.undo()
    capsys.readouterr()
    message = str(info.value)
    assert target.read_bytes() == OLD
    assert sorted(p.name for p in folder.iterdir()) == before, "a temporary file was left"
    assert CAUSES[code] in message
    assert str(target) in message


def test_the_same_writers_succeed_without_faults(tmp_path, basis):
    """The control: every writer replaces the old file when nothing fails."""
    for writer, (name, make) in WRITERS.items():
        target = tmp_path / name
        target.write_bytes(OLD)
        make(basis)(target)
        assert target.read_bytes() != OLD, writer
    leftovers = [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    assert leftovers == []


def test_full_disk_on_close_still_removes_the_temporary_file(tmp_path, monkeypatch):
    """The round-3 bug: the cleanup's close flushed, raised ENOSPC again and the unlink never
    ran. Here the flush of the buffered file fails (the data sits in its buffer), so the
    close in the cleanup fails as well."""
    target = tmp_path / "big.txt"
    target.write_bytes(OLD)
    _inject(monkeypatch, "write", errno.ENOSPC)
    with pytest.raises(MeshError, match="no space left on device"):
        with atomic_write(target, "w") as f:
            f.write("x" * 10)  # buffered: reaches the failing raw write at flush and close
    monkeypatch.undo()
    assert target.read_bytes() == OLD
    assert [p.name for p in tmp_path.iterdir()] == ["big.txt"]
