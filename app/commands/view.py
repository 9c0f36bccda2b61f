"""``meshlap view [MESH] [--screenshot OUT.png]``: the polyscope viewer (:mod:`..viewer`).

Registered with the core's command line through the ``meshlap.commands`` entry point; the
parser reads only pure data (the registry's views, the field names), so ``meshlap --help``
does not import polyscope.
"""

from __future__ import annotations

import argparse

from meshlap_core.errors import MeshError
from meshlap_core.options import CURVATURE_FIELDS, UP_AXES

from ..registry import VIEWS

START_OPTIONS = ("field", "vertex", "k")
"""The options handed to the panels when the window opens (each checks its own)."""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("view", help="open the polyscope viewer (default: the bundled mesh)")
    p.add_argument("mesh", nargs="?", help="mesh file (default: assets/bumpy.obj)")
    p.add_argument(
        "--screenshot",
        metavar="OUT.png",
        help="render one frame headless (EGL) into OUT.png and exit",
    )
    p.add_argument(
        "--session",
        metavar="FILE.json",
        help="reopen a saved session (mesh, panel settings, camera); replaces MESH and the "
        "options below",
    )
    p.add_argument(
        "--field", choices=CURVATURE_FIELDS, help="curvature field shown first (default cotan)"
    )
    p.add_argument("--panel", choices=VIEWS, help=f"panel shown first (default {VIEWS[0]})")
    p.add_argument("--vertex", type=int, help="one-ring panel: the selected vertex")
    p.add_argument("--k", type=int, help="spectral panel: reconstruct from k eigenvectors")
    p.add_argument(
        "--ui-scale",
        type=float,
        help="size of the panel's text and widgets, 0.5 to 3 (projectors: 1.5-2); with "
        "--session it replaces the session's scale",
    )
    p.add_argument(
        "--up",
        choices=UP_AXES,
        help="the mesh's axis shown up (default: y, or the mesh's known axis, e.g. z for "
        "nefertiti.obj; a negated axis as --up=-z); kept in a saved session",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.session is not None:
        given = [("MESH", args.mesh)] + [
            (f"--{name.replace('_', '-')}", getattr(args, name))
            for name in (*START_OPTIONS, "panel", "up")  # --ui-scale: the projector's, wins
        ]
        given = [flag for flag, value in given if value is not None]
        if given:
            raise MeshError(
                f"{', '.join(given)} cannot be combined with --session (the session sets them)",
                "--session",
            )
    if args.screenshot is not None:
        from meshlap_core.io import check_output_path

        # before the viewer starts: a missing folder, a directory, a non-PNG name or the input
        # mesh itself as the target fail at once, and an existing PNG is replaced only by a
        # complete new one (the viewer writes it atomically)
        check_output_path(
            args.screenshot,
            overwrite_inputs=[p for p in (args.mesh, args.session) if p],
            suffixes=(".png",),
        )
    # a bad mesh or option fails in viewer.run before any window or EGL context is created
    from ..viewer import run as run_viewer  # polyscope is imported only when a view runs

    return run_viewer(
        args.mesh,
        screenshot=args.screenshot,
        panel=args.panel,
        ui_scale=args.ui_scale,
        session=args.session,
        up=args.up,
        **{name: getattr(args, name) for name in START_OPTIONS},
    )
