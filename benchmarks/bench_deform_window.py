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

``--scan``: the 692k scan (one ``igl.upsample`` of ``armadillo_loop``) in a viewer on
polyscope's ``openGL_mock`` backend with the window's jobs (threads, child processes): a
handle clicked, then a drag of ``--steps`` moves; printed: the set-up's time (a child process
keeps the deformers), the longest gap between two frames while it ran (the window keeps
drawing), each move's time to the screen and the longest frame meanwhile.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

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


def bench_scan(method: str, steps: int, radius: float) -> None:
    """The window's frames while the 692k scan's handle set is built and dragged."""
    import igl
    import polyscope as ps
    from meshlap_app import jobs as jobs_mod
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    path = shared_mesh("armadillo_loop.obj")
    if path is None:
        raise SystemExit("../shared/meshes/armadillo_loop.obj not found")
    src = load_mesh(path)
    V, F = igl.upsample(src.V, src.F)
    out = Path(tempfile.gettempdir()) / "meshlap-scans" / "armadillo_692k.obj"
    if not out.exists():  # made once
        out.parent.mkdir(exist_ok=True)
        tmp = out.with_name(f".armadillo_692k.{os.getpid()}.obj")
        igl.write_triangle_mesh(str(tmp), V, F)
        tmp.replace(out)
    mesh = MeshState()
    assert mesh.load(out), mesh.error
    ps.set_allow_headless_backends(True)
    ps.init("openGL_mock")
    ps.set_max_fps(-1)
    ps.set_frame_tick_limit_fps_mode("ignore_limits")
    jobs_mod.warm_up()
    viewer = Viewer(AppState(mesh=mesh))
    viewer.background = True
    viewer.state.jobs.processes = True
    viewer.sync_mesh()
    ps.set_user_callback(viewer.callback)
    viewer.set_panel("deform")
    st = viewer.panels["deform"].state
    st.method, st.radius = method, radius
    print(f"692k scan: {len(mesh.V):,} vertices, {method}; {load_text()}")

    def run_until(done, limit: float = 600.0) -> tuple[float, float, int]:
        t0 = last = time.perf_counter()
        worst, n = 0.0, 0
        while not done():
            ps.frame_tick()
            now = time.perf_counter()
            worst, last, n = max(worst, now - last), now, n + 1
            if now - t0 > limit:
                raise SystemExit("gave up waiting")
        return time.perf_counter() - t0, worst, n

    ps.frame_tick()
    st.select(len(mesh.V), int(np.argmax(mesh.V[:, 1])))
    took, worst, n = run_until(lambda: st.built is not None and not st.due())
    print(
        f"set-up {took:.1f} s as a job ({type(st.built).__name__}); {n} frames meanwhile, "
        f"longest {worst:.2f} s"
    )
    for k, m in enumerate(drag_moves(mesh.V, steps)):
        st.set_move(0, m)
        took, worst, n = run_until(lambda: st.solved.get(method) == st.moved)
        print(f"move {k + 1}: on screen after {took:.2f} s; {n} frames, longest {worst:.2f} s")
    if method == "arap":  # the iterations going on after the last move
        d = st.built.deformers[method]
        first = d.iteration
        took, worst, n = run_until(lambda: d.iteration >= first + 5 or not st.due())
        print(
            f"ARAP: {(d.iteration - first) / took:.2f} iterations/s shown while the window "
            f"drew {n} frames, longest {worst:.2f} s"
        )
    st.drop()
    print(load_text())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", default="armadillo_igl.obj")
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--radius", type=float, default=5.0, help="% of the bounding-box diagonal")
    ap.add_argument("--only", default=",".join(DEFORM_METHODS))
    ap.add_argument("--scan", action="store_true", help="the 692k scan in a mock window")
    args = ap.parse_args()
    if args.scan:
        bench_scan(args.only.split(",")[0], args.steps, args.radius)
        return
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
