"""The report's pictures from the viewer: ``meshlap report`` renders its mesh figures with
the viewer's screenshot entry point (registered in the ``meshlap.screenshots`` entry-point group,
which :mod:`meshlap_core.cli.report` reads; the core never imports the viewer)."""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from types import TracebackType
from typing import Any

from meshlap_core.io import save_mesh
from meshlap_core.study import MeshSource


class ViewerScreenshots:
    """The report's screenshot function (:class:`meshlap_core.study.Screenshot`): the viewer's
    screenshot entry point called in this process, polyscope's EGL backend started once.

    A subprocess is not needed for a fresh GL context: one ``polyscope.init("openGL3_egl")``
    renders any number of screenshots of different scenes, since the viewer registers the
    structures of each and removes them all after its frame (measured: the frames are the same
    as those of separate ``meshlap view --screenshot`` processes, to a few pixels of 1.4
    million). Each screenshot then costs 1.5-2 s instead of a new process that imports numpy,
    scipy and polyscope and starts EGL: ``meshlap report --quick`` with its 13 screenshots took
    147 s instead of 269 s on the same machine. Use it as a context manager: on exit it
    shuts polyscope down if it started it (so the process may start another backend later)
    and removes its temporary folder. Meanwhile, polyscope's messages on the standard output
    and error are captured (a ``--json`` output stays one JSON object) and its ``.ini`` files go
    to the temporary folder, not the working directory.
    """

    def __init__(self) -> None:
        self._tmp: tempfile.TemporaryDirectory[str] | None = None
        self._count = 0
        self._started_polyscope = False

    def __enter__(self) -> ViewerScreenshots:
        self._tmp = tempfile.TemporaryDirectory(prefix="meshlap-shots-")
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if self._tmp is None:
            return
        work = Path(self._tmp.name)
        try:
            if self._started_polyscope:
                import polyscope as ps

                with _in_folder(work), _captured_output(work / "shutdown.log"):
                    ps.shutdown()
        finally:
            self._started_polyscope = False
            self._tmp.cleanup()
            self._tmp = None

    def __call__(
        self, mesh: MeshSource, panel: str, options: Mapping[str, Any], out_png: Path
    ) -> bool:
        """Render one frame into ``out_png`` (see :class:`meshlap_core.study.Screenshot`);
        a failure raises with the viewer's message."""
        from .viewer import run as run_viewer  # the viewer's screenshot entry point

        if self._tmp is None:
            raise RuntimeError("ViewerScreenshots is used outside its `with` block")
        import polyscope as ps

        self._count += 1
        work = Path(self._tmp.name) / f"shot{self._count}"
        work.mkdir()
        path = mesh
        if isinstance(mesh, tuple):
            V, F, name = mesh
            path = work / f"{name}.obj"  # the viewer's panel names the mesh after its file
            save_mesh(path, V, F)
        # before the working directory changes; absolute, not resolved (a link named as the
        # output is replaced, not written through)
        out = Path(out_png).absolute()
        path = Path(path).resolve() if path is not None else None
        started_before = ps.is_initialized()
        log = work / "output.log"
        try:
            with _in_folder(work), _captured_output(log):
                code = run_viewer(path, screenshot=out, panel=panel, **dict(options))
        finally:
            self._started_polyscope |= ps.is_initialized() and not started_before
        return code == 0 and out.is_file()


@contextlib.contextmanager
def _in_folder(folder: Path) -> Iterator[None]:
    """Work in ``folder`` (polyscope writes ``.polyscope.ini`` and ``imgui.ini`` into the
    working directory), then return to the previous one."""
    old = os.getcwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(old)


@contextlib.contextmanager
def _captured_output(log: Path) -> Iterator[None]:
    """Send what is printed on the file descriptors 1 and 2 (polyscope's C++ messages) to
    ``log`` instead of the terminal; Python's own streams are flushed first."""
    try:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = (os.dup(1), os.dup(2))
    except (OSError, ValueError):  # no real descriptors (embedded interpreter)
        yield
        return
    with open(log, "wb") as fh:
        os.dup2(fh.fileno(), 1)
        os.dup2(fh.fileno(), 2)
        try:
            yield
        finally:
            with contextlib.suppress(Exception):
                ctypes.CDLL(None).fflush(None)  # C stdio's buffered part goes to the log too
            for fd, old in zip((1, 2), saved, strict=True):
                os.dup2(old, fd)
                os.close(old)
