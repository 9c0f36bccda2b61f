"""Benchmark: a drag of the deformation methods beside libigl's, on the same handles.

    python benchmarks/bench_deform.py [--mesh armadillo_igl.obj] [--drags 30] [--iters 30]
                                      [--repeat 3] [--radius 0.02] [--only harmonic,arap]

Handles: three seeds spread over the mesh (fixed seed), each grown into a geodesic disc of
``--radius`` times the bounding-box diagonal; fixed: the default far region
(:func:`~meshlap_core.deform.farthest_region`). A drag is ``--drags`` target poses, the
handles rotated about their centroid by up to 30° and moved by up to 5 % of the diagonal.

* **k-harmonic** (k = 1, 2, 3): our :class:`~meshlap_core.deform.HarmonicDeformer`
  (precompute = operators + factorization; update = one back-substitution) beside
  ``igl.harmonic`` (the call libigl's tutorial makes per frame: it factorizes every time) and
  beside libigl's split path (``min_quad_with_fixed_precompute`` once on ``K(M⁻¹K)ᵏ⁻¹``, ``K = −L``,
  ``min_quad_with_fixed_solve`` per drag);
* **Laplacian coordinates** (soft constraints): ours alone (libigl has none);
* **ARAP**: our :class:`~meshlap_core.deform.ArapDeformer` (spokes) beside
  ``igl.arap_precomputation`` and ``igl.arap_solve`` with ``max_iter = 1``, both continuing
  from their last positions: time per iteration with the targets held, and per drag update
  (new targets, one iteration).

Ours and libigl's alternate (precomputations, then drag by drag), so a load that comes and
goes falls on both alike; times are medians (updates, iterations) and the best of ``--repeat``
(precomputations); ratios are ours / libigl's (below 1: ours faster). The load average is
printed with them.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import igl
import numpy as np
import scipy.sparse as sp
from _util import best_of, print_table, shared_mesh

from meshlap_core.deform import (
    ArapDeformer,
    HarmonicDeformer,
    LaplacianCoordinates,
    farthest_region,
    grow_handles,
    rigid_targets,
    rotation_matrix,
)
from meshlap_core.io import load_mesh


def load_text() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f}"


def handle_set(V: np.ndarray, F: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Three spread seeds grown into discs, and the far region."""
    rng = np.random.default_rng(7)
    seeds = rng.choice(len(V), 3, replace=False)
    diag = float(np.linalg.norm(np.ptp(V, axis=0)))
    regions = grow_handles(V, F, seeds, radius * diag)
    return regions.vertices, farthest_region(V, F, regions.vertices)


def drag_poses(V: np.ndarray, handles: np.ndarray, count: int) -> list[np.ndarray]:
    """``count`` targets: up to 30° about a fixed axis and 5 % of the diagonal."""
    diag = float(np.linalg.norm(np.ptp(V, axis=0)))
    out = []
    for i in range(1, count + 1):
        s = i / count
        out.append(
            rigid_targets(
                V, handles, rotation_matrix([0.3, 1, 0.2], 30 * s), [0.05 * diag * s, 0, 0]
            )
        )
    return out


def median_ms(times: list[float]) -> float:
    return 1e3 * statistics.median(times)


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def _igl_split_precompute(V, F, b, k):
    """libigl's ``harmonic`` split in two: ``min_quad_with_fixed_precompute`` on ``K(M⁻¹K)ᵏ⁻¹``
    (``K = −L``, the sign that makes it positive definite), to solve per drag."""
    L = igl.cotmatrix(V, F)
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
    Q = -L
    if k > 1:
        MiK = sp.diags(1.0 / M.diagonal()) @ Q
        for _ in range(k - 1):
            Q = Q @ MiK
    data = igl.min_quad_with_fixed_data()
    igl.min_quad_with_fixed_precompute(sp.csc_matrix(Q), b, sp.csc_matrix((0, len(V))), True, data)
    return data


def harmonic_rows(V, F, handles, fixed, poses, k, repeat):
    """Ours, igl.harmonic and libigl's split path for one k, alternating (so the load falls
    on each alike): a table row each."""
    b = np.concatenate([handles, fixed]).astype(np.int64)
    zeros = np.zeros((len(fixed), 3))
    bc = np.concatenate([poses[-1] - V[handles], zeros])
    pre, whole, spre = [], [], []
    for _ in range(repeat):
        t, ours = _timed(lambda: HarmonicDeformer(V, F, handles, fixed, k=k))
        pre.append(t)
        t, W = _timed(lambda: igl.harmonic(V, F, b, bc, k))
        whole.append(t)
        t, data = _timed(lambda: _igl_split_precompute(V, F, b, k))
        spre.append(t)
    upd, supd = [], []
    B = np.zeros((len(V), 3))
    for t in poses:
        bct = np.concatenate([t - V[handles], zeros])
        upd.append(_timed(lambda t=t: ours.update(t))[0])
        supd.append(
            _timed(lambda bct=bct: igl.min_quad_with_fixed_solve(data, B, bct, zeros[:0]))[0]
        )
    err = float(np.abs(ours.positions - V - W).max())
    name = ours.method
    p, w, s_ = min(pre), min(whole), min(spre)
    u, su = median_ms(upd), median_ms(supd)
    return (
        [
            [name, "ours", p, u, 1e3 / u, "", ""],
            [name, "igl.harmonic (per call)", w, 1e3 * w, 1 / w, p / w, u / (1e3 * w)],
            [name, "igl min_quad_with_fixed", s_, su, 1e3 / su, p / s_, u / su],
        ],
        err,
        ours.stats,
    )


