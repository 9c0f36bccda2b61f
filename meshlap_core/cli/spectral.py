"""``meshlap spectral MESH --k K``: Laplace–Beltrami eigenbasis and spectral reconstruction.

Sign convention: the Laplacian is negative semidefinite (``Δ = M⁻¹C``); the eigenvalues printed
are the non-negative frequencies ``λ`` of ``−C u = λ M u``. The reconstruction from ``k``
modes is the ``M``-orthogonal projection ``U_k U_kᵀ M V``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from ..errors import MeshError
from ..options import AREA_KINDS, LAPLACIAN_KINDS, MASS_AREA
from ..progress import Progress
from ..spectral import SpectralBasis
from ._common import add_json_flag, add_renamed_flag, emit_json, parse_list

_DEFAULT_RECONSTRUCT = (5, 15, 50, 100, 300, 1000)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "spectral",
        help="Laplace-Beltrami eigenbasis (cached) and reconstruction from k modes",
        description=(
            "Compute the k lowest eigenpairs of -C u = lambda M u (C cotangent stiffness, M lumped "
            "mass; or the graph Laplacian D - A with M = I), cache them, and report the "
            "reconstruction error of the vertices from the first k' modes, U U^T M V."
        ),
    )
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument("--k", required=True, help="number of eigenmodes (1 <= K <= vertices)")
    p.add_argument(
        "--area",
        choices=AREA_KINDS,
        default=MASS_AREA,
        help=f"vertex area of the lumped mass M of the cotan Laplacian (default {MASS_AREA})",
    )
    add_renamed_flag(p, "--mass", "--area (the area kind of the mass matrix, barycentric|voronoi)")
    p.add_argument(
        "--laplacian",
        choices=LAPLACIAN_KINDS,
        default="cotan",
        help="cotan (default) or uniform (graph Laplacian D - A, identity mass)",
    )
    p.add_argument(
        "--reconstruct",
        default=None,
        help="comma-separated mode counts to reconstruct with, each <= K "
        "(default: 5,15,50,100,300,1000 up to K, and K)",
    )
    p.add_argument(
        "--save-reconstruction",
        metavar="DIR",
        default=None,
        help="write each reconstruction as DIR/<mesh>_k<k>.obj",
    )
    p.add_argument("--out", default=None, help="also save the basis as this .npz file")
    p.add_argument(
        "--no-cache",
        action="store_true",
        help="neither read nor write the user cache "
        "($MESHLAP_CACHE_DIR, $XDG_CACHE_HOME/meshlap or ~/.cache/meshlap)",
    )
    add_json_flag(p)
    p.set_defaults(func=run)


def _solve_progress() -> Progress:
    """Lines on stderr for a solve that takes a while: the first after a second, then at most
    one a second (``meshlap spectral:  40% message``); ``update(fraction, message)`` is the
    solver's progress callback."""
    return Progress(1.0, _solve_line, in_place=False, after_s=1.0, every_s=1.0)


def _solve_line(p: Progress) -> str:
    return f"meshlap spectral: {100 * p.done:3.0f}% {p.message}"


def _parse_k(text: str) -> int:
    try:
        k = int(text)
    except (TypeError, ValueError):
        raise MeshError(f"must be a positive integer, got {text!r}", "--k") from None
    if k < 1:
        raise MeshError(f"must be a positive integer, got {text!r}", "--k")
    return k


def _check_args(args: argparse.Namespace) -> tuple[int, list[int] | None, Path | None]:
    """``(k, reconstruct list or None, reconstruction folder or None)``, every output checked
    before the work (a doomed run fails at once)."""
    from ..io import check_output_path

    k = _parse_k(args.k)
    recon = None
    if args.reconstruct is not None:
        recon = parse_list(args.reconstruct, int, "--reconstruct")
        bad = [r for r in recon if r < 1 or r > k]
        if bad:
            raise MeshError(
                f"each value must be between 1 and --k = {k}; got {bad[0]}", "--reconstruct"
            )
    if args.out is not None:
        check_output_path(args.out, overwrite_inputs=[args.mesh], suffixes=(".npz",))
    out_dir = None
    if args.save_reconstruction is not None:
        out_dir = Path(args.save_reconstruction)
        if out_dir.exists() and not out_dir.is_dir():
            raise MeshError("exists and is not a directory", args.save_reconstruction)
    return k, recon, out_dir


def compute_basis(args: argparse.Namespace, V: Any, F: Any, k: int) -> SpectralBasis:
    """The basis, errors attributed to the mesh file or ``--k``; a cache file that failed its
    checks (and was recomputed) is said on stderr."""
    try:
        basis = SpectralBasis.compute(
            V,
            F,
            k,
            laplacian=args.laplacian,
            area=args.area,
            cache=not args.no_cache,
            progress=_solve_progress().update,
        )
    except MeshError as exc:
        if exc.source in ("k", "--k"):
            raise MeshError(exc.problem, "--k") from None
        if exc.source in ("K", "m"):  # the pencil of this mesh: the solver's checks
            raise MeshError(exc.problem, args.mesh) from None
        raise exc.with_source(args.mesh) from None
    for msg in basis.info.messages:
        if msg.startswith("ignored cache file"):
            sys.stderr.write(f"meshlap spectral: {msg}; recomputed\n")
    return basis


