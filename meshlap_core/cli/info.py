"""``meshlap info MESH [--json]``: counts, bounding box, topology, repairs."""

from __future__ import annotations

import argparse

from ..describe import format_info, mesh_info
from ..io import load_mesh
from ._common import add_json_flag, emit_json


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "info", help="counts, bounding box, boundary, components, chi, genus, repairs"
    )
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    add_json_flag(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    mesh = load_mesh(args.mesh)
    info = mesh_info(mesh.V, mesh.F, mesh.report, str(args.mesh), table=mesh.edge_table)
    if args.json:
        emit_json(info)
    else:
        print(format_info(info))
    return 0