def laplacian_row(V, F, handles, fixed, poses, repeat):
    pre, ours = best_of(lambda: LaplacianCoordinates(V, F, handles, fixed), repeat)
    upd = []
    for t in poses:
        t0 = time.perf_counter()
        ours.update(t)
        upd.append(time.perf_counter() - t0)
    u = median_ms(upd)
    return [["laplacian", "ours (soft)", pre, u, 1e3 / u, "", ""]]


def arap_rows(V, F, handles, fixed, poses, iters, repeat):
    """Iterations with the targets held and drag updates, ours beside libigl's."""
    b = np.concatenate([handles, fixed])

    def igl_pre():
        data = igl.ARAPData()
        data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
        data.max_iter = 1
        igl.arap_precomputation(V, F, 3, b.astype(np.int32), data)
        return data

    pres, ipres = [], []
    for _ in range(repeat):
        t, ours = _timed(lambda: ArapDeformer(V, F, handles, fixed))
        pres.append(t)
        t, data = _timed(igl_pre)
        ipres.append(t)
    pre, ipre = min(pres), min(ipres)
    target = poses[-1]
    bc = np.concatenate([target, V[fixed]])
    ours.set_targets(target)
    ours_it, igl_it = [], []
    U = V.copy()
    for _ in range(iters):  # alternating, so the load falls on both alike
        t0 = time.perf_counter()
        ours.step()
        ours_it.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        U = igl.arap_solve(bc, data, U)
        igl_it.append(time.perf_counter() - t0)
    ours_up, igl_up = [], []
    ours.reset()
    U = V.copy()
    for t in poses:
        bct = np.concatenate([t, V[fixed]])
        t0 = time.perf_counter()
        ours.update(t)
        ours_up.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        U = igl.arap_solve(bct, data, U)
        igl_up.append(time.perf_counter() - t0)
    oi, ii = median_ms(ours_it), median_ms(igl_it)
    ou, iu = median_ms(ours_up), median_ms(igl_up)
    return [
        ["arap iteration", "ours", pre, oi, 1e3 / oi, "", ""],
        ["arap iteration", "igl.arap_solve", ipre, ii, 1e3 / ii, pre / ipre, oi / ii],
        ["arap drag update", "ours", pre, ou, 1e3 / ou, "", ""],
        ["arap drag update", "igl.arap_solve", ipre, iu, 1e3 / iu, pre / ipre, ou / iu],
    ], ours.stats


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mesh", default="armadillo_igl.obj")
    ap.add_argument("--drags", type=int, default=30)
    ap.add_argument("--iters", type=int, default=30)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--radius", type=float, default=0.02, help="disc radius / bbox diagonal")
    ap.add_argument("--only", default="harmonic,laplacian,arap")
    args = ap.parse_args()
    path = shared_mesh(args.mesh)
    if path is None:
        return
    mesh = load_mesh(path)
    V, F = mesh.V, mesh.F
    handles, fixed = handle_set(V, F, args.radius)
    poses = drag_poses(V, handles, args.drags)
    print(
        f"{args.mesh}: {len(V):,} vertices; {len(handles)} handle and {len(fixed)} fixed vertices"
    )
    print(load_text())
    only = set(args.only.split(","))
    rows: list[list] = []
    if "harmonic" in only:
        for k in (1, 2, 3):
            r, err, stats = harmonic_rows(V, F, handles, fixed, poses, k, args.repeat)
            rows += r
            print(f"k={k}: max |ours - igl.harmonic| = {err:.2e}; {stats}")
    if "laplacian" in only:
        rows += laplacian_row(V, F, handles, fixed, poses, args.repeat)
    if "arap" in only:
        r, stats = arap_rows(V, F, handles, fixed, poses, args.iters, args.repeat)
        rows += r
        print(f"arap: {stats}")
    print_table(
        ["method", "solver", "precompute s", "update ms", "updates/s", "pre ratio", "update ratio"],
        rows,
    )
    print("ratios: ours / libigl's (below 1: ours faster)")
    print(load_text())


if __name__ == "__main__":
    main()
