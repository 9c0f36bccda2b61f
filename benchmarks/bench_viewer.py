"""Viewer speed under polyscope's headless EGL backend, ours beside the naive approach.

Run: ``python benchmarks/bench_viewer.py [--mesh armadillo_igl.obj] [--kmax 300]``.

- k slider: ``SpectralState.set_k`` (incremental reconstruction) + position/colour upload, for
  random jumps of k; naive: ``U_k (U_kᵀ M X)`` from scratch + re-registering the mesh.
  Target < 16 ms per update.
- live implicit smoothing: one ``step()`` (factorized once) + position upload; naive:
  ``scipy.sparse.linalg.spsolve`` of the whole system + re-registering. Target >= 20 steps/s.
- idle frame: the cost of the viewer's per-frame callback when nothing changes. Target < 2 ms.
- eigenbasis in the window: ``--eigen-k`` eigenpairs computed by the panel's worker thread while
  the window renders (paced: a few frames/s while the job runs), against ``meshlap spectral
  MESH --k K --no-cache`` in a subprocess: same mesh, same k, one run each, no cache. Target
  <= 1.3x. Also the unthrottled window, for comparison.

Uses ../shared/meshes (falls back to the bundled bumpy sphere when absent, and says so).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import polyscope as ps
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from _util import print_table, shared_mesh
from meshlap_app.state import AppState, MeshState
from meshlap_app.viewer import Viewer, init_polyscope


def eigen_in_window(viewer: Viewer, k: int, paced: bool) -> float:
    """Seconds from the panel's "compute" to the basis shown, rendering frames meanwhile
    (``paced``: the window's frame pacing, a few frames per second while the job runs)."""
    os.environ["MESHLAP_CACHE_DIR"] = tempfile.mkdtemp()  # a fresh cache: no hit
    viewer.pace, viewer.background = paced, True
    viewer.set_panel("spectral")
    panel = viewer.panels["spectral"]
    st = panel.state
    st.clear()
    st.k_request = k
    t = time.perf_counter()
    panel.compute(viewer)  # the "compute eigenbasis" button: a background job
    while st.basis is None and not st.error:
        ps.frame_tick()  # the job's result is applied on the UI thread by a frame
    viewer.pace, viewer.background = False, False
    if st.error:
        raise SystemExit(st.error)
    return time.perf_counter() - t


def eigen_cli(path: str, k: int) -> float:
    """Seconds of ``meshlap spectral MESH --k K --no-cache`` (a whole process)."""
    cmd = [sys.executable, "-m", "meshlap_core.cli", "spectral", str(path), "--k", str(k)]
    t = time.perf_counter()
    subprocess.run([*cmd, "--no-cache", "--json"], check=True, capture_output=True)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="armadillo_igl.obj")
    ap.add_argument("--kmax", type=int, default=300)
    ap.add_argument("--jumps", type=int, default=60)
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--eigen-k", type=int, default=100)
    args = ap.parse_args()
    path = shared_mesh(args.mesh)
    os.chdir(tempfile.mkdtemp())  # polyscope writes its .ini files into the cwd
    mesh = MeshState()
    mesh.load(path)
    print(f"mesh: {mesh.name}, {len(mesh.V)} vertices")
    init_polyscope("openGL3_egl")
    viewer = Viewer(AppState(mesh=mesh, panel="spectral"))
    viewer.sync_mesh()
    ps.set_user_callback(viewer.callback)
    rows = []

    # ---- eigenbasis in the window vs the CLI ------------------------------------------
    cli = eigen_cli(path, args.eigen_k)
    win = eigen_in_window(viewer, args.eigen_k, True)
    free = eigen_in_window(viewer, args.eigen_k, False)
    print(
        f"eigenbasis k={args.eigen_k}: meshlap spectral {cli:.2f} s, window (throttled) "
        f"{win:.2f} s = {win / cli:.2f}x, window (unthrottled) {free:.2f} s = {free / cli:.2f}x"
    )
    rows.append(
        [
            f"eigenbasis k={args.eigen_k} in the window (s)",
            f"{win:.2f}",
            f"{free:.2f} unthrottled",
            f"{win / cli:.2f}x of CLI {cli:.2f} s",
            "<= 1.3x CLI",
            "yes" if win <= 1.3 * cli else "NO",
        ]
    )

    # ---- k slider ------------------------------------------------------------------
    spec = viewer.panels["spectral"]
    st = spec.state
    st.k_request = args.kmax
    t0 = time.perf_counter()
    st.start(mesh.V, mesh.F, background=False)
    print(f"eigenbasis k={args.kmax}: {time.perf_counter() - t0:.1f} s ({st.message})")
    spec.push_k(viewer, force=True)
    rng = np.random.default_rng(0)
    ks = rng.integers(1, st.basis.k_max + 1, size=args.jumps)
    for k in rng.integers(1, st.basis.k_max + 1, size=20):  # warm-up: first touch of the
        st.set_k(int(k))  # freshly loaded basis and checkpoints (reported separately below)
        spec.push_k(viewer)
    times, t_rec = [], []
    for k in ks:
        t = time.perf_counter()
        st.set_k(int(k))
        t_mid = time.perf_counter()
        spec.push_k(viewer)
        times.append(time.perf_counter() - t)
        t_rec.append(t_mid - t)
    ours = 1e3 * float(np.median(times))
    worst = 1e3 * float(np.max(times))
    p95 = 1e3 * float(np.percentile(times, 95))
    print(f"k slider: {args.jumps} random jumps after a 20-jump warm-up")
    print(
        f"k slider: reconstruct median {1e3 * np.median(t_rec):.2f} ms, max "
        f"{1e3 * np.max(t_rec):.2f} ms; whole update p95 {p95:.2f} ms, max {worst:.2f} ms"
    )
    U, M, X = st.basis.vectors, sp.diags(st.basis.mass), mesh.V
    times = []
    for k in ks[:10]:
        t = time.perf_counter()
        Uk = U[:, :k]
        Xk = Uk @ (Uk.T @ (M @ X))
        ps.register_surface_mesh("naive", Xk, mesh.F)
        times.append(time.perf_counter() - t)
    ps.remove_surface_mesh("naive")
    naive = 1e3 * float(np.median(times))
    rows.append(
        [
            "k-slider update (ms, median / p95 / max)",
            f"{ours:.2f} / {p95:.2f} / {worst:.2f}",
            f"{naive:.2f}",
            f"{naive / ours:.1f}x",
            "< 16 ms",
            "yes" if worst < 16 else ("p95 only" if p95 < 16 else "NO"),
        ]
    )

    # ---- live implicit smoothing -----------------------------------------------------
    viewer.state.panel = "smoothing"
    sm = viewer.panels["smoothing"]
    sm.state.method, sm.state.laplacian, sm.state.lam = "implicit", "uniform", 0.5
    sm.rebuild(viewer)
    sm.state.step()  # the first step includes the one factorization
    sm.push(viewer)
    t = time.perf_counter()
    for _ in range(args.steps):
        sm.state.step()
        sm.push(viewer)
    ours_sps = args.steps / (time.perf_counter() - t)
    n = len(mesh.V)
    from meshlap_core.laplacian import adjacency_matrix

    A = adjacency_matrix(mesh.F, n)
    D = sp.diags(np.asarray(A.sum(axis=1)).ravel())
    S = ((1 + 0.5) * D - 0.5 * A).tocsc()
    Vn = mesh.V.copy()
    t = time.perf_counter()
    naive_steps = 3
    for _ in range(naive_steps):
        Vn = spla.spsolve(S, D @ Vn)
        ps.register_surface_mesh("naive", Vn, mesh.F)
    naive_sps = naive_steps / (time.perf_counter() - t)
    ps.remove_surface_mesh("naive")
    rows.append(
        [
            "implicit smoothing incl. upload (steps/s)",
            f"{ours_sps:.1f}",
            f"{naive_sps:.1f}",
            f"{ours_sps / naive_sps:.1f}x",
            ">= 20",
            "yes" if ours_sps >= 20 else "NO",
        ]
    )

    # ---- idle frame ------------------------------------------------------------------
    for panel in ("curvature", "spectral", "smoothing"):
        viewer.state.panel = panel
        viewer.refresh()
        ps.frame_tick()
        cost = []

        def timed(cost=cost):
            t = time.perf_counter()
            try:
                viewer.callback()
            except Exception as exc:  # a callback exception would vanish inside polyscope
                print(f"callback raised: {exc!r}")
                raise
            cost.append(time.perf_counter() - t)

        ps.set_user_callback(timed)
        for _ in range(60):
            ps.frame_tick()
        ms = 1e3 * float(np.median(cost))
        rows.append(
            [
                f"idle callback, {panel} panel (ms)",
                f"{ms:.3f}",
                "-",
                "-",
                "< 2 ms",
                "yes" if ms < 2 else "NO",
            ]
        )
    print_table(["measure", "ours", "naive", "ratio", "target", "ok"], rows)


if __name__ == "__main__":
    main()
