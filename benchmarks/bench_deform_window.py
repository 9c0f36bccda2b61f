"""Benchmark: a drag in the Deform panel, through the panel's own state code (headless).

    python benchmarks/bench_deform_window.py [--mesh armadillo_igl.obj] [--steps 40]
                                             [--radius 5] [--only biharmonic,arap]

What the window does per frame while a handle is dragged, without the drawing: the move
changed (:meth:`~meshlap_app.state.deform.DeformState.set_move`), the handles' targets made and
the method's solve (:meth:`~meshlap_app.state.deform.DeformState.solve`: one
back-substitution, or the frame's ARAP iterations), then the colour map's values
(displacement, or each vertex's rotation error). Reported per method: the set-up (discs, fixed
region, factorization, as the panel's job runs it), updates per second while dragging (solve
alone, and with the colour map), and for ARAP the iterations per second with the handles held
(the iterations running live after a drag). One handle: the vertex highest in y, a disc of
``--radius`` % of the bounding-box diagonal, the farthest region held; the drag lifts it by up
to 10 % of the diagonal and turns it by up to 30°.

The window adds the upload of the positions to polyscope (``update_vertex_positions``) and the
draw, which this script does not time. The load average is printed with the figures.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np
from _util import print_table, shared_mesh
from meshlap_app.state.deform import DeformState
from meshlap_app.state.handle_sets import build_set

from meshlap_core.io import load_mesh
from meshlap_core.options import DEFORM_METHODS


def load_text() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f}"


def drag_moves(V: np.ndarray, steps: int) -> list[dict]:
    """``steps`` moves of a drag: up by up to a tenth of the diagonal, a turn up to 30°."""
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    out = []
    for t in np.linspace(0.0, 1.0, steps + 1)[1:]:
        out.append({"rotate": [0.0, 0.0, 1.0, 30.0 * t], "move": [0.0, 0.1 * diag * t, 0.0]})
    return out


def bench_method(V, F, method: str, steps: int, radius: float) -> list:
    st = DeformState(method=method, radius=radius, arap_per_frame=1, arap_max=10**5)
    st.select(len(V), int(np.argmax(V[:, 1])))
    t0 = time.perf_counter()
    st.adopt(build_set(V, F, st.setup_key(0)))
    setup = time.perf_counter() - t0
    d = st.built.deformers[method]
    solve, with_field = [], []
    for k, m in enumerate(drag_moves(V, steps)):
        st.colour = "displacement" if k % 2 == 0 else "rotation error"
        t0 = time.perf_counter()
        st.set_move(0, m)
        st.solve(method)
        t1 = time.perf_counter()
        st.field(method)
        t2 = time.perf_counter()
        solve.append(t1 - t0)
        with_field.append((t2 - t0, st.colour))
    disp = [t for t, c in with_field if c == "displacement"]
    rot = [t for t, c in with_field if c == "rotation error"]
    row = [
        method,
        f"{d.stats.n_unknowns:,}",
        f"{setup:.2f}",
        f"{d.stats.factor_seconds:.2f}",
        f"{1 / statistics.median(solve):.1f}",
        f"{1 / statistics.median(disp):.1f}",
        f"{1 / statistics.median(rot):.1f}",
    ]
    if method == "arap":  # the iterations running live with the handles held
        t0 = time.perf_counter()
        n = 0
        while time.perf_counter() - t0 < 2.0:
            d.step()
            n += 1
        row.append(f"{n / (time.perf_counter() - t0):.1f}")
    else:
        row.append("")
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", default="armadillo_igl.obj")
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--radius", type=float, default=5.0, help="% of the bounding-box diagonal")
    ap.add_argument("--only", default=",".join(DEFORM_METHODS))
    args = ap.parse_args()
    path = shared_mesh(args.mesh)
    if path is None:
        raise SystemExit(f"../shared/meshes/{args.mesh} not found")
    mesh = load_mesh(path)
    V, F = mesh.V, mesh.F
    print(f"{args.mesh}: {len(V):,} vertices; {load_text()}")
    rows = [bench_method(V, F, m, args.steps, args.radius) for m in args.only.split(",")]
    print_table(
        [
            "method",
            "unknowns",
            "set-up s",
            "factor s",
            "updates/s (solve)",
            "+ displacement",
            "+ rotation error",
            "ARAP it/s held",
        ],
        rows,
    )
    print(load_text())


if __name__ == "__main__":
    main()
