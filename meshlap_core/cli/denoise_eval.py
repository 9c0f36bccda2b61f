"""``meshlap denoise-eval CLEAN``: sweep noise × method × λ × iterations and tabulate the errors.

Noise is added to CLEAN with a fixed seed (``σ = α × bbox diagonal``), or a given noisy file with
the same faces and vertex order is used (``--noisy``). Sign convention: the Laplacian is negative
semidefinite, an explicit step is ``x′ = x + λLx`` with ``λ > 0``.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError
from ..noise import check_noise, check_seed
from ..options import (
    AREA_KINDS,
    DEFAULT_NOISE_MODE,
    EULER_METHODS,
    LAPLACIAN_KINDS,
    NOISE_MODES,
    SMOOTHING_METHODS,
    check_choice,
)
from ..smoothing import (
    MAX_ITERS,
    best_rows,
    check_iters,
    check_lam,
    denoise_sweep,
)
from ._common import add_json_flag, emit_json, parse_list, print_report

COLUMNS = (
    "noise",
    "method",
    "laplacian",
    "lam",
    "iters",
    "rmse",
    "rmse_noisy",
    "max_error",
    "volume_change_pct",
    "volume_change_noisy_pct",
    "dihedral_mae_deg",
    "dihedral_mae_noisy_deg",
    "normal_dev_deg",
    "normal_dev_noisy_deg",
    "stable",
    "diverged",
    "seconds",
    "failed",
)
DEFAULT_NOISE = "0.005,0.02,0.05"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "denoise-eval",
        help="denoising sweep: noise x method x lam x iterations against a clean mesh",
        description=(
            "Add seeded Gaussian noise (sigma = alpha x bbox diagonal) to CLEAN, or take --noisy "
            "(same faces and vertex order), smooth it with every combination and report RMSE, "
            "volume change and dihedral-angle error against CLEAN."
        ),
    )
    p.add_argument("clean", help="clean reference mesh")
    p.add_argument(
        "--noisy", default=None, help="noisy version of CLEAN (same faces, same vertex order)"
    )
    p.add_argument("--noise", default=None, help=f"noise levels alpha (default {DEFAULT_NOISE})")
    p.add_argument(
        "--noise-mode", choices=NOISE_MODES, default=DEFAULT_NOISE_MODE, help="noise direction"
    )
    p.add_argument(
        "--methods",
        default=",".join(EULER_METHODS),
        help=f"from {','.join(SMOOTHING_METHODS)}",
    )
    p.add_argument("--laplacian", default="uniform", help="uniform and/or cotan (default uniform)")
    p.add_argument("--lam", default="0.1,0.5,1.0", help="step sizes (default 0.1,0.5,1.0)")
    p.add_argument(
        "--iters", default="10", help=f"iteration counts, each 0 to {MAX_ITERS} (default 10)"
    )
    p.add_argument("--seed", default="0", help="noise seed (default 0)")
    p.add_argument("--area", choices=AREA_KINDS, default="voronoi", help="cotan lumped area")
    p.add_argument("--csv", default=None, help="also write the table as CSV here")
    add_json_flag(p)
    p.set_defaults(func=run)


def _names(text: str, allowed: tuple[str, ...], flag: str) -> list[str]:
    values = [t.strip() for t in text.split(",") if t.strip()]
    if not values:
        raise MeshError("the list is empty", flag)
    for v in values:
        check_choice(v, allowed, "value", flag)
    return list(dict.fromkeys(values))


def _seed_and_noise(args: argparse.Namespace) -> tuple[int, list[float]]:
    """``--seed`` and the ``--noise`` levels (none with ``--noisy``), checked."""
    try:
        seed = int(args.seed)
    except ValueError:
        raise MeshError(f"must be an integer >= 0, got {args.seed!r}", "--seed") from None
    seed = check_seed(seed, "--seed")
    if args.noisy is not None and args.noise is not None:
        raise MeshError("cannot be combined with --noisy (that file fixes the noise)", "--noise")
    noise_text = args.noise or DEFAULT_NOISE
    noise = [] if args.noisy is not None else parse_list(noise_text, float, "--noise")
    for a in noise:
        if a < 0:
            raise MeshError(f"noise levels must be >= 0, got {a:g}", "--noise")
    return seed, noise


def _check_csv(args: argparse.Namespace) -> None:
    """Refuse a ``--csv`` path that is an input or cannot be written, before any work."""
    inputs = [Path(args.clean).resolve()] + ([Path(args.noisy).resolve()] if args.noisy else [])
    if Path(args.csv).resolve() in inputs:
        raise MeshError("refusing to overwrite an input mesh", args.csv)
    from ..io import check_output_path

    check_output_path(args.csv, overwrite_inputs=inputs, suffixes=(".csv",))


def run(args: argparse.Namespace) -> int:
    from ..io import load_mesh  # imported here so --help never loads the mesh readers

    methods = _names(args.methods, SMOOTHING_METHODS, "--methods")
    laplacians = _names(args.laplacian, LAPLACIAN_KINDS, "--laplacian")
    lams = [check_lam(v, "--lam") for v in parse_list(args.lam, float, "--lam")]
    iters = [check_iters(v, "--iters") for v in parse_list(args.iters, int, "--iters")]
    seed, noise = _seed_and_noise(args)
    if args.csv is not None:
        _check_csv(args)

    clean = load_mesh(args.clean)
    Vn = None
    if args.noisy is not None:
        noisy = load_mesh(args.noisy)
        if noisy.V.shape != clean.V.shape or not np.array_equal(noisy.F, clean.F):
            raise MeshError(
                f"must have the same faces and vertex order as {args.clean} "
                f"({len(noisy.V)} vs {len(clean.V)} vertices, "
                f"{len(noisy.F)} vs {len(clean.F)} faces"
                + (", different face lists" if noisy.F.shape == clean.F.shape else "")
                + ")",
                args.noisy,
            )
        Vn = noisy.V
    for a in noise:  # before any work: an amplitude that would overflow names --noise
        check_noise(clean.V, a, "--noise")

    def progress(line: str) -> None:
        sys.stderr.write(f"denoise-eval: {line}\n")

    t0 = time.perf_counter()
    try:
        rows = denoise_sweep(
            clean.V,
            clean.F,
            V_noisy=Vn,
            noise_levels=noise,
            methods=methods,
            laplacians=laplacians,
            lams=lams,
            iters=iters,
            seed=seed,
            noise_mode=args.noise_mode,
            area=args.area,
            progress=progress,
        )
    except MeshError as exc:
        raise exc.with_source(args.clean) from None
    seconds = time.perf_counter() - t0

    if args.csv is not None:
        _write_csv(args.csv, rows, [args.clean] + ([args.noisy] if args.noisy else []))
    result: dict[str, Any] = {
        "clean": str(args.clean),
        "noisy": None if args.noisy is None else str(args.noisy),
        "n_vertices": len(clean.V),
        "n_faces": len(clean.F),
        "noise_mode": None if args.noisy is not None else args.noise_mode,
        "seed": None if args.noisy is not None else seed,
        "volume_note": _volume_note(rows),
        "rows": [{k: r[k] for k in COLUMNS} for r in rows],
        "best": {
            "rmse": [_brief(r) for r in best_rows(rows, "rmse")],
            "dihedral_mae_deg": [_brief(r) for r in best_rows(rows, "dihedral_mae_deg")],
        },
        "seconds": seconds,
        "csv": args.csv,
        "repairs": list(getattr(clean.report, "repairs", [])),
        "warnings": list(getattr(clean.report, "warnings", [])),
    }
    print_report(args.clean, clean.report)
    if args.json:
        emit_json(result)
    else:
        print(format_table(result))
    return 0


def _volume_note(rows: list[dict[str, Any]]) -> str | None:
    if rows and rows[0]["volume_change_pct"] is None and not rows[0]["diverged"]:
        return "volume change undefined: the mesh is open (it has boundary edges)"
    return None


def _brief(r: dict[str, Any]) -> dict[str, Any]:
    keys = (
        "noise",
        "method",
        "laplacian",
        "lam",
        "iters",
        "rmse",
        "rmse_noisy",
        "dihedral_mae_deg",
        "dihedral_mae_noisy_deg",
        "volume_change_pct",
    )
    return {k: r[k] for k in keys}


def _write_csv(path: str, rows: list[dict[str, Any]], inputs: list[str]) -> None:
    from ..io import atomic_write

    with atomic_write(path, "w", overwrite_inputs=inputs) as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow(["" if r[k] is None else r[k] for k in COLUMNS])


def _num(x: Any, spec: str, width: int) -> str:
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return f"{'n/a':>{width}}"
    return f"{format(x, spec):>{width}}"


def format_table(r: dict[str, Any]) -> str:
    """The sweep as an aligned text table, then the best setting per noise level."""
    src = (
        f"noisy file {r['noisy']} (noise = measured RMS offset per coordinate / bbox diagonal)"
        if r["noisy"]
        else f"synthetic {r['noise_mode']} noise sigma = noise x bbox diagonal, seed {r['seed']}"
    )
    head = (
        f"{'noise':>8} {'laplacian':>9} {'method':>8} {'lam':>7} {'iters':>5} "
        f"{'RMSE':>10} {'RMSE in':>10} {'vol %':>8} {'dihed°':>7} {'dihed° in':>9} "
        f"{'normal°':>7}  note"
    )
    lines = [
        f"clean {r['clean']} ({r['n_vertices']} vertices), {src}",
        "RMSE/dihedral 'in' = the noisy input before smoothing; vol % = volume change vs clean",
        "",
        head,
        "-" * len(head),
    ]
    prev = None
    for row in r["rows"]:
        if prev is not None and row["noise"] != prev:
            lines.append("")
        prev = row["noise"]
        note = (
            f"FAILED: {row['failed']}"
            if row.get("failed")
            else "DIVERGED"
            if row["diverged"]
            else ("" if row["stable"] else "unstable lam")
        )
        lines.append(
            f"{row['noise']:>8.4g} {row['laplacian']:>9} {row['method']:>8} {row['lam']:>7.4g} "
            f"{row['iters']:>5d} {_num(row['rmse'], '.4g', 10)} "
            f"{_num(row['rmse_noisy'], '.4g', 10)} "
            f"{_num(row['volume_change_pct'], '+.2f', 8)} "
            f"{_num(row['dihedral_mae_deg'], '.2f', 7)} "
            f"{_num(row['dihedral_mae_noisy_deg'], '.2f', 9)} "
            f"{_num(row['normal_dev_deg'], '.2f', 7)}"
            f"  {note}".rstrip()
        )
    if r["volume_note"]:
        lines += ["", r["volume_note"]]
    for key, label in (("rmse", "lowest RMSE"), ("dihedral_mae_deg", "lowest dihedral error")):
        lines += ["", f"{label} per noise level:"]
        for b in r["best"][key]:
            lines.append(
                f"  noise {b['noise']:.4g}: {b['method']} {b['laplacian']} lam={b['lam']:g} "
                f"iters={b['iters']}  RMSE {b['rmse']:.4g} (noisy {b['rmse_noisy']:.4g}), "
                f"dihedral {b['dihedral_mae_deg']:.2f}° (noisy {b['dihedral_mae_noisy_deg']:.2f}°)"
            )
    lines += ["", f"{len(r['rows'])} rows in {r['seconds']:.2f} s"]
    if r["csv"]:
        lines.append(f"wrote {r['csv']}")
    return "\n".join(lines)
