"""``meshlap smooth MESH``: explicit, implicit or Taubin Laplacian smoothing with stability figures.

Sign convention: the Laplacian is negative semidefinite (``L = D⁻¹A − I`` or ``M⁻¹C``), so an
explicit step is ``x′ = x + λLx`` with ``λ > 0``.

Bounded work: ``--iters`` above :data:`~meshlap_core.smoothing.MAX_ITERS` (10⁷) is refused; the
per-iteration history keeps at most :data:`HISTORY_SAMPLES` entries (decimated, always with the
input and the last step; the JSON says the stride); a long run shows its progress on stderr.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal, TextIO

from ..errors import MeshError, MeshWarning
from ..options import (
    AREA_KINDS,
    DEFAULT_MASS_UPDATE,
    DEFAULT_SMOOTHING_METHOD,
    LAPLACIAN_KINDS,
    MASS_UPDATES,
    SMOOTHING_METHODS,
)
from ..progress import Progress
from ..smoothing import (
    MAX_ITERS,
    Smoother,
    check_iters,
    check_lam,
)
from ._common import add_json_flag, add_renamed_flag, emit_json, summary_stats

HISTORY_SAMPLES = 2000
"""At most this many per-iteration entries in the output (about 1 MB of JSON)."""


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
    p.add_argument(
        "--method",
        choices=SMOOTHING_METHODS,
        default=DEFAULT_SMOOTHING_METHOD,
        help=f"default: {DEFAULT_SMOOTHING_METHOD}",
    )
    p.add_argument(
        "--laplacian", choices=LAPLACIAN_KINDS, default="uniform", help="default: uniform"
    )
    p.add_argument("--lam", default="0.5", help="step lambda > 0 (default 0.5)")
    p.add_argument(
        "--iters",
        default="10",
        help=f"number of iterations, 0 to {MAX_ITERS} (default 10)",
    )
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
        "--mass-update",
        choices=MASS_UPDATES,
        default=DEFAULT_MASS_UPDATE,
        help="cotan mass matrix frozen (factorize once) or recomputed each step "
        f"(default {DEFAULT_MASS_UPDATE})",
    )
    add_renamed_flag(
        p,
        "--mass",
        "--mass-update (frozen|recompute); the area kind is --area (barycentric|voronoi)",
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
    digits = text.strip()
    if len(digits) > 40 and digits.isascii() and digits.isdigit():  # int() refuses > 4300 digits
        raise MeshError(f"must be at most {MAX_ITERS}, got a number of {len(digits)} digits", name)
    try:
        value = int(text)
    except ValueError:
        raise MeshError(f"must be an integer >= 0, got {text!r}", name) from None
    return check_iters(value, name)


def run(args: argparse.Namespace) -> int:
    """Check the arguments, smooth, write, and report.

    Long because the result's JSON object is spelled out key by key in one place (32 lines).
    """
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
    s, caught = _make_smoother(args, V, F, lam, nu, pass_band, iters)
    setup_s = time.perf_counter() - t0
    msgs += caught

    t1 = time.perf_counter()
    _iterate(s, iters)
    run_s = time.perf_counter() - t1
    t2 = time.perf_counter()
    stab = s.stability
    stab_s = time.perf_counter() - t2

    solver = s.solver_report()
    s.close()  # the helper process of the implicit solves, if any, ends here
    if s.diverged:
        raise MeshError(f"{s.divergence_message()}; nothing written", "--lam")
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
        "mass": args.mass_update,
        "area": args.area,
        "closed": s.closed,
        "volume_change_pct": last["volume_change_pct"],
        "volume_note": s.volume_note,
        "drift_rms": last["drift_rms"],
        "stability": stab.as_dict(),
        "n_factorizations": s.n_factorizations,
        "solver": solver,
        "timings": {
            "setup_s": setup_s,
            "smoothing_s": run_s,
            "stability_s": stab_s,
            "step_ms": summary_stats(step_ms) if step_ms else None,
        },
        "iterations": s.history,
        "iterations_stride": s.history_stride,
        "iterations_note": _history_note(s),
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


def _make_smoother(
    args: argparse.Namespace,
    V: Any,
    F: Any,
    lam: float,
    nu: float | None,
    pass_band: float,
    iters: int,
) -> tuple[Smoother, list[str]]:
    """The stepper of the command's options and the warnings its construction gave; the
    number of steps asked for picks the implicit solver (:meth:`Smoother.solver_report`)."""
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
                mass_update=args.mass_update,
                area=args.area,
                history_samples=HISTORY_SAMPLES,
                steps=iters,
            )
        except MeshError as exc:
            raise _cli_error(exc, args.mesh) from None
    return s, [str(w.message) for w in caught]


def _iterate(s: Smoother, iters: int) -> None:
    """Step ``iters`` times (progress on stderr for long runs), stopping if the run diverges."""
    progress = iteration_progress(iters)
    for k in range(iters):
        s.step()
        if s.diverged:
            break
        progress.update(k + 1)
    progress.close()


def _history_note(s: Smoother) -> str | None:
    if s.history_stride == 1:
        return None
    return (
        f"decimated: {len(s.history)} of {s.iteration + 1} entries kept (the input, every "
        f"{s.history_stride}th iteration and the last one; at most {HISTORY_SAMPLES}); "
        "timings.step_ms summarises the kept entries"
    )


def iteration_progress(
    total: int,
    stream: TextIO | Literal["stderr"] | None = "stderr",
    clock: Callable[[], float] = time.monotonic,
) -> Progress:
    """Progress of a long smoothing run on stderr, never in the way of a short run's output.

    On a terminal: one line redrawn in place once a second has passed, at most every 0.5 s,
    erased at the end. Otherwise (a pipe, a log, a test capturing stderr): nothing for the first
    10 s, then one full line every 30 s; a run shorter than 10 s prints nothing.
    ``smooth: 10/100 iterations (10.0 %), 10 s elapsed, about 90 s left``.
    """
    return Progress(
        total,
        _iterations_line,
        "smooth",
        stream=stream,
        erase=True,
        after_s=10.0,
        every_s=30.0,
        tty_after_s=1.0,
        tty_every_s=0.5,
        clock=clock,
    )


def _iterations_line(p: Progress) -> str:
    left = p.elapsed * (p.total - p.done) / p.done if p.done else float("nan")
    return (
        f"{p.label}: {p.done}/{p.total} iterations ({100.0 * p.done / p.total:.1f} %), "
        f"{p.elapsed:.0f} s elapsed, about {left:.0f} s left"
    )


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
    solver = r["solver"]
    if solver.get("answering") is not None:
        lines.append(f"solver      {solver['answering']}: {solver['reason']}")
    hist = r["iterations"]
    if len(hist) > 1:
        lines.append("")
        if r["iterations_note"]:
            lines.append(f"history {r['iterations_note']}")
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
