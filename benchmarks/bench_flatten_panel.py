"""Benchmark: the Flatten panel's jobs beside the core's maps and libigl's, on a 43k disk.

    python benchmarks/bench_flatten_panel.py [--mesh armadillo_igl.obj] [--repeat 3] [--iters 40]

The mesh (closed, genus 0) is first cut to a disk (a slit, :func:`meshlap_core.flatten.make_disk`,
timed apart); the disk is then the mesh the panel maps. Per map, best of ``--repeat``,
alternating:

* **libigl**: its pipeline for the same map (``bench_flatten``'s: boundary loop, circle,
  ``harmonic`` / ``min_quad_with_fixed`` / ``lscm``; for the spectral map libigl's LSCM, for
  scale), the map alone;
* **core**: ``Flattener(V, F).map(method)`` (the disk check, operators, factorization, solve);
* **panel, kept disk**: :func:`meshlap_app.state.flatten.compute` with the disk's flattener
  already made (headless renders, animations, tests): the map plus what the panel draws of it
  (the distortion of every face, the checkerboard's corner coordinates, colour ranges,
  histograms, the table's row);
* **panel, window**: the same job as the window runs it, in a child process
  (:func:`meshlap_app.ipc.call`): the process, the disk made again, the map, what is drawn,
  and the arrays sent back through shared memory.

Then ARAP (free boundary, from LSCM): the core's bare iterations per second
(``ARAP.step``), and the panel's while live (``--iters`` iterations handing their maps to the
window as the window takes them: in this process and from a child process).

Each row prints the times and the ratios to libigl's (below 1: faster than libigl). The load
average is printed: timings on a busy machine are only comparable side by side.
"""

from __future__ import annotations

import argparse
import os
import threading
import time

import numpy as np
from _util import best_of, print_table, shared_mesh
from bench_flatten import igl_harmonic, igl_lscm, igl_tutte
from meshlap_app import ipc
from meshlap_app.jobs import Reporter
from meshlap_app.state.flatten import Request, compute

from meshlap_core.flatten import Flattener, make_disk
from meshlap_core.io import load_mesh

METHODS = ("tutte", "harmonic", "lscm", "scp")


def map_rows(V: np.ndarray, F: np.ndarray, repeat: int) -> list[list]:
    """Each linear map: libigl, the core, the panel with a kept disk, the panel's child job."""
    pins = Flattener(V, F).map("lscm").pins
    peers = {
        "tutte": lambda: igl_tutte(V, F),
        "harmonic": lambda: igl_harmonic(V, F),
        "lscm": lambda: igl_lscm(V, F, pins),
        "scp": lambda: igl_lscm(V, F, pins),
    }
    rows = []
    for method in METHODS:
        req = Request(
            V, F, (0, ()), method, "circle" if method in ("tutte", "harmonic") else "free"
        )
        times = {"libigl": [], "core": [], "kept": [], "child": []}
        for _ in range(repeat):
            times["libigl"].append(best_of(peers[method], 1)[0])
            times["core"].append(best_of(lambda m=method: Flattener(V, F).map(m), 1)[0])
            flat = Flattener(V, F)  # (the kept disk: made before, as the panel keeps it)
            times["kept"].append(best_of(lambda r=req, f=flat: compute(r, f), 1)[0])
            rep = Reporter(threading.Event())
            job = lambda r=req, p=rep: ipc.call(compute, r, reporter=p)  # noqa: E731
            times["child"].append(best_of(job, 1)[0])
        t = {k: min(v) for k, v in times.items()}
        label = "scp (libigl: lscm)" if method == "scp" else method
        rows.append([
            label, t["libigl"], t["core"], t["kept"], t["child"], t["core"] / t["libigl"],
            t["kept"] / t["libigl"], t["child"] / t["libigl"],
        ])  # fmt: skip
    return rows


def arap_rows(V: np.ndarray, F: np.ndarray, iters: int, repeat: int) -> list[list]:
    """ARAP's iterations per second: bare (the core's ``step``), and the panel's live run in
    this process and from a child process (partial maps handed over as it goes)."""
    bare, kept, child, shown = [], [], [], []
    flat = Flattener(V, F)
    req = Request(V, F, (0, ()), "arap", "free", iters=iters)
    for _ in range(repeat):
        arap = flat.arap()
        t0 = time.perf_counter()
        arap.run(iters)
        bare.append(iters / (time.perf_counter() - t0))
        count: list[int] = []
        rep = Reporter(threading.Event())
        rep.on_partial = lambda c=count: c.append(1)
        _, _, _, rate = compute(req, flat, None, progress=rep)
        kept.append(rate)
        shown.append(len(count))
        rep = Reporter(threading.Event())
        child.append(ipc.call(compute, req, reporter=rep)[3])
    return [
        ["arap iterations/s, core (bare steps)", max(bare)],
        ["arap iterations/s, panel live (this process)", max(kept)],
        ["arap iterations/s, panel live (child process: the window)", max(child)],
        [f"maps handed to the window in {iters} iterations", float(np.median(shown))],
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--mesh", default="armadillo_igl.obj")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--iters", type=int, default=40, help="ARAP iterations timed")
    args = parser.parse_args()
    path = shared_mesh(args.mesh)
    if path is None:
        return
    ipc.start_server()
    mesh = load_mesh(path)
    t, disk = best_of(lambda: make_disk(mesh.V, mesh.F), 1)
    V, F = disk.V, disk.F
    print(f"{args.mesh}: {mesh.n_vertices} vertices -> disk of {len(V)} vertices, {len(F)} "
          f"faces in {t:.2f} s ({'; '.join(disk.messages)})")  # fmt: skip
    header = ["map", "libigl (s)", "core (s)", "panel, kept disk (s)", "panel, window job (s)"]
    header += ["core / libigl", "kept / libigl", "window / libigl"]
    print_table(header, map_rows(V, F, args.repeat))
    print()
    print_table(["ARAP", "value"], arap_rows(V, F, args.iters, args.repeat))
    print(f"load average: {os.getloadavg()}")


if __name__ == "__main__":
    main()
