"""``meshlap curvature MESH --method ...``: a per-vertex curvature field and its statistics."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..curvature import curvature_field
from ..errors import MeshError
from ..io import check_output_path, load_mesh, save_mesh, save_scalars
from ..options import (
    AREA_KINDS,
    BOUNDARY_RULES,
    CURVATURE_AREA,
    CURVATURE_METHODS,
    DEFAULT_BOUNDARY,
    DEFAULT_CURVATURE_FIELD,
)
from ._common import add_json_flag, emit_json, print_report, summary_stats

OUT_SUFFIXES = (".csv", ".npy", ".ply")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("curvature", help="per-vertex mean / Gaussian / principal curvature")
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument(
        "--method",
        choices=CURVATURE_METHODS,
        default=DEFAULT_CURVATURE_FIELD,
        help="uniform H, cotangent H, angle-deficit K, or principal k1/k2 (default cotan)",
    )
    p.add_argument(
        "--area",
        choices=AREA_KINDS,
        default=CURVATURE_AREA,
        help="vertex area (default voronoi, the mixed area that converges; barycentric: the "
        "course's)",
    )
    p.add_argument(
        "--boundary",
        choices=BOUNDARY_RULES,
        default=DEFAULT_BOUNDARY,
        help="angle deficit at boundary vertices: pi - sum (default), 2pi - sum, or zero",
    )
    p.add_argument(
        "--out", help="write the field: .csv, .npy, or .ply (mesh with a 'quality' property)"
    )
    add_json_flag(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.out is not None and not args.out.strip():
        raise MeshError("the output path is empty (give a file name or leave --out out)", "--out")
    out = Path(args.out) if args.out is not None else None
    if out is not None:  # checked first: a doomed run fails at once and writes nothing
        check_output_path(out, overwrite_inputs=(args.mesh,), suffixes=OUT_SUFFIXES)
    mesh = load_mesh(args.mesh)
    values = curvature_field(mesh.V, mesh.F, args.method, args.area, args.boundary)
    if not np.isfinite(values).all():  # never write or summarize a broken field
        bad = int(np.count_nonzero(~np.isfinite(values)))
        raise MeshError(f"the {args.method} curvature is not finite at {bad} vertices", args.mesh)
    print_report(args.mesh, mesh.report)
    if out is not None:
        if out.suffix.lower() == ".ply":
            save_mesh(out, mesh.V, mesh.F, scalars=values, overwrite_inputs=(args.mesh,))
        else:
            save_scalars(out, values, overwrite_inputs=(args.mesh,))
    stats = summary_stats(values)
    if args.json:
        emit_json(
            {
                "file": str(args.mesh),
                "method": args.method,
                "area": args.area,
                "boundary": args.boundary,
                "n_vertices": len(values),
                **stats,
                "repairs": mesh.report.repairs,
                "warnings": mesh.report.warnings,
                "out": str(out) if out else None,
            }
        )
    else:
        print(
            f"{args.method} curvature ({args.area} area, boundary rule {args.boundary}) "
            f"on {len(values)} vertices"
        )
        for k, v in stats.items():
            print(f"  {k:<7}{v: .6g}")
        if out is not None:
            print(f"wrote {out}")
    return 0
