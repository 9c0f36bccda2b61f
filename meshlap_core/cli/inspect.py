"""``meshlap inspect MESH --vertex I``: every operator term at one vertex, formulas substituted."""

from __future__ import annotations

import argparse

from ..errors import MeshError
from ..inspector import format_inspection, inspect_vertex
from ..io import load_mesh
from ..options import AREA_KINDS, BOUNDARY_RULES, CURVATURE_AREA, DEFAULT_BOUNDARY
from ._common import add_json_flag, emit_json, print_report


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "inspect",
        help="the cotangent weights, areas, Laplacians and curvatures at one vertex, step by step",
    )
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument(
        "--vertex", type=int, required=True, help="vertex index (0-based, after repairs)"
    )
    p.add_argument(
        "--area",
        choices=AREA_KINDS,
        default=CURVATURE_AREA,
        help=f"the A_i that Δ_cotan and K divide by (default {CURVATURE_AREA})",
    )
    p.add_argument(
        "--boundary",
        choices=BOUNDARY_RULES,
        default=DEFAULT_BOUNDARY,
        help=f"angle-deficit rule at boundary vertices (default {DEFAULT_BOUNDARY})",
    )
    add_json_flag(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    mesh = load_mesh(args.mesh)
    try:
        result = inspect_vertex(mesh.V, mesh.F, args.vertex, args.area, args.boundary)
    except MeshError as exc:  # the library names its argument "vertex"; here it is the flag
        if exc.source != "vertex":
            raise
        raise MeshError(exc.problem, "--vertex") from None
    print_report(args.mesh, mesh.report)  # vertex indices are those after the repairs
    if args.json:
        emit_json(result.to_json())
    else:
        print(format_inspection(result))
    return 0
