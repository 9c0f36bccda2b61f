"""``meshlap surface NAME``: the differential geometry of a parametric surface.

At one point (``--u U --v V``): fundamental forms, curvatures, principal directions (their
angles in the tangent plane from ``p_u``, ``theta_max``/``theta_min``, and in the ``(u, v)``
plane, ``theta_uv_max``/``theta_uv_min``) and the point's class; ``--plot kn.png`` draws the
normal curvature ``κₙ`` against the tangent-plane angle; ``--signs do-carmo`` reports them with
do Carmo's (the course's) sign of ``II``; ``--mesh out.obj --res N`` triangulates the surface;
``--convergence`` measures the discrete estimators against the exact curvature under refinement.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..curvature.convergence import convergence_study
from ..errors import MeshError
from ..options import DEFAULT_SURFACE_SIGNS, MESHERS, SURFACE_SIGNS
from ..surfaces import (
    PARAMETER_ANGLE_REFERENCE,
    SURFACES,
    TANGENT_ANGLE_REFERENCE,
    ParametricSurface,
    PointGeometry,
    check_mesh_res,
    check_uv,
    estimate_mesh_bytes,
    get_surface,
    mesh_surface,
    plot_normal_curvature,
    point_geometry,
    signs_note,
)
from ._common import add_json_flag, emit_json, parse_list, shown

DEFAULT_RES = {"grid": "8,16,32,64,128", "icosphere": "1,2,3,4,5"}
PROGRESS_BYTES = 256 * 1024**2  # --mesh: a line on stderr before meshes estimated above this


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "surface",
        help="fundamental forms, curvature and meshes of a parametric surface",
        description="Exact differential geometry of a parametric surface p(u,v) at one point, "
        "its normal-curvature plot, a mesh of it, or the convergence of the discrete curvature "
        "estimators on its meshes. Angles: theta_max/theta_min are the principal directions' "
        "angles in the tangent plane, measured from the unit p_u direction towards n × p_u "
        "(90° apart); theta_uv_max/theta_uv_min are the same directions in the (u, v) plane.",
    )
    p.add_argument(
        "name",
        nargs="?",
        default="helicoid",
        help=f"surface: {', '.join(SURFACES)} (default helicoid)",
    )
    p.add_argument("--u", type=float, help="parameter u (default: the surface's default point)")
    p.add_argument("--v", type=float, help="parameter v (default: the surface's default point)")
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="shape parameter, e.g. --param R=2 --param r=0.5 (repeatable)",
    )
    p.add_argument(
        "--plot",
        metavar="PNG",
        help="save a plot of the normal curvature κn against θ, the direction's angle in the "
        "tangent plane from p_u (towards n × p_u)",
    )
    p.add_argument(
        "--signs",
        choices=SURFACE_SIGNS,
        help="sign of the second fundamental form: outward (default, meshlap's: e = −p_uu·n, "
        "H > 0 on spheres as on meshes) or do-carmo (do Carmo's and the course's: e = p_uu·n; "
        "II, H, κ1, κ2 and κn negated, κ1 and κ2 swap directions, K unchanged)",
    )
    p.add_argument("--mesh", metavar="OUT", help="write a triangle mesh of the surface")
    p.add_argument(
        "--res",
        help="--mesh: cells per direction N or NU,NV (default 32); "
        f"--convergence: list of levels (default {DEFAULT_RES['grid']}, "
        f"icosphere {DEFAULT_RES['icosphere']})",
    )
    p.add_argument(
        "--convergence",
        action="store_true",
        help="table of discrete-vs-exact curvature errors and observed orders",
    )
    p.add_argument(
        "--mesher",
        choices=MESHERS,
        default="grid",
        help="--convergence meshes: the (u,v) grid (default) or icospheres (sphere only)",
    )
    p.add_argument(
        "--exclude-poles",
        action="store_true",
        help="--convergence: leave the pole vertices of a grid mesh out",
    )
    p.add_argument("--list", action="store_true", help="list the surfaces and exit")
    add_json_flag(p)
    p.set_defaults(func=run)


def _params(items: list[str]) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items:
        key, sep, val = item.partition("=")
        try:
            if not sep or not key.strip():
                raise ValueError
            out[key.strip()] = float(val)
        except ValueError:
            raise MeshError(f"expected KEY=NUMBER, got {item!r}", "--param") from None
    return out


def _vec(x: Any) -> str:
    return "(" + ", ".join(f"{c + 0.0:.6g}" for c in np.asarray(x).ravel()) + ")"


def _run_list(args: argparse.Namespace) -> int:
    rows = []
    for name in SURFACES:
        s = get_surface(name)
        rows.append(
            {
                "name": name,
                "domain": list(s.domain),
                "closed_u": s.closed_u,
                "closed_v": s.closed_v,
                "poles": list(s.poles),
                "params": dict(s.params),
                "exact_derivatives": s.derivatives is not None,
                "description": s.description,
            }
        )
    if args.json:
        emit_json({"surfaces": rows})
    else:
        for r in rows:
            params = ", ".join(f"{k}={v:g}" for k, v in r["params"].items())
            print(f"{r['name']:<14} {r['description']} [{params}]")
    return 0


def _run_convergence(args: argparse.Namespace, surface: Any) -> int:
    for flag, val in (
        ("--mesh", args.mesh),
        ("--plot", args.plot),
        ("--u", args.u),
        ("--v", args.v),
        ("--signs", None if args.signs in (None, DEFAULT_SURFACE_SIGNS) else args.signs),
    ):
        if val is not None:
            raise MeshError("cannot be combined with --convergence", flag)
    levels = parse_list(args.res or DEFAULT_RES[args.mesher], int, "--res")
    study = convergence_study(
        surface,
        levels,
        mesher=args.mesher,
        exclude_poles=args.exclude_poles,
        progress=lambda line: print(f"meshlap: {line}", file=sys.stderr, flush=True),
    )
    if args.json:
        emit_json({"params": dict(surface.params), **study.to_dict()})
    else:
        print(study.table())
    return 0


def run(args: argparse.Namespace) -> int:
    try:
        return _run(args)
    except MeshError as exc:  # name the flag the user typed, not the core's argument
        flag = {
            "res": "--res",
            "u": "--u",
            "v": "--v",
            "u, v": "--u/--v",
            "params": "--param",
            "mesher": "--mesher",
        }.get(exc.source or "")
        raise (MeshError(exc.problem, flag) if flag else exc) from None


def _run(args: argparse.Namespace) -> int:
    if args.list:
        return _run_list(args)
    surface = get_surface(args.name, **_params(args.param))
    if args.convergence:
        return _run_convergence(args, surface)
    if args.mesher != "grid" or args.exclude_poles:
        raise MeshError("only applies with --convergence", "--mesher/--exclude-poles")
    if args.res is not None and args.mesh is None:
        raise MeshError("needs --mesh or --convergence", "--res")
    u = surface.default_uv[0] if args.u is None else args.u
    v = surface.default_uv[1] if args.v is None else args.v
    check_uv(surface, u, v, names=("--u", "--v"))

    plot = Path(args.plot) if args.plot else None
    from ..io import WRITE_FORMATS, check_output_path

    # both outputs checked before either is written: a failing run leaves no file behind
    if plot is not None:
        check_output_path(plot, suffixes=(".png",))
    if args.mesh is not None:
        check_output_path(args.mesh, suffixes=WRITE_FORMATS)
        res = parse_list(args.res or "32", int, "--res")
        if len(res) > 2:
            raise MeshError(f"expected N or NU,NV, got {args.res!r}", "--res")
        nu, nv = check_mesh_res(surface, res[0] if len(res) == 1 else (res[0], res[1]), "--res")
    signs = args.signs or DEFAULT_SURFACE_SIGNS
    if plot is not None:
        geo = plot_normal_curvature(surface, u, v, plot, signs=signs)
    else:
        geo = point_geometry(surface, u, v, signs=signs)

    mesh_info = None if args.mesh is None else _write_mesh(surface, args.mesh, nu, nv)

    if args.json:
        emit_json(
            {
                **geo.to_dict(),
                "angles": {
                    "theta_max, theta_min": "radians in [0, pi), in the tangent plane from "
                    + TANGENT_ANGLE_REFERENCE,
                    "theta_uv_max, theta_uv_min": "radians in [0, pi), in "
                    + PARAMETER_ANGLE_REFERENCE,
                },
                "params": dict(surface.params),
                "plot": str(plot) if plot else None,
                "mesh": mesh_info,
            }
        )
        return 0
    _print_point(geo, surface)
    if plot is not None:
        print(f"wrote {shown(plot)}")
    if mesh_info is not None:
        print(
            f"wrote {args.mesh}: {mesh_info['n_vertices']} vertices, {mesh_info['n_faces']} faces"
        )
    return 0


def _write_mesh(surface: ParametricSurface, path: str, nu: int, nv: int) -> dict[str, Any]:
    """Mesh ``nu × nv`` cells (already checked), write them, return the JSON summary; a line on
    stderr first when the estimated peak memory is large."""
    from ..io import save_mesh

    need = estimate_mesh_bytes(nu, nv)
    if need >= PROGRESS_BYTES:
        print(
            f"meshlap: meshing the {surface.name}: {nu} x {nv} cells, estimated peak memory "
            f"{need / 1024**3:.2f} GiB",
            file=sys.stderr,
            flush=True,
        )
    m = mesh_surface(surface, (nu, nv))
    save_mesh(Path(path), m.V, m.F)
    return {
        "path": str(path),
        "res": list(m.res),
        "n_vertices": len(m.V),
        "n_faces": len(m.F),
        "n_boundary_vertices": int(m.boundary.sum()),
        "n_pole_vertices": int(m.pole.sum()),
    }


def _print_point(geo: PointGeometry, surface: ParametricSurface) -> None:
    """The text report of one point."""
    params = ", ".join(f"{k}={x:g}" for k, x in surface.params.items())
    print(f"{geo.surface} [{params}] at (u, v) = ({geo.u:.6g}, {geo.v:.6g})")
    print(f"  p    = {_vec(geo.p)}")
    print(f"  p_u  = {_vec(geo.p_u)}    p_v  = {_vec(geo.p_v)}")
    print(f"  p_uu = {_vec(geo.p_uu)}    p_uv = {_vec(geo.p_uv)}    p_vv = {_vec(geo.p_vv)}")
    print(f"  n    = {_vec(geo.n)}  (p_u x p_v normalized)")
    print(f"  first form   E = {geo.E:.6g}   F = {geo.F:.6g}   G = {geo.G:.6g}")
    print(f"  second form  e = {geo.e:.6g}   f = {geo.f:.6g}   g = {geo.g:.6g}")
    print(f"  K = {geo.K:.6g}   H = {geo.H:.6g}   ({geo.classification})")
    for k, t, t_uv, d_uv, d3, what in (
        (geo.k1, geo.theta_max, geo.theta_uv_max, geo.dir1_uv, geo.dir1, "max"),
        (geo.k2, geo.theta_min, geo.theta_uv_min, geo.dir2_uv, geo.dir2, "min"),
    ):
        name = "k1" if what == "max" else "k2"
        print(
            f"  {name} = {k:.6g}: κn is {what} at θ = {np.degrees(t):.6g}° (and θ + 180°), "
            f"θ_uv = {np.degrees(t_uv):.6g}°; direction (u,v) {_vec(d_uv)}, 3-D {_vec(d3)}"
        )
    print(f"  θ: angle in the tangent plane from {TANGENT_ANGLE_REFERENCE}")
    print(f"  θ_uv: angle in {PARAMETER_ANGLE_REFERENCE}")
    print(f"  {signs_note(geo.signs)}")
