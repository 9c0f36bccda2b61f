"""``meshlap report [--meshes DIR] [--out DIR] [--quick]``: regenerate the whole study.

Writes ``report.md``, ``report.html``, ``figures/*.png`` and ``tables/*.csv`` into ``--out``
(see :mod:`meshlap_core.study`). A progress bar and the time of each section go to stderr;
stdout gets the list of files (or one JSON object with ``--json``). Sign convention of every
Laplacian used: negative semidefinite, ``Δx = −2Hn``.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import os
import sys
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any

from ._common import add_json_flag, emit_json

if TYPE_CHECKING:  # the study is imported when the command runs, not when the CLI starts
    from ..study import MeshSource

DEFAULT_OUT = "meshlap-report"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "report",
        help="regenerate every figure and table of the curvature / spectral / smoothing study",
        description=(
            "Run the seven sections of the study (one-ring, uniform curvature, helicoid, cotan "
            "vs uniform, spectral reconstruction, smoothing, denoising) and write report.md, "
            "report.html, PNG figures and CSV tables. Meshes come from --meshes (default "
            "../shared/meshes beside the checkout); missing ones are replaced by the bundled "
            "assets and the report says so."
        ),
    )
    p.add_argument(
        "--meshes",
        metavar="DIR",
        default=None,
        help="folder with the course meshes (default: ../shared/meshes)",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        default=DEFAULT_OUT,
        help=f"output folder (default: ./{DEFAULT_OUT})",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="smaller sweeps and fewer pictures (under 2 minutes on 2 cores)",
    )
    p.add_argument(
        "--sections",
        metavar="LIST",
        default=None,
        help="only these sections: numbers 1-7 or names (onering, uniform, "
        "helicoid, cotan, spectral, smoothing, denoising)",
    )
    p.add_argument(
        "--no-screenshots",
        action="store_true",
        help="draw meshes with matplotlib instead of the viewer's EGL screenshots",
    )
    p.add_argument(
        "--max-screenshots",
        metavar="N",
        type=int,
        default=None,
        help="take at most N viewer screenshots, draw the rest with matplotlib",
    )
    add_json_flag(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..study import build_report

    with ViewerScreenshots() as screenshot:
        result = build_report(
            args.out,
            args.meshes,
            quick=args.quick,
            sections=args.sections,
            screenshots=not args.no_screenshots,
            progress_stream=sys.stderr,
            screenshot=screenshot,
            max_screenshots=args.max_screenshots,
        )
    if args.json:
        emit_json(result.to_dict())
    else:
        print(f"wrote {result.markdown}")
        print(f"wrote {result.html}")
        print(f"wrote {len(result.figures)} figures in {result.out_dir / 'figures'}")
        print(f"wrote {len(result.tables)} tables in {result.out_dir / 'tables'}")
        print(
            f"total {result.total_seconds:.1f} s: "
            + ", ".join(f"{k} {v:.1f} s" for k, v in result.section_seconds.items())
        )
        if result.screenshot_failures:
            print(f"screenshots failed: {result.screenshot_failures[0]}")
    for key, err in result.errors.items():
        sys.stderr.write(f"meshlap: error: report section {key} failed: {err}\n")
    return 1 if result.errors else 0


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
        from meshlap_app.viewer import run as run_viewer  # the viewer's screenshot entry point

        if self._tmp is None:
            raise RuntimeError("ViewerScreenshots is used outside its `with` block")
        import polyscope as ps

        from ..io import save_mesh

        self._count += 1
        work = Path(self._tmp.name) / f"shot{self._count}"
        work.mkdir()
        path = mesh
        if isinstance(mesh, tuple):
            V, F, name = mesh
            path = work / f"{name}.obj"  # the viewer's panel names the mesh after its file
            save_mesh(path, V, F)
        out = Path(out_png).resolve()  # before the working directory changes
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
