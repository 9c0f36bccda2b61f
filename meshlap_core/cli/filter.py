"""``meshlap filter MESH --k K (--low-pass K' | --band A:B --gain G | --taubin LAM MU N | …)
--out filtered.obj``: a spectral filter of the vertex positions.

The filtered mesh is ``U h(Λ) Uᵀ M X`` over the first ``K`` eigenpairs (cached like ``meshlap
spectral``); ``--residual`` adds back what the modes do not represent (``X − U Uᵀ M X``),
which a band exaggeration usually wants. ``--explicit LAM N``, ``--implicit LAM N`` and
``--taubin LAM MU N`` apply the transfer functions of those smoothers (cotangent Laplacian,
frozen operator): ``(1 − LAM λ)^N``, ``(1 + LAM λ)^−N``, ``((1 − LAM λ)(1 − MU λ))^N``.
"""

from __future__ import annotations

import argparse

import numpy as np

from ..diffusion import SpectralFilter, transfer
from ..errors import MeshError
from ..io import WRITE_FORMATS, load_mesh, save_mesh
from ..options import MASS_AREA, SMOOTHING_METHODS
from ..smoothing.params import check_iters
from ._common import add_json_flag, emit_json, print_report, shown
from ._sources import output

OUT_SUFFIXES = WRITE_FORMATS  # (what save_mesh writes: refused before the work otherwise)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("filter", help="spectral filter of the geometry: U h(Λ) Uᵀ M X")
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument("--k", type=int, required=True, help="eigenmodes used (1 <= K <= vertices)")
    kind = p.add_mutually_exclusive_group(required=True)
    kind.add_argument("--low-pass", type=int, metavar="K2", help="keep the K2 lowest modes")
    kind.add_argument("--band", metavar="A:B", help="multiply modes A..B-1 by --gain")
    kind.add_argument("--explicit", nargs=2, metavar=("LAM", "N"), help="explicit smoother")
    kind.add_argument("--implicit", nargs=2, metavar=("LAM", "N"), help="implicit smoother")
    kind.add_argument("--taubin", nargs=3, metavar=("LAM", "MU", "N"), help="Taubin smoother")
    p.add_argument("--gain", type=float, default=None, help="gain of --band (default 2)")
    p.add_argument("--residual", action="store_true", help="add back X − U Uᵀ M X")
    p.add_argument("--no-cache", action="store_true", help="do not read or write the basis cache")
    p.add_argument("--out", required=True, help=f"the filtered mesh ({', '.join(OUT_SUFFIXES)})")
    add_json_flag(p)
    p.set_defaults(func=run, laplacian="cotan", area=MASS_AREA)


def _float(text: str, flag: str) -> float:
    """A finite float from the command line (``nan``, ``inf``, ``1e999`` refused)."""
    try:
        value = float(text)
    except ValueError:
        raise MeshError(f"expected a number, got {text!r}", flag) from None
    if not np.isfinite(value):
        raise MeshError(f"must be finite, got {text!r}", flag)
    return value


def _int(text: str, flag: str, what: str) -> int:
    """An integer from the command line (``2.5``, ``1e3`` refused; any number of digits is
    read without overflow: the range checks that follow say what fits)."""
    digits = text.strip()
    if len(digits) > 40 and digits.lstrip("+-").isdigit():  # int() refuses > 4300 digits
        sign = "-" if digits.startswith("-") else ""
        return int(sign + "9" * 41)  # (out of every range: the caller's check names it)
    try:
        return int(digits)
    except ValueError:
        raise MeshError(f"expected {what} (an integer), got {text!r}", flag) from None


def _gains(args: argparse.Namespace, lam: np.ndarray) -> tuple[str, np.ndarray]:
    """The filter's name and its gain per mode (every one finite, else refused naming the
    flag)."""
    name, flag, h = _filter(args, lam)
    bad = np.flatnonzero(~np.isfinite(h))
    if len(bad):
        raise MeshError(
            f"the filter's gain overflows at mode {int(bad[0])} (lambda = {lam[bad[0]]:.4g}): "
            "fewer steps, a smaller step or fewer modes (--k)",
            flag,
        )
    return name, h


