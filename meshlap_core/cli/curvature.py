"""``meshlap curvature MESH --method ... [--estimator NAME]``: a per-vertex curvature field and
its statistics.

Without ``--estimator`` the fields of :mod:`meshlap_core.curvature` (``--method uniform, cotan,
gaussian, k1, k2``); with it (or with ``--method H, K, abs_max``) a field of the principal
curvatures of :mod:`meshlap_core.curvature.estimators` (``--method k1, k2, H, K, abs_max``,
estimator ``cotan`` when not given), ``--radius`` its scale (quadric: edge rings; jet: world
units) and ``--directions FILE.npy`` the ``(n, 2, 3)`` principal directions ``d1, d2``.
"""

from __future__ import annotations

import argparse
import os
import threading
from pathlib import Path
from typing import Any

import numpy as np

from ..curvature import curvature_field
from ..curvature.fields import check_ring_radius
from ..errors import MeshError
from ..io import check_output_path, load_mesh
from ..io.atomic import atomic_write
from ..mesh import Mesh
from ..options import (
    AREA_KINDS,
    BOUNDARY_RULES,
    CURVATURE_AREA,
    CURVATURE_ESTIMATORS,
    CURVATURE_METHODS,
    DEFAULT_BOUNDARY,
    DEFAULT_CURVATURE_FIELD,
    PRINCIPAL_FIELDS,
)
from ._common import add_json_flag, emit_json, print_report, save_field, shown, summary_stats

