"""``meshlap deform MESH --handle V[,V…] --method M --out OUT``: drag handles, write the shape.

The handles are exactly the listed vertices (``--radius R`` grows each into the disc of
vertices within geodesic distance ``R``, in the mesh's units); nothing else is held unless
``--fixed`` lists it (a component holding neither stays where it is). The handles are rotated
about their centroid (``--rotate ax,ay,az,deg``, right-handed about the axis), then moved
(``--move dx,dy,dz``). Methods: Laplacian coordinates (soft constraints), the harmonic,
biharmonic and triharmonic displacement, and ``--iters`` ARAP iterations from the rest pose
(:mod:`meshlap_core.deform`).

Bounded work: at most :data:`~meshlap_core.deform.regions.MAX_SEEDS` handle and fixed values,
at most :data:`~meshlap_core.deform.arap.MAX_ITERS` iterations; the output is written
atomically and never over the input.
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

import numpy as np

from ..errors import MeshError
from ..options import DEFORM_METHODS
from ..progress import Progress
from ._common import add_json_flag, emit_json, parse_list, print_report, summary_stats
from ._sources import output

DEFAULT_ITERS = 10
"""ARAP iterations when ``--iters`` is not given."""
FLAGS = {
    "handles": "--handle",
    "fixed": "--fixed",
    "radius": "--radius",
    "rotate": "--rotate",
    "move": "--move",
    "iters": "--iters",
    "targets": "--move",  # a target out of range: the move took the handles there
}
"""The core's argument names and the flags users typed."""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "deform",
        help="drag handle vertices: Laplacian coordinates, k-harmonic displacement or ARAP",
        description=(
            "Move the --handle vertices (each grown into a geodesic disc of --radius) by a "
            "rotation about their centroid (--rotate ax,ay,az,deg) and then a translation "
            "(--move dx,dy,dz); only the handles and the --fixed vertices are held. Writes "
            "the deformed mesh (.obj, .off, .ply)."
        ),
    )
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument(
        "--handle",
        action="append",
        required=True,
        metavar="V[,V...]",
        help="handle vertices (0-based, after repairs); repeat or separate with commas",
    )
    p.add_argument("--radius", default="0", help="grow each handle into a disc (mesh units)")
    p.add_argument(
        "--fixed", action="append", metavar="V[,V...]", help="vertices held at rest (none)"
    )
    p.add_argument(
        "--rotate",
        metavar="ax,ay,az,deg",
        help="rotate the handles about their centroid (degrees; --rotate=-1,0,0,30 with '=' "
        "when the first number is negative)",
    )
    p.add_argument("--move", metavar="dx,dy,dz", help="then translate them (--move=-1,0,0)")
    p.add_argument("--method", choices=DEFORM_METHODS, required=True)
    p.add_argument("--iters", help=f"ARAP iterations (default {DEFAULT_ITERS})")
    p.add_argument("--out", required=True, help="the deformed mesh (.obj, .off, .ply)")
    add_json_flag(p)
    p.set_defaults(func=run)


def _indices(values: list[str] | None, flag: str) -> list[int] | None:
    """The comma lists of a repeatable flag as one list of ints (bounded before parsing)."""
    if values is None:
        return None
    from ..deform.regions import MAX_SEEDS

    if sum(v.count(",") + 1 for v in values) > MAX_SEEDS:
        raise MeshError(f"at most {MAX_SEEDS} vertices", flag)
    return [i for v in values for i in parse_list(v, int, flag)]  # each one non-empty


def _floats(text: str | None, count: int, flag: str, spelled: str) -> list[float] | None:
    if text is None:
        return None
    values = parse_list(text, float, flag)
    if len(values) != count:
        raise MeshError(f"expected {count} numbers {spelled}, got {len(values)}", flag)
    return values


def _iters(text: str | None, method: str) -> int:
    from ..deform.arap import MAX_ITERS

    if text is None:
        return DEFAULT_ITERS
    if method != "arap":
        raise MeshError(f"only --method arap iterates (got --method {method})", "--iters")
    digits = text.strip()
    if not (digits.isascii() and digits.isdigit()) or len(digits) > 12:
        raise MeshError(f"must be an integer from 0 to {MAX_ITERS}, got {text!r}", "--iters")
    value = int(digits)
    if value > MAX_ITERS:
        raise MeshError(f"must be at most {MAX_ITERS}, got {value}", "--iters")
    return value


def _checked(args: argparse.Namespace) -> dict[str, Any]:
    """Every argument checked before the mesh is read (a doomed run fails at once)."""
    from ..deform.regions import check_radius
    from ..io import WRITE_FORMATS

    return {
        "out": output(args.out, args.mesh, WRITE_FORMATS, "--out"),
        "handles": _indices(args.handle, "--handle"),
        "fixed": _indices(args.fixed, "--fixed"),
        "radius": check_radius(args.radius, "--radius"),
        "rotate": _floats(args.rotate, 4, "--rotate", "ax,ay,az,deg"),
        "move": _floats(args.move, 3, "--move", "dx,dy,dz"),
        "iters": _iters(args.iters, args.method),
    }