def run(args: argparse.Namespace) -> int:
    from ..io import load_mesh, save_mesh

    t_start = time.perf_counter()
    k, recon, out_dir = _check_args(args)
    mesh = load_mesh(args.mesh)
    V, F = mesh.V, mesh.F
    n = len(V)
    if k > n:
        raise MeshError(
            f"asks for {k} eigenmodes but {args.mesh} has only {n} vertices "
            f"(at most {n}; --k {n} is the full basis)",
            "--k",
        )
    if recon is None:
        recon = sorted({r for r in _DEFAULT_RECONSTRUCT if r < k} | {k})
    t_load = time.perf_counter() - t_start

    basis = compute_basis(args, V, F, k)
    info = basis.info

    t0 = time.perf_counter()
    errs = basis.errors_at(recon)  # (the rows asked for only: not every k up to the largest)
    rows = [errs.row(r) for r in recon]
    t_err = time.perf_counter() - t0

    written: list[str] = []
    t0 = time.perf_counter()
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        stem = Path(args.mesh).stem
        for r in recon:
            path = out_dir / f"{stem}_k{r}.obj"
            save_mesh(path, basis.reconstruct(r), F, overwrite_inputs=[args.mesh])
            written.append(str(path))
    if args.out is not None:
        basis.save(args.out, overwrite_inputs=[args.mesh])
    t_write = time.perf_counter() - t0

    timings = {"load": t_load}
    timings.update({key: float(v) for key, v in info.timings.items()})
    timings.setdefault("eigensolve", 0.0)
    timings["errors"] = t_err
    timings["write"] = t_write
    timings["total"] = time.perf_counter() - t_start
    result: dict[str, Any] = {
        "mesh": str(args.mesh),
        "n_vertices": n,
        "n_faces": len(F),
        "k": k,
        "laplacian": basis.options["laplacian"],
        "mass": basis.options["mass"],
        "eigenvalues": basis.eigenvalues.tolist(),
        "timings": timings,
        "reconstruction": rows,
        "bbox_diagonal": errs.diagonal,
        "method": info.method,
        "from_cache": info.from_cache,
        "cache_file": info.cache_path,
        "n_components": info.n_components,
        "n_clipped_eigenvalues": info.n_clipped,
        "max_residual": info.max_residual,
        "orthogonality_error": info.orthogonality_error,
        "saved_reconstructions": written,
        "out": None if args.out is None else str(args.out),
        "repairs": list(getattr(mesh.report, "repairs", [])),
        "messages": list(info.messages),
    }
    for r in result["repairs"]:  # after the work succeeded: a failing run prints one line
        sys.stderr.write(f"meshlap: {args.mesh}: repaired: {r}\n")
    if args.json:
        emit_json(result)
    else:
        print(format_spectral(result))
    return 0


def format_spectral(r: dict[str, Any]) -> str:
    """Human-readable report of :func:`run`'s result."""
    lam = r["eigenvalues"]
    shown = ", ".join(f"{x:.6g}" for x in lam[:10]) + (", ..." if len(lam) > 10 else "")
    src = "cache" if r["from_cache"] else r["method"]
    lines = [
        f"{r['mesh']}: {r['n_vertices']:,} vertices, {r['n_faces']:,} faces",
        f"Laplacian: {r['laplacian']}, mass: {r['mass']} (eigenvalues of "
        + ("-C u = lambda M u)" if r["laplacian"] == "cotan" else "(D - A) u = lambda u)"),
        f"{r['k']} eigenpairs from {src} in {r['timings']['eigensolve']:.2f} s "
        f"(total {r['timings']['total']:.2f} s)",
        f"eigenvalues: {shown}",
        f"components: {r['n_components']} (one zero eigenvalue each); "
        f"max|U^T M U - I| = {_fmt(r['orthogonality_error'])}, "
        f"max relative residual {_fmt(r['max_residual'])}",
        "",
        f"reconstruction error |x - x_k| (bbox diagonal {r['bbox_diagonal']:.4g}):",
        f"{'k':>6} {'mean':>11} {'max':>11} {'rms':>11} {'mean/diag':>10}",
    ]
    for row in r["reconstruction"]:
        lines.append(
            f"{row['k']:>6} {row['mean_error']:>11.4g} {row['max_error']:>11.4g} "
            f"{row['rms_error']:>11.4g} {row['relative_mean_error']:>10.3e}"
        )
    for path in r["saved_reconstructions"]:
        lines.append(f"wrote {path}")
    if r["out"]:
        lines.append(f"wrote {r['out']}")
    if r["cache_file"] and not r["from_cache"]:
        lines.append(f"cached in {r['cache_file']}")
    lines += [f"note: {m}" for m in r["messages"]]
    return "\n".join(lines)


def _fmt(x: float | None) -> str:
    return "n/a" if x is None or x != x else f"{x:.1e}"
