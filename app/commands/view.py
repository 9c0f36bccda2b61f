"""``meshlap view [MESH] [--screenshot OUT.png]``: the polyscope viewer (:mod:`..viewer`).

Registered with the core's command line through the ``meshlap.commands`` entry point. The
host's own options (MESH, ``--screenshot``, ``--session``, ``--panel``, ``--ui-scale``,
``--up``) are here; every panel's options (``--field``, ``--vertex``, ``--k`` ...) are the
``view`` flags of the registered specs' settings, with their help, type and range from the
settings schema. The parser reads only the specs (pure data), so ``meshlap --help`` does not
import polyscope.
"""

from __future__ import annotations

import argparse
import textwrap

from meshlap_core.errors import MeshError
from meshlap_core.options import UP_AXES

from ..registry import REGISTRY, VIEWS


def start_options() -> list[str]:
    """The dests of the panels' ``meshlap view`` flags: handed to the panels when the window
    opens (each parsed and checked by its setting, then against the mesh by its spec)."""
    return [flag.dest for spec in REGISTRY for _, flag in spec.flags("view")]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "view",
        help="open the polyscope viewer (default: the bundled mesh)",
        epilog="views (--panel, keys 1, 2, ...):\n"
        + "\n".join(
            textwrap.fill(f"{s.name}: {s.summary}", 78, initial_indent="  ", subsequent_indent="  ")
            for s in REGISTRY
            if s.view
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
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
    p.add_argument("--panel", choices=VIEWS, help=f"panel shown first (default {VIEWS[0]})")
    for spec in REGISTRY:
        for setting, flag in spec.flags("view"):
            p.add_argument(
                flag.name,
                dest=flag.dest,
                metavar=setting.metavar(),
                help=setting.flag_help(flag, spec.name, default=False),
            )
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
            for name in (*start_options(), "panel", "up")  # --ui-scale: the projector's, wins
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
        **{name: getattr(args, name) for name in start_options()},
    )
