"""The real window from a notebook cell: :func:`open_viewer` saves the mesh to a temporary
file and starts ``meshlap view`` on it as a separate process (the notebook's kernel goes on;
closing the window ends that process only). Where no display exists it starts nothing and
says so (:attr:`ViewerWindow.message`)."""

from __future__ import annotations

import atexit
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import MeshError
from ..options import CURVATURE_FIELDS, check_choice
from . import scene as sc

COMMANDS_GROUP = "meshlap.commands"
"""Entry-point group of the commands the viewer adds (``view``, ``animate``)."""

FIRST_LOOK_SECONDS = 1.5
"""How long :func:`open_viewer` waits for a ``meshlap view`` that fails at once (a bad
option, no OpenGL) to say why."""


def display_problem(environ: Any = None, platform: str | None = None) -> str:
    """Why no window can open here ("" when a display exists): on Linux, neither ``DISPLAY``
    nor ``WAYLAND_DISPLAY`` is set (a server, a container, a remote kernel)."""
    env = os.environ if environ is None else environ
    if (platform or sys.platform).startswith("linux") and not (
        env.get("DISPLAY") or env.get("WAYLAND_DISPLAY")
    ):
        return (
            "no display here (neither DISPLAY nor WAYLAND_DISPLAY is set, as on a server or "
            "in a container): the window cannot open; show(...) draws the picture in the "
            "notebook, or run `meshlap view` on a machine with a screen"
        )
    return ""


def _viewer_installed() -> bool:
    from importlib.metadata import entry_points

    return any(e.name == "view" for e in entry_points(group=COMMANDS_GROUP))


@dataclass
class ViewerWindow:
    """A ``meshlap view`` started from a notebook, or why none was.

    Attributes
    ----------
    process : subprocess.Popen or None
        ``None`` when nothing was started (see ``message``).
    path : Path or None
        The temporary mesh file the window opened.
    command : list of str
        The command line.
    message : str
        Why nothing was started, or what was started.

    Examples
    --------
    Where no display exists nothing is started, and the window says why:

    >>> from meshlap_core import icosphere, open_viewer
    >>> window = open_viewer(*icosphere(1), environ={})  # an environment without DISPLAY
    >>> window.process is None, window.running, window.status().startswith("no display")
    (True, False, True)
    """

    process: subprocess.Popen[bytes] | None
    path: Path | None
    command: list[str] = field(default_factory=list)
    message: str = ""

    @property
    def running(self) -> bool:
        """The window's process is alive."""
        return self.process is not None and self.process.poll() is None

    def output(self) -> str:
        """What the window's process printed (its log file)."""
        if self.path is None:
            return ""
        log = self.path.parent / "viewer.log"
        return log.read_text(errors="replace") if log.is_file() else ""

    def status(self) -> str:
        """What the window is doing now: not started (why), running, or ended (its exit code
        and its error, else the last line it printed)."""
        if self.process is None:
            return self.message
        code = self.process.poll()
        if code is None:
            return f"meshlap view is running on {self.path} (pid {self.process.pid})"
        said = [x.strip() for x in self.output().splitlines() if x.strip()]
        errors = [x for x in said if x.startswith("meshlap: error:")]  # not polyscope's exit
        last = (errors or said or [""])[-1]
        return f"meshlap view ended (exit code {code})" + (f": {last}" if last else "")

    def wait(self, timeout: float | None = None) -> int | None:
        """Wait up to ``timeout`` seconds for the window to close; its exit code, or ``None``
        while it still runs (or when nothing was started)."""
        if self.process is None:
            return None
        try:
            return self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def close(self) -> None:
        """End the window's process (nothing when it has ended)."""
        if self.running:
            assert self.process is not None
            self.process.terminate()
            if self.wait(5) is None:
                self.process.kill()

    def __repr__(self) -> str:
        return f"<ViewerWindow: {self.status()}>"


def open_viewer(
    mesh_or_V: Any,
    F: Any = None,
    *,
    panel: str | None = None,
    field: str | None = None,
    vertex: Any = None,
    up: str | None = None,
    environ: Any = None,
) -> ViewerWindow:
    """Open the real viewer window on a mesh from Python (a notebook cell): the mesh is
    written to a temporary ``.obj`` and ``meshlap view FILE [--panel P] [--field FIELD]
    [--vertex I] [--up AXIS]`` starts as a separate process.

    Parameters
    ----------
    mesh_or_V, F
        As :func:`~.picture.show`.
    panel : str, optional
        The view shown first (``meshlap view --panel``: curvature, onering, spectral, ...).
    field : str, optional
        The curvature field shown first (one of the window's: cotan, uniform, gaussian, ...).
    vertex : int, optional
        The selected vertex (the One-ring view).
    up : str, optional
        The mesh axis shown up.
    environ : mapping, optional
        The environment to look for a display in (default: this process's).

    Returns
    -------
    ViewerWindow
        With ``process=None`` and the reason in ``message`` when no display exists or the
        viewer is not installed; :meth:`ViewerWindow.status` says later whether the window
        still runs or why it ended.

    Raises
    ------
    MeshError
        A bad mesh or argument (named in the message), or a window that ended with an error
        within :data:`FIRST_LOOK_SECONDS` (its exit code and last message).

    Examples
    --------
    Without a display (here an empty environment) nothing starts and the message says why:

    >>> from meshlap_core import icosphere, open_viewer
    >>> window = open_viewer(*icosphere(1), vertex=0, environ={})
    >>> window.process is None and "no display" in window.message
    True
    """
    V, Fc, name = sc.subject(mesh_or_V, F)
    args: list[str] = []
    if panel is not None:
        args += ["--panel", str(panel)]
    if field is not None:
        args += ["--field", check_choice(str(field), CURVATURE_FIELDS, "curvature field", "field")]
    i = sc.check_vertex(vertex, len(V))
    if i is not None:
        args += ["--vertex", str(i)]
    if up is not None:
        args += [f"--up={sc.check_up(up)}"]
    why = display_problem(environ)
    if not why and not _viewer_installed():
        why = "the viewer (meshlap_app) is not installed: pip install -e . in the checkout"
    if why:
        return ViewerWindow(None, None, [], why)
    from ..io import save_mesh

    folder = Path(tempfile.mkdtemp(prefix="meshlap-window-"))
    atexit.register(shutil.rmtree, folder, True)
    stem = Path(name).stem or "mesh"
    path = folder / f"{stem}.obj"
    save_mesh(path, V, Fc)
    command = [sys.executable, "-m", "meshlap_core.cli", "view", str(path), *args]
    with open(folder / "viewer.log", "wb") as log:
        process = subprocess.Popen(
            command, stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
            env=dict(os.environ if environ is None else environ),
        )  # fmt: skip
    window = ViewerWindow(process, path, command, f"meshlap view started on {path}")
    code = window.wait(FIRST_LOOK_SECONDS)
    if code not in (0, None):
        raise MeshError(window.status(), "open_viewer")
    return window