def _filter(args: argparse.Namespace, lam: np.ndarray) -> tuple[str, str, np.ndarray]:
    """The filter's name, its flag and its gains (unchecked)."""
    k = len(lam)
    if args.low_pass is not None:
        if not 0 <= args.low_pass <= k:
            raise MeshError(f"must be between 0 and --k = {k}, got {args.low_pass}", "--low-pass")
        return "low-pass", "--low-pass", transfer("low-pass", lam, keep=args.low_pass)
    if args.band is not None:
        parts = args.band.split(":")
        if len(parts) != 2:
            raise MeshError(f"expected A:B (mode indices), got {args.band!r}", "--band")
        a, b = (_int(x, "--band", "a mode index") for x in parts)
        if not 0 <= a < b <= k:
            raise MeshError(f"needs 0 <= A < B <= --k = {k}, got {args.band!r}", "--band")
        if not np.isfinite(args.gain):
            raise MeshError(f"must be finite, got {args.gain}", "--gain")
        return "band", "--band", transfer("band", lam, band=(a, b), gain=args.gain)
    for name in SMOOTHING_METHODS:
        vals = getattr(args, name)
        if vals is None:
            continue
        flag = f"--{name}"
        step = _float(vals[0], flag)
        iters = check_iters(_int(vals[-1], flag, "N, a number of steps"), flag)
        nu = _float(vals[1], flag) if name == "taubin" else 0.0
        if step <= 0:
            raise MeshError(f"needs LAM > 0, got {vals[0]!r}", flag)
        if name == "taubin" and not nu < -step:
            raise MeshError(
                f"needs MU < -LAM (Taubin's second step inflates: MU negative and larger than "
                f"LAM in size), got LAM = {vals[0]}, MU = {vals[1]}",
                flag,
            )
        try:
            gains = transfer(name, lam, step=step, iters=iters, nu=nu)  # type: ignore[arg-type]
        except MeshError as exc:  # (the core names its argument; here it is the flag)
            raise MeshError(exc.problem, flag) from None
        return name, flag, gains
    raise MeshError("choose a filter", "--low-pass")  # argparse requires one


def run(args: argparse.Namespace) -> int:
    out = output(args.out, args.mesh, OUT_SUFFIXES, "--out")
    if out is None:  # --out is required: argparse has refused its absence already
        raise MeshError("give the output mesh", "--out")
    if args.gain is not None and args.band is None:
        raise MeshError("--gain is the gain of --band; it has no meaning here", "--gain")
    args.gain = 2.0 if args.gain is None else args.gain
    if not np.isfinite(args.gain):  # before the work (the eigenbasis)
        raise MeshError(f"must be finite, got {args.gain}", "--gain")
    mesh = load_mesh(args.mesh)
    V, F = mesh.V, mesh.F
    if not 1 <= args.k <= len(V):
        raise MeshError(f"must be between 1 and {len(V)} (the vertices), got {args.k}", "--k")
    from .spectral import compute_basis

    basis = compute_basis(args, V, F, args.k)
    name, h = _gains(args, basis.eigenvalues)
    X = SpectralFilter(basis).apply(h, residual=args.residual)
    print_report(args.mesh, mesh.report)
    save_mesh(out, X, F, overwrite_inputs=(args.mesh,))
    moved = np.linalg.norm(X - V, axis=1)
    result = {
        "file": str(args.mesh),
        "filter": name,
        "k": args.k,
        "residual": bool(args.residual),
        "gain_min": float(h.min()),
        "gain_max": float(h.max()),
        "displacement_max": float(moved.max()),
        "displacement_mean": float(moved.mean()),
        "out": str(out),
    }
    if args.json:
        emit_json(result)
    else:
        print(f"{name} filter over {args.k} modes (gain {h.min():.3g} .. {h.max():.3g})")
        print(f"  vertex displacement: max {moved.max():.6g}, mean {moved.mean():.6g}")
        print(f"wrote {shown(out)}")
    return 0