OUT_SUFFIXES = (".csv", ".npy", ".ply")
METHODS: tuple[str, ...] = CURVATURE_METHODS + tuple(
    m for m in PRINCIPAL_FIELDS if m not in CURVATURE_METHODS
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("curvature", help="per-vertex mean / Gaussian / principal curvature")
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument(
        "--method",
        choices=METHODS,
        default=None,
        help="uniform H, cotangent H, angle-deficit K, or principal k1/k2 (default cotan); "
        "with --estimator: k1, k2, H (default), K or abs_max",
    )
    p.add_argument(
        "--estimator",
        choices=CURVATURE_ESTIMATORS,
        help="principal curvatures by this estimator (k1 >= k2, H > 0 on spheres): cotan "
        "(Meyer 2003), quadric (libigl), rusinkiewicz (2004), jet (robust to noise)",
    )
    p.add_argument(
        "--radius",
        type=float,
        help="the estimator's scale: quadric edge rings (default 5), jet world units "
        "(default automatic, from the edge length and the estimated noise)",
    )
    p.add_argument("--directions", help="with an estimator: write d1, d2 as (n, 2, 3) .npy")
    p.add_argument(
        "--area",
        choices=AREA_KINDS,
        default=CURVATURE_AREA,
        help="vertex area (default voronoi, the mixed area that converges; barycentric: the "
        "course's)",
    )
    p.add_argument(
        "--boundary",
        choices=BOUNDARY_RULES,
        default=DEFAULT_BOUNDARY,
        help="angle deficit at boundary vertices: pi - sum (default), 2pi - sum, or zero",
    )
    p.add_argument(
        "--out", help="write the field: .csv, .npy, or .ply (mesh with a 'quality' property)"
    )
    add_json_flag(p)
    p.set_defaults(func=run)


def _outputs(args: argparse.Namespace) -> tuple[Path | None, Path | None]:
    """``--out`` and ``--directions`` checked first (a doomed run fails at once and writes
    nothing): not empty, writable, not the input, not one and the same file."""
    paths = []
    for flag, text, suffixes in (
        ("--out", args.out, OUT_SUFFIXES),
        ("--directions", args.directions, (".npy",)),
    ):
        if text is not None and not text.strip():
            raise MeshError(
                f"the output path is empty (give a file name or leave {flag} out)", flag
            )
        paths.append(None if text is None else Path(text))
        if text is not None:
            check_output_path(paths[-1], overwrite_inputs=(args.mesh,), suffixes=suffixes)
    out, dirs = paths
    if out is not None and dirs is not None and os.path.abspath(dirs) == os.path.abspath(out):
        raise MeshError(
            "--out and --directions name the same file (one would replace the other); give "
            "them different names",
            "--directions",
        )
    return out, dirs


def run(args: argparse.Namespace) -> int:
    out, dirs = _outputs(args)
    result = None
    if args.method is None:
        args.method = DEFAULT_CURVATURE_FIELD if args.estimator is None else "H"
    if args.estimator is None and args.method in CURVATURE_METHODS:
        if args.radius is not None or dirs is not None:
            raise MeshError("--radius and --directions need --estimator", "--estimator")
        mesh, values = load_with_field(args.mesh, args.method, args.area, args.boundary)
    else:
        from ..curvature.estimators import estimate_curvature  # (scipy's trees: when asked)

        mesh = load_mesh(args.mesh)
        args.estimator = args.estimator or "cotan"
        if args.method not in PRINCIPAL_FIELDS:
            raise MeshError(
                f"an estimator gives {', '.join(PRINCIPAL_FIELDS)}, not {args.method!r}",
                "--method",
            )
        try:
            result = estimate_curvature(mesh.V, mesh.F, args.estimator, **_options(args))
        except MeshError as exc:
            if exc.source == "radius":  # the flag the user typed
                raise MeshError(exc.problem, "--radius") from None
            raise
        values = result.field(args.method)
    if not np.isfinite(values).all():  # never write or summarize a broken field
        bad = int(np.count_nonzero(~np.isfinite(values)))
        raise MeshError(f"the {args.method} curvature is not finite at {bad} vertices", args.mesh)
    print_report(args.mesh, mesh.report)
    save_field(out, mesh.V, mesh.F, values, args.mesh)
    if dirs is not None and result is not None:
        with atomic_write(dirs, "wb", overwrite_inputs=(args.mesh,)) as f:
            np.save(f, np.stack([result.d1, result.d2], axis=1))
    stats = summary_stats(values)
    if args.json:
        emit_json(
            {
                "file": str(args.mesh),
                "method": args.method,
                "estimator": args.estimator,
                "area": args.area,
                "boundary": args.boundary,
                "n_vertices": len(values),
                **stats,
                "repairs": mesh.report.repairs,
                "warnings": mesh.report.warnings,
                "out": str(out) if out else None,
            }
        )
    else:
        how = (
            f"{args.estimator} estimator"
            if args.estimator
            else f"{args.area} area, boundary rule {args.boundary}"
        )
        print(f"{args.method} curvature ({how}) on {len(values)} vertices")
        for k, v in stats.items():
            print(f"  {k:<7}{v: .6g}")
        if out is not None:
            print(f"wrote {shown(out)}")
    return 0


def load_with_field(path: str, method: str, area: str, boundary: str) -> tuple[Mesh, np.ndarray]:
    """``load_mesh(path)`` and its curvature field ``method``, the field computed in a thread
    from the parsed arrays while the mesh is validated (the two take about as long: on two
    cores the command takes the longer of them, not their sum). When the validation
    changed the geometry (a repair), the field is computed again from the validated mesh.

    Returns
    -------
    mesh : Mesh
    values : (n,) float
    """
    work: dict[str, Any] = {}

    def compute(V: np.ndarray, F: np.ndarray) -> None:
        try:
            work["values"] = curvature_field(V, F, method, area, boundary)  # type: ignore[arg-type]
        except Exception:  # e.g. what the validation repairs: computed again below
            work.pop("values", None)

    def start(V: np.ndarray, F: np.ndarray) -> None:
        work["VF"] = (V, F)
        work["thread"] = threading.Thread(target=compute, args=(V, F), daemon=True)
        work["thread"].start()

    try:
        mesh = load_mesh(path, on_parsed=start)
    finally:
        if "thread" in work:
            work["thread"].join()
    V, F = work.get("VF", (None, None))
    same = V is not None and _same(V, mesh.V) and _same(F, mesh.F)
    if same and "values" in work:
        return mesh, work["values"]
    return mesh, curvature_field(mesh.V, mesh.F, method, area, boundary)  # type: ignore[arg-type]


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a is b or (a.shape == b.shape and bool(np.array_equal(a, b)))


def _options(args: argparse.Namespace) -> dict[str, object]:
    """The estimator's keyword options from the flags."""
    if args.estimator == "cotan":
        if args.radius is not None:
            raise MeshError("the cotan estimator has no radius", "--radius")
        return {"area": args.area, "boundary": args.boundary}
    if args.radius is None:
        return {}
    if args.estimator == "quadric":
        return {"radius": check_ring_radius(args.radius, "--radius")}
    if args.estimator == "jet":
        return {"radius": args.radius}
    raise MeshError(f"the {args.estimator} estimator has no radius", "--radius")
