"""``meshlap report [--meshes DIR] [--out DIR] [--quick]``: regenerate the whole study.

Writes ``report.md``, ``report.html``, ``figures/*.png`` and ``tables/*.csv`` into ``--out``
(see :mod:`meshlap_core.course_report`). A progress bar and the time of each section go to stderr;
stdout gets the list of files (or one JSON object with ``--json``). Sign convention of every
Laplacian used: negative semidefinite, ``Δx = −2Hn``.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from typing import Any

from ._common import add_json_flag, emit_json

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


def screenshot_provider() -> contextlib.AbstractContextManager[Any]:
    """The viewer's screenshot function for the report, as a context manager: the first
    ``meshlap.screenshots`` entry point (the viewer package registers its EGL renderer there),
    or one giving ``None`` (meshes drawn with matplotlib) when no viewer is installed."""
    from importlib.metadata import entry_points

    for ep in entry_points(group="meshlap.screenshots"):
        return ep.load()()
    return contextlib.nullcontext(None)


def run(args: argparse.Namespace) -> int:
    from ..course_report import build_report

    with screenshot_provider() as screenshot:
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
