"""``meshlap geodesic MESH --vertex V [--vertex V2 …]``: geodesic distance from source vertices.

The heat method (Crane, Weischedel & Wardetzky 2013) with ``t = m·h²``; ``--method igl-heat``
runs libigl's; ``--method exact`` (or ``--exact`` beside another method, which then reports the
method's relative error) the exact polyhedral distance (MMP, ``igl.exact_geodesic``: seconds to
minutes on large meshes). Vertices in a component without a source are at infinite distance
(written as ``inf``, ``null`` in JSON).
"""

from __future__ import annotations

import argparse

import numpy as np

from ..diffusion import HeatGeodesic, exact_distance, igl_heat_distance, mean_edge_length
from ..diffusion.geodesic import check_time_factor
from ..errors import MeshError
from ..io import load_mesh
from ..options import DEFAULT_HEAT_BOUNDARY, GEODESIC_METHODS, HEAT_BOUNDARIES
from ..progress import Progress
from ._common import (
    add_json_flag,
    emit_json,
    number_text,
    print_report,
    save_field,
    shown,
    summary_stats,
)
from ._curves import add_curve_flags, curves_path, write_curves
from ._sources import add_vertex_flag, output, vertices

OUT_SUFFIXES = (".npy", ".csv", ".ply")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "geodesic",
        help="geodesic distance from vertices (heat method, libigl's, or exact)",
        description=(
            "Distance to the nearest --vertex: heat method with t = m h^2 (h the mean edge "
            "length), the boundary condition of the heat step on open meshes, or the exact "
            "polyhedral distance. --isolines N writes N level curves to --curves (OBJ lines)."
        ),
    )
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    add_vertex_flag(p)
    p.add_argument("--method", choices=GEODESIC_METHODS, default="heat", help="default: heat")
    p.add_argument(
        "--exact", action="store_true", help="also compute the exact distance and report the error"
    )
    p.add_argument(
        "--m",
        default=None,
        help="heat time factor, t = m h^2 (default 1; heat and igl-heat methods)",
    )
    p.add_argument(
        "--boundary",
        choices=HEAT_BOUNDARIES,
        default=None,
        help=f"heat-step boundary condition on open meshes (default {DEFAULT_HEAT_BOUNDARY}; "
        "heat method only: libigl's averages the two conditions itself)",
    )
    p.add_argument("--out", help="write one distance per vertex: .npy, .csv or .ply")
    add_curve_flags(p, "distance")
    add_json_flag(p)
    p.set_defaults(func=run)


def _distance(args: argparse.Namespace, V: np.ndarray, F: np.ndarray, src: np.ndarray, method: str):
    m = 1.0 if args.m is None else check_time_factor(number_text(args.m, "--m"), "--m")
    try:
        if method == "exact":
            bar = Progress(
                1.0,
                lambda p: f"meshlap geodesic: {100 * p.done:3.0f}% {p.message}",
                in_place=False,
                after_s=1.0,
                every_s=1.0,
            )
            d = exact_distance(V, F, src, progress=bar.update)
            bar.close()
            return d
        if method == "igl-heat":
            t = None if args.m is None else m * mean_edge_length(V, F) ** 2
            return igl_heat_distance(V, F, src, t=t)
        boundary = DEFAULT_HEAT_BOUNDARY if args.boundary is None else args.boundary
        return HeatGeodesic(V, F, m=m, boundary=boundary).distance(src)
    except MeshError as exc:
        if exc.source in ("m", "t"):
            raise MeshError(exc.problem, "--m") from None
        if exc.source in ("V", "F"):  # the mesh's own problem: named by its file
            raise MeshError(exc.problem, args.mesh) from None
        raise exc.with_source(args.mesh) from None


def _check_method_flags(args: argparse.Namespace) -> None:
    """Flags the chosen method would ignore are refused, not dropped without a word."""
    if args.method == "exact" and args.m is not None:
        raise MeshError("the exact distance has no heat time; --m is for the heat methods", "--m")
    if args.method != "heat" and args.boundary is not None:
        raise MeshError(
            f"--boundary is for --method heat (the {args.method} method does not take it)",
            "--boundary",
        )


def run(args: argparse.Namespace) -> int:
    out = output(args.out, args.mesh, OUT_SUFFIXES, "--out")
    curves = curves_path(args)
    if args.m is not None:
        check_time_factor(number_text(args.m, "--m"), "--m")
    _check_method_flags(args)
    mesh = load_mesh(args.mesh)
    V, F = mesh.V, mesh.F
    src = vertices(args, len(V))
    d = _distance(args, V, F, src, args.method)
    result = {
        "file": str(args.mesh),
        "method": args.method,
        "sources": src.tolist(),
        "n_vertices": len(V),
        "unreachable": int(np.count_nonzero(np.isinf(d))),
        **summary_stats(d),
    }
    if args.exact and args.method != "exact":
        ex = _distance(args, V, F, src, "exact")
        ok = np.isfinite(ex) & (ex > 0)
        rel = np.abs(d[ok] - ex[ok]) / ex[ok]
        result["relative_error_max"] = float(rel.max()) if rel.size else 0.0
        result["relative_error_mean"] = float(rel.mean()) if rel.size else 0.0
    print_report(args.mesh, mesh.report)
    save_field(out, V, F, d, args.mesh)
    write_curves(args, curves, V, F, d, result)
    result["out"] = str(out) if out else None
    if args.json:
        emit_json(result)
    else:
        _print_text(result)
    return 0


def _print_text(r: dict) -> None:
    print(
        f"{r['method']} geodesic distance from {len(r['sources'])} source(s) "
        f"on {r['n_vertices']} vertices"
    )
    for k in ("min", "max", "mean", "median"):
        print(f"  {k:<8}{r[k]: .6g}")
    if r["unreachable"]:
        print(f"  {r['unreachable']} vertices in components without a source: distance inf")
    if "relative_error_max" in r:
        print(
            f"  relative error vs exact: max {r['relative_error_max']:.3%}, "
            f"mean {r['relative_error_mean']:.3%}"
        )
    for key in ("out", "curves"):
        if r[key]:
            print(f"wrote {shown(r[key])}")
