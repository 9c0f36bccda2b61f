"""``meshlap smooth MESH``: explicit, implicit or Taubin Laplacian smoothing with stability figures.

Sign convention: the Laplacian is negative semidefinite (``L = D⁻¹A − I`` or ``M⁻¹C``), so an
explicit step is ``x′ = x + λLx`` with ``λ > 0``.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path
from typing import Any

from ..errors import MeshError, MeshWarning
from ..options import AREA_KINDS
from ..smoothing import LAPLACIANS, MASS_MODES, METHODS, Smoother, check_iters, check_lam
from ._common import add_json_flag, emit_json, summary_stats


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "smooth",
        help="Laplacian smoothing (explicit, implicit, Taubin) with stability figures",
        description=(
            "Smooth a mesh with x' = x + lam L x (explicit), (I - lam L) x' = x (implicit, "
            "factorized once) or Taubin lam|mu steps. L is negative semidefinite: uniform "
            "D^-1 A - I (lam dimensionless, explicit stable for lam <= 1) or cotan M^-1 C (lam in "
            "length^2; the largest stable explicit lam is printed)."
        ),
    )
    p.add_argument("mesh", help="mesh file")
    p.add_argument("--method", choices=METHODS, default="explicit", help="default: explicit")
    p.add_argument("--laplacian", choices=LAPLACIANS, default="uniform", help="default: uniform")
    p.add_argument("--lam", default="0.5", help="step lambda > 0 (default 0.5)")
    p.add_argument("--iters", default="10", help="number of iterations >= 0 (default 10)")
    p.add_argument(
        "--taubin-mu", default=None, help="Taubin's negative factor (default from --pass-band)"
    )
    p.add_argument(
        "--pass-band",
        default="0.1",
        help="Taubin pass band relative to mean(-L_ii); equals k_PB for uniform (default 0.1)",
    )
    p.add_argument("--fix-boundary", action="store_true", help="keep boundary vertices fixed")
    p.add_argument(
        "--preserve-volume",
        action="store_true",
        help="rescale to keep the enclosed volume (closed meshes)",
    )
    p.add_argument(
        "--mass",
        choices=MASS_MODES,
        default="frozen",
        help="cotan mass matrix frozen (factorize once) or recomputed each step (default frozen)",
    )
    p.add_argument(
        "--area", choices=AREA_KINDS, default="voronoi", help="cotan lumped area (default voronoi)"
    )
    p.add_argument("--out", default=None, help="write the smoothed mesh here (not over the input)")
    add_json_flag(p)
    p.set_defaults(func=run)


def _float_arg(text: str | None, name: str) -> float | None:
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        raise MeshError(f"must be a number, got {text!r}", name) from None


def _int_arg(text: str, name: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise MeshError(f"must be an integer >= 0, got {text!r}", name) from None
    return check_iters(value, name)


def run(args: argparse.Namespace) -> int:
    from ..io import load_mesh  # imported here so --help never loads the mesh readers

    lam = check_lam(_float_arg(args.lam, "--lam"), "--lam")
    iters = _int_arg(args.iters, "--iters")
    nu = _float_arg(args.taubin_mu, "--taubin-mu")
    pass_band = check_lam(_float_arg(args.pass_band, "--pass-band"), "--pass-band")
    if args.out is not None and Path(args.out).resolve() == Path(args.mesh).resolve():
        raise MeshError("refusing to overwrite the input mesh", args.out)
    if args.out is not None:  # checked before the work: a doomed run fails at once
        from ..io import WRITE_FORMATS, check_output_path

        check_output_path(args.out, overwrite_inputs=[args.mesh], suffixes=WRITE_FORMATS)

    mesh = load_mesh(args.mesh)
    V, F = mesh.V, mesh.F
    msgs: list[str] = list(getattr(mesh.report, "warnings", []))
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MeshWarning)
        try:
            s = Smoother(
                V,
                F,
                args.method,
                args.laplacian,
                lam,
                taubin_nu=nu,
                pass_band=pass_band,
                fix_boundary=args.fix_boundary,
                preserve_volume=args.preserve_volume,
                mass=args.mass,
                area=args.area,
            )
        except MeshError as exc:
            raise _cli_error(exc, args.mesh) from None
    setup_s = time.perf_counter() - t0
    msgs += [str(w.message) for w in caught]

    t1 = time.perf_counter()
    report_every = max(1, iters // 10)
    for k in range(iters):
        s.step()
        if s.diverged:
            break
        if iters >= 50 and (k + 1) % report_every == 0:
            sys.stderr.write(f"smooth: {k + 1}/{iters} iterations\n")
    run_s = time.perf_counter() - t1
    t2 = time.perf_counter()
    stab = s.stability
    stab_s = time.perf_counter() - t2

    if s.diverged:
        raise MeshError(
            f"{args.method} smoothing diverged at iteration {s.iteration + 1} "
            f"(largest stable lam for this mesh: {_fmt(stab.max_stable_lam)}); nothing written",
            "--lam",
        )
    out_path = None
    if args.out is not None:
        from ..io import save_mesh

        save_mesh(args.out, s.V, F, overwrite_inputs=[args.mesh])
        out_path = str(args.out)

    last = s.history[-1]
    step_ms = [h["time_ms"] for h in s.history[1:]]
    result: dict[str, Any] = {
        "mesh": str(args.mesh),
        "n_vertices": len(V),
        "n_faces": len(F),
        "method": args.method,
        "laplacian": args.laplacian,
        "lam": lam,
        "taubin_mu": s.taubin_nu,
        "taubin_k_pb": s.k_pb if args.method == "taubin" else None,
        "iters": s.iteration,
        "fix_boundary": bool(args.fix_boundary),
        "preserve_volume": bool(args.preserve_volume),
        "mass": args.mass,
        "area": args.area,
        "closed": s.closed,
        "volume_change_pct": last["volume_change_pct"],
        "volume_note": s.volume_note,
        "drift_rms": last["drift_rms"],
        "stability": stab.as_dict(),
        "n_factorizations": s.n_factorizations,
        "timings": {
            "setup_s": setup_s,
            "smoothing_s": run_s,
            "stability_s": stab_s,
            "step_ms": summary_stats(step_ms) if step_ms else None,
        },
        "iterations": s.history,
        "out": out_path,
        "repairs": list(getattr(mesh.report, "repairs", [])),
        "warnings": msgs,
    }
    for r in result["repairs"]:  # after the work succeeded: a failing run prints one line
        sys.stderr.write(f"meshlap: {args.mesh}: repaired: {r}\n")
    for m in msgs:
        sys.stderr.write(f"meshlap: warning: {m}\n")
    if args.json:
        emit_json(result)
    else:
        print(format_smooth(result))
    return 0


def _cli_error(exc: MeshError, mesh: str) -> MeshError:
    """Map core argument names to the CLI flags users typed."""
    flags = {
        "lam": "--lam",
        "taubin_nu": "--taubin-mu",
        "pass_band": "--pass-band",
        "preserve_volume": "--preserve-volume",
        "mesh": str(mesh),
    }
    if exc.source in flags:
        return MeshError(exc.problem, flags[exc.source])
    return exc.with_source(mesh)


def _fmt(x: float | None, spec: str = ".4g") -> str:
    if x is None:
        return "none (unconditionally stable)"
    return format(x, spec)


def format_smooth(r: dict[str, Any]) -> str:
    """Human-readable report of :func:`run`'s result."""
    st = r["stability"]
    lines = [
        f"mesh        {r['mesh']}  ({r['n_vertices']} vertices, {r['n_faces']} faces, "
        f"{'closed' if r['closed'] else 'open'})",
        f"smoothing   {r['method']}, {r['laplacian']} Laplacian, lam={r['lam']:g}"
        + (f", mu={r['taubin_mu']:.4g}" if r["taubin_mu"] is not None else "")
        + f", {r['iters']} iterations"
        + (", boundary fixed" if r["fix_boundary"] else "")
        + (", volume preserved" if r["preserve_volume"] else ""),
        f"stability   highest frequency -mu_min = {-st['mu_min']:.4g}"
        + ("" if st["mu_min_exact"] else " (Gershgorin bound)")
        + f"; largest stable explicit lam = {st['explicit_lam_limit']:.4g}",
        f"            this method: g(mu_min) = {st['high_freq_gain']:.4g}, spectral radius "
        f"{st['spectral_radius']:.4g}, max stable lam {_fmt(st['max_stable_lam'])} -> "
        + ("STABLE" if st["stable"] else "UNSTABLE"),
    ]
    vc = r["volume_change_pct"]
    lines.append(
        "volume      " + (f"{vc:+.3f} % change" if vc is not None else str(r["volume_note"]))
    )
    lines.append(f"displacement RMS {r['drift_rms']:.4g} from the input")
    t = r["timings"]
    step = t["step_ms"]
    lines.append(
        f"time        setup {t['setup_s'] * 1e3:.1f} ms, "
        f"{r['iters']} steps {t['smoothing_s'] * 1e3:.1f} ms"
        + (f" (median {step['median']:.3f} ms/step)" if step else "")
        + f", {r['n_factorizations']} factorization(s)"
    )
    hist = r["iterations"]
    if len(hist) > 1:
        lines.append("")
        lines.append(f"{'iter':>6} {'step RMS':>11} {'drift RMS':>11} {'volume %':>10} {'ms':>8}")
        stride = max(1, (len(hist) - 1) // 20)
        shown = list(range(stride, len(hist), stride))
        if shown[-1] != len(hist) - 1:
            shown.append(len(hist) - 1)
        for h in (hist[i] for i in shown):
            v = h["volume_change_pct"]
            vs = f"{v:+10.3f}" if v is not None else f"{'n/a':>10}"
            lines.append(
                f"{h['iteration']:>6} {h['step_rms']:>11.4g} {h['drift_rms']:>11.4g} {vs} "
                f"{h['time_ms']:>8.3f}"
            )
    if r["out"]:
        lines.append(f"\nwrote {r['out']}")
    return "\n".join(lines)
