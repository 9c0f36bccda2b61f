"""``meshlap view [MESH] [--screenshot OUT.png]``: the polyscope viewer (``meshlap_app.viewer``)."""

from __future__ import annotations

import argparse

from meshlap_app.state.names import FIELDS, PANELS  # pure data: no polyscope, no numpy

from ..errors import MeshError


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("view", help="open the polyscope viewer (default: the bundled mesh)")
    p.add_argument("mesh", nargs="?", help="mesh file (default: assets/bumpy.obj)")
    p.add_argument(
        "--screenshot",
        metavar="OUT.png",
        help="render one frame headless (EGL) into OUT.png and exit",
    )
    p.add_argument("--field", choices=FIELDS, default="cotan", help="curvature field shown first")
    p.add_argument("--panel", choices=PANELS, default="curvature", help="panel shown first")
    p.add_argument("--vertex", type=int, help="one-ring panel: the selected vertex")
    p.add_argument("--k", type=int, help="spectral panel: reconstruct from k eigenvectors")
    p.add_argument(
        "--ui-scale",
        type=float,
        default=1.0,
        help="size of the panel's text and widgets, 0.5 to 3 (projectors: 1.5-2)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.k is not None and args.k < 1:
        raise MeshError(f"must be at least 1, got {args.k}", "--k")
    if args.screenshot is not None:
        from ..io import check_output_path

        # before the viewer starts: a missing folder, a directory, a non-PNG name or the input
        # mesh itself as the target fail at once, and an existing PNG is replaced only by a
        # complete new one (the viewer writes it atomically)
        check_output_path(
            args.screenshot,
            overwrite_inputs=[args.mesh] if args.mesh else [],
            suffixes=(".png",),
        )
    # a bad mesh fails in meshlap_app.viewer.run before any window or EGL context is created
    from meshlap_app.viewer import run as run_viewer  # the CLI imports the GUI only here

    return run_viewer(
        args.mesh,
        screenshot=args.screenshot,
        field=args.field,
        panel=args.panel,
        vertex=args.vertex,
        k=args.k,
        ui_scale=args.ui_scale,
    )
