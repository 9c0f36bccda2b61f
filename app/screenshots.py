"""The core's pictures drawn by the viewer, found through entry points (the core never imports
the viewer):

- ``meshlap report`` renders its mesh figures with the viewer's screenshot entry point
  (:class:`ViewerScreenshots`, group ``meshlap.screenshots``, read by
  :mod:`meshlap_core.cli.report`);
- a check result's notebook picture draws the difference map with :func:`difference_png`
  (group ``meshlap.check_picture``, read by :mod:`meshlap_core.exercises.result`).
"""

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

import numpy as np

from meshlap_core.course_report import MeshSource
from meshlap_core.errors import MeshError
from meshlap_core.io import save_mesh

from . import ipc

PICTURE_TIMEOUT = 120.0
"""Seconds the difference map's EGL process may take (start-up of polyscope and EGL
included)."""


class ViewerScreenshots:
    """The report's screenshot function (:class:`meshlap_core.course_report.Screenshot`): the
    viewer's screenshot entry point called in this process, polyscope's EGL backend started once.

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

                with in_folder(work), captured_output(work / "shutdown.log"):
                    ps.shutdown()
        finally:
            self._started_polyscope = False
            self._tmp.cleanup()
            self._tmp = None

    def __call__(
        self, mesh: MeshSource, panel: str, options: Mapping[str, Any], out_png: Path
    ) -> bool:
        """Render one frame into ``out_png`` (see :class:`meshlap_core.course_report.Screenshot`);
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
            with in_folder(work), captured_output(log):
                code = run_viewer(path, screenshot=out, panel=panel, **dict(options))
        finally:
            self._started_polyscope |= ps.is_initialized() and not started_before
        return code == 0 and out.is_file()


@contextlib.contextmanager
def in_folder(folder: Path) -> Iterator[None]:
    """Work in ``folder`` (polyscope writes ``.polyscope.ini`` and ``imgui.ini`` into the
    working directory), then return to the previous one."""
    old = os.getcwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(old)


@contextlib.contextmanager
def captured_output(log: Path) -> Iterator[None]:
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


def difference_png(
    V: np.ndarray, F: np.ndarray, difference: np.ndarray, signed: bool, size: int = 400
) -> bytes:
    """The difference map student − reference drawn on the mesh by polyscope's EGL snapshot
    renderer (``openGL3_egl``, started as the viewer starts it), a ``size``² PNG.

    This is the ``meshlap.check_picture`` entry point that
    :meth:`meshlap_core.exercises.result.CheckResult.picture` reads. The render runs in a
    child process (:func:`meshlap_app.ipc.call`): EGL failing to start can abort its
    process, and a notebook's kernel must survive that (the caller then draws with
    matplotlib and says why).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    difference : (n,) float
        Per vertex; signed (coolwarm, symmetric range) or a magnitude (viridis from 0).
    signed : bool
    size : int
        Pixels per side.

    Returns
    -------
    bytes
        The PNG.

    Raises
    ------
    RuntimeError
        EGL could not render (why, and polyscope's last message line when it printed one).
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    d = np.asarray(difference, dtype=np.float64)
    with tempfile.TemporaryDirectory(prefix="meshlap-picture-") as tmp:
        work = Path(tmp)
        try:
            return ipc.call(
                render_difference,
                V,
                F,
                d,
                bool(signed),
                int(size),
                str(work),
                timeout=PICTURE_TIMEOUT,
                name="picture",
            )
        except (ipc.NoChildProcess, MeshError) as exc:
            log = work / "output.log"
            lines = log.read_text(errors="replace").splitlines() if log.is_file() else []
            said = [x.strip() for x in lines if x.strip()]
            why = f"{exc} ({said[-1]})" if said else str(exc)
            raise RuntimeError(f"polyscope's EGL backend did not render: {why}") from exc


def render_difference(
    V: np.ndarray,
    F: np.ndarray,
    d: np.ndarray,
    signed: bool,
    size: int,
    folder: str,
    progress: Any = None,
) -> bytes:
    """The body of :func:`difference_png`'s child process: polyscope started by the viewer's
    :func:`~meshlap_app.viewer.init_polyscope` on ``openGL3_egl``, the map drawn, a PNG made.
    Polyscope's messages go to ``folder/output.log``; ``progress`` is unused."""
    import polyscope as ps

    from .panels.check import difference_colours
    from .scene import write_png
    from .viewer import init_polyscope

    work = Path(folder)
    with in_folder(work), captured_output(work / "output.log"):
        init_polyscope("openGL3_egl")
        ps.set_ground_plane_mode("none")
        ps.set_window_size(size, size)
        mesh = ps.register_surface_mesh("mesh", V, F, smooth_shade=True)
        cmap, (lo, hi) = difference_colours(d, signed)
        mesh.add_scalar_quantity(
            "student - reference",
            d,
            defined_on="vertices",
            cmap=cmap,
            vminmax=(lo, hi),
            enabled=True,  # no colour bar: the notebook's figure draws its own
        )
        ps.reset_camera_to_home_view()
        rgba = ps.screenshot_to_buffer(transparent_bg=False, include_UI=False)
        ps.shutdown()
    out = work / "picture.png"
    write_png(out, rgba)
    return out.read_bytes()