def _cli_error(exc: MeshError, mesh: str) -> MeshError:
    if exc.source in FLAGS:
        return MeshError(exc.problem, FLAGS[exc.source])
    return exc.with_source(mesh)


def _deform(args: argparse.Namespace, V: np.ndarray, F: np.ndarray, a: dict[str, Any]):
    """Grow the handles, build the method's solver, move the handles, solve."""
    from ..deform import ArapDeformer, grow_handles, make_deformer, rigid_targets, rotation_matrix

    t0 = time.perf_counter()
    regions = grow_handles(V, F, a["handles"], a["radius"])
    t1 = time.perf_counter()
    solver = make_deformer(args.method, V, F, regions.vertices, a["fixed"])
    rot = None if a["rotate"] is None else rotation_matrix(a["rotate"][:3], a["rotate"][3])
    targets = rigid_targets(V, solver.handles, rot, a["move"])
    t2 = time.perf_counter()
    if isinstance(solver, ArapDeformer):
        solver.set_targets(targets)
        bar = Progress(
            a["iters"],
            lambda p: f"meshlap deform: ARAP iteration {p.done:.0f}/{p.total:.0f}",
            in_place=False,
            after_s=2.0,
            every_s=5.0,
        )
        for i in range(a["iters"]):
            solver.step()
            bar.update(i + 1)
        bar.close()
    else:
        solver.update(targets)
    t3 = time.perf_counter()
    timings = {"grow_s": t1 - t0, "setup_s": t2 - t1, "solve_s": t3 - t2}
    return regions, solver, timings


def run(args: argparse.Namespace) -> int:
    from ..io import load_mesh, save_mesh

    a = _checked(args)
    mesh = load_mesh(args.mesh)
    V, F = mesh.V, mesh.F
    try:
        regions, solver, timings = _deform(args, V, F, a)
    except MeshError as exc:
        raise _cli_error(exc, args.mesh) from None
    U = solver.positions
    save_mesh(a["out"], U, F, overwrite_inputs=(args.mesh,))
    print_report(args.mesh, mesh.report)
    result = _result(args, a, regions, solver, timings, len(F))
    if args.json:
        emit_json(result)
    else:
        _print_text(result)
    return 0


def _result(args, a, regions, solver, timings, n_faces: int) -> dict[str, Any]:
    """The command's report as plain data (the ``--json`` object)."""
    summary = solver.summary()
    result: dict[str, Any] = {
        "file": str(args.mesh),
        "method": args.method,
        "n_vertices": summary["n_vertices"],
        "n_faces": n_faces,
        "handles": regions.seeds.tolist(),
        "radius": a["radius"],
        "n_handle_vertices": summary["n_handles"],
        "n_fixed": summary["n_fixed"],
        "n_still": summary["n_still"],
        "rotate": a["rotate"],
        "move": a["move"],
        "energy_name": summary["energy_name"],
        "energy": summary["energy"],
        "handle_error": summary["handle_error"],
        "displacement": summary_stats(solver.displacement()),
        "rotation_error": summary_stats(solver.rotation_error()),
        "system": {
            key: summary[key]
            for key in ("n_unknowns", "nnz", "factor_seconds", "setup_seconds", "backend")
        },
        "timings": timings,
        "out": str(a["out"]),
    }
    if args.method == "arap":
        result["iters"] = solver.iteration
        result["energies"] = list(solver.energies)
        result["arap_energy"] = summary["arap_energy"]
    return result


def _print_text(r: dict[str, Any]) -> None:
    s = r["system"]
    lines = [
        f"{r['method']} deformation of {r['file']} ({r['n_vertices']} vertices)",
        f"  handles     {r['n_handle_vertices']} vertices from {len(r['handles'])} seed(s)"
        + (f", radius {r['radius']:g}" if r["radius"] else "")
        + f"; fixed {r['n_fixed']}"
        + (f"; {r['n_still']} in components without a handle stay put" if r["n_still"] else ""),
        f"  energy      {r['energy']:.6g}  ({r['energy_name']})",
        f"  handles off their targets by at most {r['handle_error']:.3g}",
        f"  displacement max {r['displacement']['max']:.4g}, mean {r['displacement']['mean']:.4g}",
        f"  rotation error max {r['rotation_error']['max']:.4g}, "
        f"median {r['rotation_error']['median']:.4g}",
        f"  system      {s['n_unknowns']} unknowns, {s['nnz']} entries, factorized in "
        f"{s['factor_seconds']:.3f} s ({s['backend']})",
    ]
    if "iters" in r:
        lines.append(f"  ARAP        {r['iters']} iterations ({r['arap_energy']})")
    lines.append(f"wrote {r['out']}")
    sys.stdout.write("\n".join(lines) + "\n")
