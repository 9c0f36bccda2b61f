"""``meshlap heat MESH --vertex V --t T``: heat at time ``t`` from a unit of heat at vertices
(``--isolines N --curves FILE``: its level curves as OBJ polylines).

``u_t = Δu`` with ``Δ = M⁻¹C`` (negative semidefinite): ``--method euler`` takes ``--steps``
backward Euler steps ``(M + τK) u = M u_prev`` (``K = −C``, ``τ = t/steps``); ``--method
spectral`` sums ``Σ_{i<k} e^{−λ_i t} φ_i φ_iᵀ M u₀`` over the first ``--k`` eigenpairs (cached
like ``meshlap spectral``) and prints the truncation bound ``e^{−λ_{k−1} t}``.
"""

from __future__ import annotations

import argparse

from ..diffusion import HeatDiffusion, heat_spectral, truncation_bound, unit_heat
from ..diffusion.heat import check_time
from ..errors import MeshError
from ..io import load_mesh
from ..options import HEAT_METHODS, MASS_AREA, MAX_HEAT_STEPS
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
        "heat",
        help="heat diffusion from vertices: backward Euler or the eigen-expansion",
    )
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    add_vertex_flag(p)
    p.add_argument("--t", required=True, help="diffusion time t > 0 (length^2)")
    p.add_argument("--method", choices=HEAT_METHODS, default="euler", help="default: euler")
    p.add_argument(
        "--steps",
        type=int,
        default=None,
        help=f"backward Euler steps, 1 to {MAX_HEAT_STEPS} (default 1; --method euler)",
    )
    p.add_argument("--k", type=int, default=None, help="eigenmodes of --method spectral")
    p.add_argument("--no-cache", action="store_true", help="do not read or write the basis cache")
    p.add_argument("--out", help="write u: .npy, .csv or .ply")
    add_curve_flags(p, "heat u")
    add_json_flag(p)
    p.set_defaults(func=run, laplacian="cotan", area=MASS_AREA)


def run(args: argparse.Namespace) -> int:
    t = check_time(number_text(args.t, "--t"), "--t")
    out = output(args.out, args.mesh, OUT_SUFFIXES, "--out")
    curves = curves_path(args)
    if args.method == "spectral" and args.k is None:
        raise MeshError("--method spectral needs --k (the number of eigenmodes)", "--k")
    if args.method == "euler" and args.k is not None:
        raise MeshError("--k is the number of eigenmodes of --method spectral", "--k")
    if args.method == "euler" and args.no_cache:
        raise MeshError("--no-cache is for --method spectral (euler uses no basis)", "--no-cache")
    if args.method == "spectral" and args.steps is not None:
        raise MeshError("--steps is for --method euler (the expansion takes none)", "--steps")
    args.steps = 1 if args.steps is None else args.steps
    if args.steps < 1:
        raise MeshError(f"must be at least 1, got {args.steps}", "--steps")
    if args.steps > MAX_HEAT_STEPS:
        raise MeshError(
            f"at most {MAX_HEAT_STEPS} steps (beyond, each step's damping is within 3e-4 of "
            f"the exact flow's), got {args.steps}",
            "--steps",
        )
    mesh = load_mesh(args.mesh)
    V, F = mesh.V, mesh.F
    src = vertices(args, len(V))
    try:
        hd = HeatDiffusion(V, F)
    except MeshError as exc:
        raise exc.with_source(args.mesh) from None
    u0 = unit_heat(src, hd.mass)
    result: dict = {"file": str(args.mesh), "method": args.method, "t": t, "sources": src.tolist()}
    if args.method == "euler":
        try:
            u = hd.euler(u0, t, args.steps)
        except MeshError as exc:
            raise MeshError(exc.problem, "--t") from None
        result["steps"] = args.steps
    else:
        from .spectral import compute_basis

        if not 1 <= args.k <= len(V):
            raise MeshError(f"must be between 1 and {len(V)} (the vertices), got {args.k}", "--k")
        basis = compute_basis(args, V, F, args.k)
        u = heat_spectral(basis, u0, t)
        result["k"] = args.k
        result["truncation_bound"] = truncation_bound(basis.eigenvalues, t, args.k)
    result["total_heat"] = float(hd.mass @ u)
    result.update(summary_stats(u))
    print_report(args.mesh, mesh.report)
    save_field(out, V, F, u, args.mesh)
    write_curves(args, curves, V, F, u, result)
    result["out"] = str(out) if out else None
    if args.json:
        emit_json(result)
        return 0
    print(f"heat at t = {t:g} ({args.method}) from {len(src)} unit source(s)")
    print(f"  total heat {result['total_heat']:.6g} (conserved: {len(src)})")
    for k in ("min", "max", "mean"):
        print(f"  {k:<6}{result[k]: .6g}")
    if "truncation_bound" in result:
        print(
            f"  truncation bound exp(-λ_(k-1) t) = {result['truncation_bound']:.3g} at k = {args.k}"
        )
    for path in (out, curves):
        if path is not None:
            print(f"wrote {shown(path)}")
    return 0
