"""``meshlap info MESH [--json]``: counts, bounding box, topology, repairs."""

from __future__ import annotations

import argparse

from ..describe import format_info, mesh_info
from ..io import load_mesh
from ..linalg.spd import solver_info
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
    info["solver"] = solver_info()
    if args.json:
        emit_json(info)
    else:
        print(format_info(info))
        print(solver_line(info["solver"]))
    return 0


def solver_line(solver: dict) -> str:
    """``solver  cholmod (...)``: the sparse Cholesky back end and how to get the fast one."""
    if solver["fast"]:
        return "solver            cholmod (scikit-sparse, the fast one)"
    return (
        f"solver            {solver['backend']} (bundled; the fast one: {solver['hint']}, "
        "see README 'Fast solver')"
    )
