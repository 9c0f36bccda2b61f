"""Benchmark: the maps of ``meshlap_core.flatten`` beside libigl's, on a 43k-vertex disk.

    python benchmarks/bench_flatten.py [--mesh armadillo_igl.obj] [--repeat 5] [--iters 30]

The mesh (closed, genus 0) is first cut to a disk by :func:`meshlap_core.flatten.make_disk`
(a slit along the shortest path between two far-apart vertices; not timed). Then, alternating
ours and libigl's and keeping the best of ``--repeat``:

* **Tutte** (uniform weights, boundary on the circle): ``flatten(V, F, "tutte")`` (disk check,
  graph Laplacian, factorization, solve) against libigl's pipeline for the same map:
  ``boundary_loop``, ``map_vertices_to_circle``, ``adjacency_matrix`` and
  ``min_quad_with_fixed`` on ``D − A``;
* **harmonic** (cotangent weights, same circle): ``flatten(V, F, "harmonic")`` against
  ``boundary_loop`` + ``map_vertices_to_circle`` + ``igl.harmonic``;
* **LSCM** (two pinned vertices): ``flatten(V, F, "lscm")`` against ``boundary_loop`` +
  ``igl.lscm`` with the same two pins;
* **SCP** (no libigl counterpart): its time beside libigl's LSCM, for scale;
* **ARAP**: iterations per second of ``Flattener.arap().step()`` and of libigl's
  ``arap_solve`` (``ARAP_ENERGY_TYPE_ELEMENTS``, one iteration per call) from the same LSCM
  start, in blocks of ``--iters`` iterations, ours and libigl's alternating, the best block
  of each; the set-up apart: ``Flattener(V, F).arap()`` (disk, LSCM, factorization) against
  libigl's LSCM and ``arap_precomputation``.

Each row prints both times and ``ours / libigl`` (below 1: ours faster) and the largest
difference between the two maps (the libigl boundary is ours, passed in). The load average
is printed: timings on a busy machine are only comparable side by side.
"""

from __future__ import annotations

import argparse
import os
import time

import igl
import numpy as np
import scipy.sparse as sp
from _util import best_of, print_table, shared_mesh

from meshlap_core.flatten import Flattener, flatten, make_disk
from meshlap_core.io import load_mesh


