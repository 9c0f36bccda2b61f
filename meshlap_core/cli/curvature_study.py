"""``meshlap curvature-study``: every curvature estimator against the exact curvature of the
parametric surfaces under refinement, as a table of errors and observed orders (CSV) and a
log-log figure of the error against h with the fitted orders (PNG)."""

from __future__ import annotations

import argparse
import csv
import io
import math
from pathlib import Path

from ..curvature.study import STUDY_COLUMNS, curvature_study, write_study_figure
from ..errors import MeshError
from ..io import check_output_path
from ..io.atomic import atomic_write
from ..noise import check_seed
from ..options import CURVATURE_ESTIMATORS, check_choice
from ..surfaces import SURFACES
from ._common import add_json_flag, emit_json, parse_list, shown

DEFAULT_SURFACES = "sphere,torus,saddle,helicoid"
DEFAULT_LEVELS = "16,32,64"
MAX_LEVEL = 512
"""Largest resolution (cells per direction) accepted: 512² cells is ~0.5M vertices."""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "curvature-study",
        help="curvature estimators vs exact parametric surfaces: errors and orders (CSV)",
        description=(
            "Mesh each parametric surface at each resolution (optionally jittered and noisy), "
            "run each estimator and compare k1 >= k2, H, K and the principal direction with the "
            "exact values at the vertices away from boundaries and poles."
        ),
    )
    p.add_argument("--surfaces", default=DEFAULT_SURFACES, help=f"from {','.join(SURFACES)}")
    p.add_argument(
        "--estimators",
        default=",".join(CURVATURE_ESTIMATORS),
        help=f"from {','.join(CURVATURE_ESTIMATORS)}",
    )
    p.add_argument(
        "--levels", default=DEFAULT_LEVELS, help="cells per direction (torus: x2 around)"
    )
    p.add_argument(
        "--noise", type=float, default=0.0, help="normal noise, fraction of bbox diagonal"
    )
    p.add_argument("--jitter", type=float, default=0.0, help="parameter jitter, fraction of a cell")
    p.add_argument("--flips", type=float, default=0.0, help="fraction of interior edges flipped")
    p.add_argument("--seed", type=int, default=0, help="noise, jitter and flips seed")
    p.add_argument("--csv", default=None, help="write the table as CSV here")
    p.add_argument(
        "--figure",
        default=None,
        help="write the log-log plot of error vs h (H and K, fitted orders) as PNG here",
    )
    add_json_flag(p)
    p.set_defaults(func=run)


def _names(text: str, allowed: tuple[str, ...] | list[str], flag: str) -> list[str]:
    values = [t.strip() for t in text.split(",") if t.strip()]
    if not values:
        raise MeshError("the list is empty", flag)
    for v in values:
        check_choice(v, tuple(allowed), "value", flag)
    return list(dict.fromkeys(values))


def _fmt(x: object) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    return f"{x:.6g}" if isinstance(x, float) else str(x)


def _output(path: str | None, flag: str, suffix: str) -> Path | None:
    """An output flag's path checked before the work (an empty name refused, not ignored)."""
    if path is None:
        return None
    if not path.strip():
        raise MeshError(f"the output path is empty (give a file name or leave {flag} out)", flag)
    return check_output_path(Path(path), suffixes=(suffix,))


def _fraction(value: float, lo: float, hi: float, flag: str, what: str) -> float:
    """A finite number in ``[lo, hi]`` (NaN and negatives refused, never ignored)."""
    if not (math.isfinite(value) and lo <= value <= hi):
        raise MeshError(f"must be {lo:g} to {hi:g} ({what}), got {value}", flag)
    return value


def run(args: argparse.Namespace) -> int:
    out = _output(args.csv, "--csv", ".csv")
    figure = _output(args.figure, "--figure", ".png")
    surfaces = _names(args.surfaces, list(SURFACES), "--surfaces")
    estimators = _names(args.estimators, CURVATURE_ESTIMATORS, "--estimators")
    levels = list(dict.fromkeys(parse_list(args.levels, int, "--levels")))  # (each level once)
    if any(n < 3 or n > MAX_LEVEL for n in levels):
        raise MeshError(f"levels must be 3 to {MAX_LEVEL}, got {levels}", "--levels")
    noise = _fraction(args.noise, 0.0, 0.1, "--noise", "of the bounding-box diagonal")
    jitter = _fraction(args.jitter, 0.0, 0.45, "--jitter", "of a cell")
    flips = _fraction(args.flips, 0.0, 1.0, "--flips", "of the interior edges")
    seed = check_seed(args.seed, "--seed")
    try:
        rows = curvature_study(surfaces, estimators, levels, noise, jitter, seed, flips=flips)
    except MeshError as exc:
        flag = {"noise": "--noise", "jitter": "--jitter", "flips": "--flips", "seed": "--seed"}
        if exc.source in flag:
            raise MeshError(exc.problem, flag[exc.source]) from None
        raise
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(STUDY_COLUMNS)
    for r in rows:
        w.writerow([_fmt(r[c]) for c in STUDY_COLUMNS])
    if out is not None:
        with atomic_write(out) as f:
            f.write(buf.getvalue())
    if figure is not None:
        write_study_figure(rows, figure)
    if args.json:
        emit_json(
            {
                "rows": rows,
                "csv": str(out) if out else None,
                "figure": str(figure) if figure else None,
            }
        )
        return 0
    show = ("surface", "estimator", "res", "n_vertices", "H_rel", "H_order", "K_rel", "K_order")
    print(" ".join(f"{c:>12}" for c in show) + f" {'angle_p95':>10}")
    for r in rows:
        cells = [_fmt(r[c]) for c in show] + [_fmt(r["angle_p95_deg"])]
        print(" ".join(f"{c:>12}" for c in cells))
    if out is not None:
        print(f"wrote {shown(out)}")
    if figure is not None:
        print(f"wrote {shown(figure)}")
    return 0
