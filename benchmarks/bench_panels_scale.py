"""Every panel of the viewer on a big scan (issue 21: "the 2.77M scan works in every panel"),
driven headless through the widgets as a user would, with the time and memory each took.

Usage::

    python benchmarks/bench_panels_scale.py [SCAN.obj] [--k 100]

Without ``SCAN`` the 2.77M armadillo (two ``igl.upsample`` of
``../shared/meshes/armadillo_loop.obj``) is made once in the temp folder. The drive runs in a
fresh child process (its peak RSS is the viewer's) on polyscope's ``openGL_mock`` backend,
through the tests' scriptable UI adapter (``tests/support/scripted_ui.py``: the child gets the
checkout on its ``PYTHONPATH``, as pytest gives it to the tests), the same widgets
``tests/app/test_viewer_widgets.py`` drives on a small sphere:

- open the scan with its curvature fields (the Mesh section's job, inline here), first frame;
- curvature: the Gaussian field, then the other vertex area (every field recomputed);
- one-ring: vertex 7 typed into the field (its inspector), and vertex ``n`` refused;
- spectral: ``--k`` modes asked for (default 100): computed, or refused with the message
  naming the memory limit (``meshlap_core/spectral/budget.py``); the basis is a job here as in
  the window (a thread), so only the refusal or the start is waited for unless
  ``--wait-basis`` (else it is cancelled before the next panel);
- smoothing: the default stepper built (its job, inline), 3 steps, the implicit cotan stepper
  built (its factorization, :meth:`~meshlap_core.smoothing.Smoother.prepare`) and 3 steps;
- surfaces: the torus;
- export: what is shown, written to a temporary folder.

Each row prints the seconds it took, the peak RSS so far and what the panel said (an error in
red is printed, not hidden). The viewer here is headless with ``background`` off, so every job
runs inline and a row's time is its work's, not a stall of the window (where they are jobs).
No threshold is checked (it is a benchmark: the 2.77M load alone takes about a minute on this
shared 2-core machine); the load average is printed before and after. Issue 21's bound for
the whole open: colours in < 20 s and < 4 GB.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT.parent / "shared" / "meshes" / "armadillo_loop.obj"


def default_scan() -> Path:
    """The 2.77M scan in the temp folder (made once)."""
    folder = Path(tempfile.gettempdir()) / "meshlap-scans"
    path = folder / "armadillo_2770k.obj"
    if not path.exists():
        import igl

        if not SOURCE.is_file():
            sys.exit(f"{SOURCE} is needed (the real meshes live beside the checkout)")
        folder.mkdir(exist_ok=True)
        V, F = igl.read_triangle_mesh(str(SOURCE))
        for _ in range(2):
            V, F = igl.upsample(V, F)
        tmp = folder / f".armadillo_2770k.{os.getpid()}.obj"
        igl.write_triangle_mesh(str(tmp), V, F)
        tmp.replace(path)
    return path


def peak_mb() -> float:
    """Peak RSS of this process so far, MiB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def child(scan: Path, k: int, wait_basis: bool, out: Path) -> list[dict[str, Any]]:
    """Drive every panel on ``scan`` in this process; one dict per step."""
    import polyscope as ps
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer, init_polyscope

    from tests.support.scripted_ui import ScriptedUI

    rows: list[dict[str, Any]] = []
    init_polyscope("openGL_mock")
    mesh = MeshState()
    mesh.load(None)  # the bundled mesh, as the window opens
    viewer = Viewer(AppState(mesh=mesh, folder=out), ui=ScriptedUI())
    viewer.sync_mesh()
    ps.set_user_callback(viewer.callback)
    ps.frame_tick()
    print(f"opening {scan.name} ...", file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    loaded = viewer.open(scan)  # the Mesh section's job (inline here): read, describe, fields
    ps.frame_tick()
    n = len(mesh.V)

    def said(panel: str) -> str:
        return viewer.state.errors.get(panel, "") or ""

    def row(panel: str, what: str, t: float, ok: bool, note: str = "") -> None:
        rows.append(
            {
                "panel": panel,
                "what": what,
                "seconds": round(time.perf_counter() - t, 2),
                "peak_mb": round(peak_mb()),
                "ok": bool(ok),
                "note": note[:300],
            }
        )
        print(json.dumps(rows[-1]), file=sys.stderr, flush=True)

    fields = viewer.state.curv.fields
    row("mesh", f"open {scan.name} ({n:,} vertices) + curvature, first frame", t0, loaded)
    row("mesh", "curvature fields on the first frame", t0, "cotan" in fields)

    def drive(label: str, value: Any, panel: str | None = None) -> None:
        if panel is not None:
            viewer.set_panel(panel)
        viewer.ui.script(label, value)
        if label == "export what is shown":
            viewer.ui.script("Export", True)
        ps.frame_tick()

    c = viewer.state.curv
    t = time.perf_counter()
    drive("field", "gaussian", "curvature")
    row("curvature", "field: gaussian", t, c.field_name == "gaussian", said("curvature"))
    t = time.perf_counter()
    other = "barycentric" if c.area != "barycentric" else "voronoi"  # not the one shown
    drive("area", other)
    row("curvature", f"area: {other} (fields recomputed)", t, c.area == other)

    ring = viewer.panels["onering"].state
    t = time.perf_counter()
    drive("vertex", 7, "onering")
    row("onering", "vertex 7 and its inspector", t, ring.vertex == 7, said("onering"))
    t = time.perf_counter()
    drive("vertex", str(n))
    row("onering", f"vertex {n} refused", t, ring.vertex == 7 and bool(said("onering")))

    sp = viewer.panels["spectral"].state
    t = time.perf_counter()
    viewer.background = True  # the eigenbasis as the window starts it: a job (a thread here)
    drive("modes to compute", k, "spectral")
    drive("compute eigenbasis", True)
    ps.frame_tick()
    refused = said("spectral") or getattr(sp, "error", "") or ""
    if wait_basis and not refused:
        while sp.busy:  # the job's result is applied in a frame (Jobs.poll)
            time.sleep(0.1)
            ps.frame_tick()
        ps.frame_tick()
    ok = bool(refused) or sp.busy or sp.basis is not None
    said_ = "refused" if refused else ("computed" if sp.basis is not None else "computing")
    row("spectral", f"k = {k}: {said_}", t, ok, refused)
    if sp.busy:  # cancelled, and waited for, before the next panel's memory is counted
        t = time.perf_counter()
        viewer.state.jobs.cancel_all()
        while sp.busy:
            time.sleep(0.1)
            ps.frame_tick()
        row("spectral", "cancelled", t, not sp.busy)
    viewer.background = False

    sm = viewer.panels["smoothing"].state
    t = time.perf_counter()
    viewer.set_panel("smoothing")
    ps.frame_tick()
    built = sm.smoother is not None
    row("smoothing", f"{sm.method} {sm.laplacian} stepper built", t, built, said("smoothing"))
    t = time.perf_counter()
    for _ in range(3):
        drive("step", True)
    row("smoothing", "3 steps", t, built and sm.smoother.iteration == 3)
    t = time.perf_counter()
    drive("method", "implicit")
    drive("Laplacian", "cotan")
    ok = sm.smoother is not None and sm.smoother.method == "implicit"
    row("smoothing", "implicit cotan stepper built (factorized)", t, ok, said("smoothing"))
    steps, t = [], time.perf_counter()
    for _ in range(3):
        ts = time.perf_counter()
        drive("step", True)
        steps.append(time.perf_counter() - ts)
    note = "each step (solve + upload): " + ", ".join(f"{s:.2f} s" for s in steps)
    row("smoothing", "3 implicit steps", t, ok and sm.smoother.iteration == 3, note)

    s = viewer.panels["surfaces"].state
    t = time.perf_counter()
    drive("surface", "torus", "surfaces")
    row("surfaces", "torus", t, s.name == "torus" and ps.has_surface_mesh("surface"))

    t = time.perf_counter()
    viewer.set_panel("curvature")
    before = set(os.listdir(out))
    drive("export what is shown", True)
    written = sorted(set(os.listdir(out)) - before)
    row("export", "export what is shown", t, bool(written), ", ".join(written) or said("export"))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scan", nargs="?", type=Path)
    parser.add_argument("--k", type=int, default=100, help="modes asked of the spectral panel")
    parser.add_argument("--wait-basis", action="store_true", help="wait for the eigenbasis")
    parser.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child is not None:
        with tempfile.TemporaryDirectory() as out:
            rows = child(args.child, args.k, args.wait_basis, Path(out))
        print(json.dumps(rows))
        return
    scan = args.scan or default_scan()
    print(f"load average before: {os.getloadavg()}", flush=True)
    argv = [sys.executable, __file__, "--child", str(scan), "--k", str(args.k)]
    if args.wait_basis:
        argv.append("--wait-basis")
    paths = [str(ROOT), os.environ.get("PYTHONPATH", "")]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in paths if p)}
    # the child's rows stream to stderr as each step ends (a long drive shows its progress)
    proc = subprocess.run(argv, stdout=subprocess.PIPE, text=True, env=env, timeout=7200)
    if proc.returncode != 0:
        sys.exit(f"the drive failed (exit code {proc.returncode}); its stderr is above")
    rows = json.loads(proc.stdout.strip().splitlines()[-1])
    print("| panel | what | s | peak RSS [MiB] | ok | note |")
    print("|---|---|---:|---:|---|---|")
    for r in rows:
        print(
            f"| {r['panel']} | {r['what']} | {r['seconds']:.2f} | {r['peak_mb']} "
            f"| {'yes' if r['ok'] else 'NO'} | {r['note']} |"
        )
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