def igl_tutte(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """libigl's Tutte map: the uniform Laplacian's Dirichlet problem, boundary on the circle."""
    loop = igl.boundary_loop(F)
    bc = igl.map_vertices_to_circle(V, loop.astype(np.int32))
    A = igl.adjacency_matrix(F).astype(np.float64)
    Q = sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A
    n = len(V)
    return igl.min_quad_with_fixed(
        sp.csc_matrix(Q), np.zeros((n, 2)), loop, bc, sp.csc_matrix((0, n)), np.zeros((0, 2)), True
    )


def igl_harmonic(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """libigl's harmonic map with the boundary on the circle."""
    loop = igl.boundary_loop(F)
    return igl.harmonic(V, F, loop, igl.map_vertices_to_circle(V, loop.astype(np.int32)), 1)


def igl_lscm(V: np.ndarray, F: np.ndarray, pins: tuple[int, int]) -> np.ndarray:
    """libigl's LSCM with the two given pins at (0, 0) and (d, 0)."""
    igl.boundary_loop(F)  # (its pipeline finds the boundary first)
    d = float(np.linalg.norm(V[pins[0]] - V[pins[1]]))
    uv, _ = igl.lscm(V, F, np.array(pins), np.array([[0.0, 0.0], [d, 0.0]]))
    return uv


def linear_rows(V: np.ndarray, F: np.ndarray, repeat: int) -> list[list]:
    """Tutte, harmonic, LSCM and SCP: ours against libigl's, alternating, best of
    ``repeat``."""
    loop = igl.boundary_loop(F)
    pins = Flattener(V, F).map("lscm").pins
    peers = {
        "tutte": lambda: igl_tutte(V, F),
        "harmonic": lambda: igl_harmonic(V, F),
        "lscm": lambda: igl_lscm(V, F, pins),
        "scp": lambda: igl_lscm(V, F, pins),
    }
    rows = []
    for method, peer in peers.items():
        ours_t, peer_t = float("inf"), float("inf")
        for _ in range(repeat):
            t, ours = best_of(lambda m=method: flatten(V, F, m), 1)
            ours_t = min(ours_t, t)
            t, theirs = best_of(peer, 1)
            peer_t = min(peer_t, t)
        if method in ("tutte", "harmonic"):
            # (libigl's loop may start elsewhere: compare with our solution for its circle)
            ours_uv = _ours_with_boundary(V, F, method, loop)
            diff = float(np.abs(ours_uv - theirs).max())
        elif method == "lscm":
            diff = float(np.abs(ours.uv - theirs).max())
        else:
            diff = float("nan")
        label = "scp (vs igl lscm)" if method == "scp" else method
        rows.append([label, ours_t, peer_t, ours_t / peer_t, f"{diff:.1e}"])
    return rows


def _ours_with_boundary(V: np.ndarray, F: np.ndarray, method: str, loop: np.ndarray) -> np.ndarray:
    """Our fixed-boundary solve with libigl's loop placed by libigl's circle."""
    from meshlap_core.flatten.fixed_boundary import (
        DirichletSolver,
        cotan_laplacian,
        graph_laplacian,
    )
    from meshlap_core.topology import EdgeTable

    K = graph_laplacian(EdgeTable.from_faces(F, len(V))) if method == "tutte" else None
    K = cotan_laplacian(V, F) if K is None else K
    return DirichletSolver(K, loop).solve(igl.map_vertices_to_circle(V, loop.astype(np.int32)))


def arap_rows(V: np.ndarray, F: np.ndarray, iters: int, repeat: int) -> list[list]:
    """ARAP: set-up (ours: the disk, LSCM's start and the factorization; libigl's: its LSCM
    and ``arap_precomputation``) and iterations per second, alternating blocks of ``iters``
    iterations of ours and libigl's from the same LSCM start, best of ``repeat``."""
    pin = np.array([F[0, 0]], dtype=np.int32)  # (libigl needs one fixed vertex, as ours)
    pins = Flattener(V, F).map("lscm").pins
    setup, igl_setup, ours, theirs = [], [], [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        arap = Flattener(V, F).arap()  # (the disk, LSCM's start, the factorization)
        setup.append(time.perf_counter() - t0)
        data = igl.ARAPData()
        data.max_iter = 1
        data.energy = igl.ARAP_ENERGY_TYPE_ELEMENTS
        t0 = time.perf_counter()
        igl_lscm(V, F, pins)
        igl.arap_precomputation(V, F, 2, pin, data)
        igl_setup.append(time.perf_counter() - t0)
        start = np.array(arap.uv)
        t0 = time.perf_counter()
        arap.run(iters)
        ours.append(iters / (time.perf_counter() - t0))
        uv = start
        t0 = time.perf_counter()
        for _ in range(iters):
            uv = igl.arap_solve(start[pin], data, uv)
        theirs.append(iters / (time.perf_counter() - t0))
    s, g, o, t = min(setup), min(igl_setup), max(ours), max(theirs)
    return [
        ["arap set-up (s)", s, g, s / g, ""],
        ["arap iterations/s", o, t, t / o, f"E {arap.energies[0]:.4g} -> {arap.energy:.4g}"],
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--mesh", default="armadillo_igl.obj")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--iters", type=int, default=30, help="ARAP iterations timed")
    args = parser.parse_args()
    path = shared_mesh(args.mesh)
    if path is None:
        return
    mesh = load_mesh(path)
    disk = make_disk(mesh.V, mesh.F)
    V, F = disk.V, disk.F
    print(f"{args.mesh}: {mesh.n_vertices} vertices -> disk of {len(V)} vertices, {len(F)} "
          f"faces, outer loop {len(disk.outer)} ({'; '.join(disk.messages)})")  # fmt: skip
    rows = linear_rows(V, F, args.repeat)
    rows += arap_rows(V, F, args.iters, args.repeat)
    print_table(["map", "ours (s)", "libigl (s)", "ours / libigl", "max |diff|"], rows)
    print("(arap iterations/s: the ratio is libigl / ours; above 1 libigl iterates faster)")
    print(f"load average: {os.getloadavg()}")


if __name__ == "__main__":
    main()
