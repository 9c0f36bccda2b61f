"""Real scans (issue 21): every core figure at 0.7 M and 2.8 M vertices beside its baseline.

Run from the repository root::

    python benchmarks/bench_scale.py            # the 692k and the 2.77M scan, 3 repeats
    python benchmarks/bench_scale.py --quick    # the 692k scan only, 1-2 repeats
    python benchmarks/bench_scale.py --only load,smooth   # some figures only
    python benchmarks/bench_scale.py --big-only --only load,cli  # the 2.77M scan only

The scans are made in a temporary folder (never in the checkout) by one and two
``igl.upsample`` of ``../shared/meshes/armadillo_loop.obj`` (691,858 and 2,766,274 vertices)
and deleted at the end (``--keep DIR`` keeps them in DIR and reuses them next time).

Every figure runs in a child process, so wall-clock and peak memory (``ru_maxrss`` of that
child, from ``os.wait4``) are those of a fresh process, as a user meets them; "ours" and its
baseline alternate, ``--repeat`` times, and the best of each is printed with the ratio
ours / baseline (< 1 is faster). Figures:

* ``load``: ``load_mesh`` (parse + full validation) vs ``igl.read_triangle_mesh``, both in
  one child, alternating;
* ``info`` / ``curvature``: ``meshlap info MESH`` and ``meshlap curvature MESH --method cotan``
  as whole processes vs a libigl script (read + cotmatrix + massmatrix + H) as one, wall
  clock and (in the note) CPU time, the figure a loaded machine disturbs least;
* ``smooth``: in one child, the CHOLMOD factorization of ``M − λC`` alone (scikit-sparse,
  when installed) and cholespy's, then ``Smoother(..., "implicit", "cotan")``: its first step
  and the next steps (target 10 per second), and the 3-column solve alone beside cholespy's
  (the floor of a step); the solver back end is printed; then the window's stepper built in
  a child process beside the same build in a thread (longest GIL stall of a 10 ms ticker
  thread meanwhile, build time, a step's round trip);
* ``spectral``: ``meshlap spectral MESH --k 100 --no-cache`` as a whole process (time, peak
  RSS; target < 60 s, < 3 GB), and on ``armadillo_igl`` against a script doing what a user
  would (libigl read + operators + ``scipy.sparse.linalg.eigsh`` shift-invert), as a whole
  process too; and on the scan the window's eigenbasis job (``SpectralState`` with the jobs in
  child processes, as ``meshlap view`` runs it): start to adopted, the longest stall of the
  calling thread, the peak RSS of the window's side.

:data:`VIEWER_FIGURES` is the hook for the window's figures (open → first frame, steps/s,
idle CPU): functions ``(scan: Path, repeat: int) -> list[Row]`` appended there are run after
the core figures on every scan.

No thresholds are checked (timings on a shared machine are noisy); the load average is
printed before and after.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "meshes"
PY = sys.executable
MESHLAP = [PY, "-m", "meshlap_core.cli"]


@dataclass
class Row:
    """One line of the table: a figure, ours and the baseline (seconds), peak RSS (MiB)."""

    scan: str
    figure: str
    ours: float
    base: float | None
    base_name: str
    rss_ours: float | None = None
    rss_base: float | None = None
    note: str = ""


#: the window's figures, added by the viewer side: ``fn(scan, repeat) -> list[Row]``
VIEWER_FIGURES: list[Callable[[Path, int], list[Row]]] = []


def run_child(argv: list[str], env: dict[str, str] | None = None) -> tuple[float, float, str]:
    """Run ``argv``; return (wall seconds, peak RSS in MiB of that child, its stdout)."""
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as out:
        proc = subprocess.Popen(
            argv, stdout=out, stderr=subprocess.PIPE, env={**os.environ, **(env or {})}
        )
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        err = proc.stderr.read().decode() if proc.stderr else ""
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(argv[:4])}... failed:\n{err[-2000:]}")
        out.seek(0)
        text = out.read().decode()
    return wall, usage.ru_maxrss / 1024.0, text


def cpu_child(argv: list[str]) -> tuple[float, float, float]:
    """Run ``argv`` (output discarded); return (wall seconds, CPU seconds: user + system of
    that child, peak RSS in MiB). CPU time is the figure a loaded machine disturbs least."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        err = proc.stderr.read().decode() if proc.stderr else ""
        raise RuntimeError(f"{' '.join(argv[:4])}... failed:\n{err[-2000:]}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def python_child(code: str) -> tuple[float, float, str]:
    """Run a Python snippet as a whole process."""
    return run_child([PY, "-c", textwrap.dedent(code)])


def make_scans(folder: Path, big: bool) -> list[Path]:
    """The 692k (and, with ``big``, the 2.77M) armadillo in ``folder`` (made once)."""
    src = SHARED / "armadillo_loop.obj"
    if not src.is_file():
        sys.exit(f"{src} is needed (the real meshes live beside the checkout)")
    out = [folder / "armadillo_692k.obj"] + ([folder / "armadillo_2770k.obj"] if big else [])
    missing = [p for p in out if not p.is_file()]
    if missing:
        print(f"making {', '.join(p.name for p in missing)} in {folder} ...", flush=True)
        python_child(
            f"""
            import igl
            V, F = igl.read_triangle_mesh({str(src)!r})
            for path in {[str(p) for p in out]!r}:
                V, F = igl.upsample(V, F)
                igl.write_triangle_mesh(path, V, F)
            """
        )
    return out


# ------------------------------------------------------------------------------ the figures


def fig_load(scan: Path, repeat: int) -> list[Row]:
    """``load_mesh`` vs ``igl.read_triangle_mesh`` in one child, alternating."""
    _, rss, text = python_child(
        f"""
        import time, igl
        from meshlap_core.io import load_mesh
        a, b = [], []
        for _ in range({repeat}):
            t = time.perf_counter(); igl.read_triangle_mesh({str(scan)!r})
            a.append(time.perf_counter() - t)
            t = time.perf_counter(); load_mesh({str(scan)!r})
            b.append(time.perf_counter() - t)
        print(min(b), min(a))
        """
    )
    ours, base = map(float, text.split())
    return [
        Row(
            scan.name,
            "load_mesh (parse + validation)",
            ours,
            base,
            "igl.read_triangle_mesh",
            rss_ours=rss,
            note="RSS: the child doing both",
        )
    ]


IGL_SCRIPT = """
import sys, numpy as np, igl
V, F = igl.read_triangle_mesh(sys.argv[1])
C = igl.cotmatrix(V, F)
M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
HN = -0.5 * (C @ V) / M.diagonal()[:, None]  # mean curvature normal (libigl's tutorial)
N = igl.per_vertex_normals(V, F)
H = np.sign(np.einsum("ij,ij->i", HN, N)) * np.linalg.norm(HN, axis=1)
print(float(np.median(H)))
"""


def fig_cli(scan: Path, repeat: int) -> list[Row]:
    """``meshlap info`` and ``meshlap curvature`` as whole processes vs the libigl script."""
    rows = []
    cmds = {
        "meshlap info, whole process": [*MESHLAP, "info", str(scan)],
        "meshlap curvature --method cotan, whole process": [
            *MESHLAP,
            "curvature",
            str(scan),
            "--method",
            "cotan",
        ],
    }
    for name, argv in cmds.items():
        ours, base = [], []
        for _ in range(repeat):
            ours.append(cpu_child(argv))
            base.append(cpu_child([PY, "-c", IGL_SCRIPT, str(scan)]))
        o, b = min(ours), min(base)
        cpu_o, cpu_b = min(r[1] for r in ours), min(r[1] for r in base)
        rows.append(
            Row(
                scan.name,
                name,
                o[0],
                b[0],
                "libigl read+cotmatrix+massmatrix+H",
                o[2],
                b[2],
                f"CPU time (user + sys) {cpu_o:.2f} s vs {cpu_b:.2f} s: {cpu_o / cpu_b:.2f}x",
            )
        )
    return rows


def fig_smooth(scan: Path, repeat: int) -> list[Row]:
    """Implicit cotan smoothing: factorization alone (CHOLMOD, cholespy) vs our first step."""
    _, rss, text = python_child(
        f"""
        import time, numpy as np, scipy.sparse as sp
        from meshlap_core.io import load_mesh
        from meshlap_core.linalg.spd import solver_backend
        from meshlap_core.smoothing.stepper import Smoother, operator_parts
        m = load_mesh({str(scan)!r})
        res = {{"chol": [], "cholespy": [], "first": [], "next": [], "build": [],
                "solve": [], "cholespy_solve": []}}
        for _ in range({repeat}):
            W, K = operator_parts(m.V, m.F, "cotan")
            A = (sp.diags(W) - 0.5 * K).tocsc()
            try:
                from sksparse.cholmod import cholesky
                t = time.perf_counter(); f = cholesky(A)
                res["chol"].append(time.perf_counter() - t)
                del f
            except ImportError:
                pass
            from cholespy import CholeskySolverD, MatrixType
            Ac = A.tocsr()
            t = time.perf_counter()
            cs = CholeskySolverD(A.shape[0], Ac.indptr.astype(np.int32),
                                 Ac.indices.astype(np.int32), Ac.data, MatrixType.CSR)
            res["cholespy"].append(time.perf_counter() - t)
            B = np.ascontiguousarray(W[:, None] * m.V)
            X = np.empty_like(B)
            for _ in range(3):
                t = time.perf_counter(); cs.solve(B, X)
                res["cholespy_solve"].append(time.perf_counter() - t)
            del W, K, A, Ac, cs
            t = time.perf_counter()
            s = Smoother(m.V, m.F, "implicit", "cotan", lam=0.5)
            res["build"].append(time.perf_counter() - t)
            t = time.perf_counter(); s.step(); res["first"].append(time.perf_counter() - t)
            t = time.perf_counter()
            for _ in range(5):
                s.step()
            res["next"].append((time.perf_counter() - t) / 5)
            B = np.ascontiguousarray(s._W[:, None] * s.V)
            for _ in range(3):
                t = time.perf_counter(); s._solver.solve(B)
                res["solve"].append(time.perf_counter() - t)
            del s
        print(solver_backend(len(m.V)), *[min(v) if v else -1 for v in res.values()])
        """
    )
    backend, chol, cholespy, first, nxt, build, solve, cholespy_solve = text.split()
    chol_f, cholespy_f = float(chol), float(cholespy)
    rows = [
        Row(
            scan.name,
            "CHOLMOD (scikit-sparse) factorization of M - lam C",
            chol_f,
            cholespy_f,
            "cholespy factorization",
            note="not installed" if chol_f < 0 else "",
        ),
        Row(
            scan.name,
            f"implicit cotan: first step ({backend})",
            float(first),
            chol_f if chol_f > 0 else cholespy_f,
            "CHOLMOD factorization alone" if chol_f > 0 else "cholespy factorization alone",
            rss_ours=rss,
            note=f"Smoother construction {float(build):.2f} s (operators, volume)",
        ),
        Row(
            scan.name,
            f"implicit cotan: next steps, each ({backend})",
            float(nxt),
            0.1,
            "target 10 steps/s",
            note=f"of it the 3-column solve {float(solve):.3f} s",
        ),
        Row(
            scan.name,
            f"3-column solve alone ({backend})",
            float(solve),
            float(cholespy_solve),
            "cholespy's solve (the floor measured here)",
        ),
    ]
    return rows


def fig_smooth_window(scan: Path, repeat: int) -> list[Row]:
    """The window's implicit cotan stepper built in a worker thread (the former way) and in a
    child process (``meshlap_app.smoother_process``), side by side in one process: the longest
    gap of a thread that wakes every 10 ms meanwhile (the GIL held: the UI stall a window
    would see), the build's time, and a step's round trip (with the child: the solve, the
    normals and the copy out of shared memory)."""
    _, rss, text = python_child(
        f"""
        import threading, time, numpy as np
        from meshlap_core.io import load_mesh
        from meshlap_app.jobs import Reporter
        from meshlap_app.smoother_process import RemoteSmoother
        from meshlap_app.state.smoothing import SmoothingState

        def ticked(fn):
            gaps, done = [0.0], threading.Event()
            def tick():
                last = time.perf_counter()
                while not done.is_set():
                    time.sleep(0.01)
                    now = time.perf_counter()
                    gaps[0], last = max(gaps[0], now - last), now
            t = threading.Thread(target=tick); t.start()
            t0 = time.perf_counter()
            try:
                out = fn()
            finally:
                done.set(); t.join()
            return out, time.perf_counter() - t0, gaps[0]

        m = load_mesh({str(scan)!r})
        opts = ("implicit", "cotan", 0.5, 0.0, 0)
        res = {{"t_build": [], "t_stall": [], "t_step": [], "c_build": [], "c_stall": [],
                "c_step": [], "c_step_stall": []}}
        for _ in range({repeat}):
            sm, b, g = ticked(lambda: SmoothingState.build(m.V, m.F, opts))
            res["t_build"].append(b); res["t_stall"].append(g)
            _, b, g = ticked(lambda: [sm.step() for _ in range(3)])
            res["t_step"].append(b / 3)
            del sm
            rep = Reporter(threading.Event())
            r, b, g = ticked(lambda: RemoteSmoother.start(m.V, m.F, opts, rep))
            res["c_build"].append(b); res["c_stall"].append(g)
            _, b, g = ticked(lambda: [r.step() for _ in range(3)])
            res["c_step"].append(b / 3); res["c_step_stall"].append(g)
            r.close()
        print(*[min(v) for v in res.values()])
        """
    )
    t_build, t_stall, t_step, c_build, c_stall, c_step, c_step_stall = map(float, text.split())
    return [
        Row(
            scan.name,
            "window stepper built in a child process / in a thread (implicit cotan)",
            c_build,
            t_build,
            "the same build in a thread",
            rss_ours=rss,
        ),
        Row(
            scan.name,
            "longest GIL stall of a 10 ms ticker during the build: child / thread",
            c_stall,
            t_stall,
            "the same build in a thread",
            note="target <= 0.5 s",
        ),
        Row(
            scan.name,
            "one implicit step, round trip: child (solve + normals + copy) / in-process",
            c_step,
            t_step,
            "in-process step",
            note=f"longest ticker stall during 3 child steps {c_step_stall:.3f} s",
        ),
    ]


EIGSH_SCRIPT = """
import sys, numpy as np, igl, scipy.sparse.linalg as sla
from threadpoolctl import threadpool_limits
V, F = igl.read_triangle_mesh(sys.argv[1])
C = igl.cotmatrix(V, F)
M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
with threadpool_limits(1):
    lam, U = sla.eigsh(-C, int(sys.argv[2]), M=M, sigma=-1e-8, which="LM")
print(lam.max())
"""


def run_child_cpu(argv: list[str]) -> tuple[float, float, float]:
    """Run ``argv``; return (wall seconds, peak RSS in MiB, CPU seconds user + system). On a
    machine shared with other work the CPU seconds move less than the wall time."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        err = proc.stderr.read().decode() if proc.stderr else ""
        raise RuntimeError(f"{' '.join(argv[:4])}... failed:\n{err[-2000:]}")
    return wall, usage.ru_maxrss / 1024.0, usage.ru_utime + usage.ru_stime


WINDOW_SPECTRAL = """
import os, sys, time, tempfile
from meshlap_app.jobs import Jobs, warm_up
from meshlap_app.state.spectral import SpectralState
from meshlap_core.io import load_mesh
from meshlap_core.linalg import spd
os.environ["MESHLAP_CACHE_DIR"] = tempfile.mkdtemp()  # (--no-cache, as the CLI row)
spd.prefer_gil_free(True)  # as the window does for its threads
mesh = load_mesh(sys.argv[1])
jobs = Jobs()
jobs.processes = True  # as the window: the eigenbasis job in a child process
warm_up()
time.sleep(1.0)  # (the fork server is started with the window, long before a basis)
s = SpectralState(k_request=int(sys.argv[2]))
t0 = time.perf_counter()
s.start(mesh.V, mesh.F, jobs=jobs)
worst, tick = 0.0, time.perf_counter()
while not s.poll():  # the UI thread: 10 ms frames; the longest gap is its worst stall
    time.sleep(0.01)
    now = time.perf_counter()
    worst, tick = max(worst, now - tick), now
print(time.perf_counter() - t0, worst, s.basis.info.messages[0] if s.basis else s.error)
"""


def fig_window_spectral(scan: Path) -> Row:
    """The window's eigenbasis job (``SpectralState`` on ``Jobs(processes=True)``: a child
    process, CHOLMOD where installed) as a whole: wall time from the start to the basis
    adopted, the longest gap of a 10 ms loop on the calling thread meanwhile, and the peak
    RSS of the calling process (the window's side: the job's own process is not counted)."""
    load = os.getloadavg()[0]
    _, rss, text = run_child([PY, "-c", WINDOW_SPECTRAL, str(scan), "100"])
    took, worst, how = text.strip().split(" ", 2)
    return Row(
        scan.name,
        "window eigenbasis job k = 100 (child process), start to adopted",
        float(took),
        60.0,
        "target 60 s",
        rss,
        None,
        f"longest UI-thread gap {float(worst):.2f} s; {how}; load {load:.1f}",
    )


def fig_spectral(scan: Path, repeat: int, eigsh_mesh: Path | None) -> list[Row]:
    """``meshlap spectral --k 100`` on the scan (time, RSS, CPU), and vs eigsh on
    armadillo_igl (alternating runs; the best of each)."""
    rows = []
    argv = [*MESHLAP, "spectral", str(scan), "--k", "100", "--no-cache", "--json"]
    load = os.getloadavg()[0]
    wall, rss, cpu = min(run_child_cpu(argv) for _ in range(max(1, repeat - 1)))
    rows.append(
        Row(
            scan.name,
            "meshlap spectral --k 100, whole process",
            wall,
            60.0,
            "target 60 s",
            rss,
            None,
            f"target < 3 GB peak; CPU {cpu:.1f} s; load {load:.1f}",
        )
    )
    rows.append(fig_window_spectral(scan))
    if eigsh_mesh is not None:
        argv = [*MESHLAP, "spectral", str(eigsh_mesh), "--k", "100", "--no-cache", "--json"]
        ours, base = [], []
        load = os.getloadavg()[0]
        for _ in range(repeat):
            ours.append(run_child_cpu(argv))
            base.append(run_child_cpu([PY, "-c", EIGSH_SCRIPT, str(eigsh_mesh), "100"]))
        o, b = min(ours), min(base)
        rows.append(
            Row(
                eigsh_mesh.name,
                "meshlap spectral --k 100, whole process",
                o[0],
                b[0],
                "libigl + eigsh shift-invert, whole process",
                o[1],
                b[1],
                f"CPU ours {min(x[2] for x in ours):.2f} s, eigsh {min(x[2] for x in base):.2f} s"
                f"; load {load:.1f}",
            )
        )
    return rows


# ------------------------------------------------------------------------------ the table


def print_rows(rows: list[Row]) -> None:
    print(
        "| scan | figure | ours [s] | baseline [s] | ratio | baseline | RSS ours / base [MiB] "
        "| note |"
    )
    print("|---|---|---:|---:|---:|---|---|---|")
    for r in rows:
        ratio = f"{r.ours / r.base:.2f}x" if r.base else "-"
        base = f"{r.base:.2f}" if r.base is not None and r.base >= 0 else "-"
        rss = " / ".join(f"{x:.0f}" if x is not None else "-" for x in (r.rss_ours, r.rss_base))
        print(
            f"| {r.scan} | {r.figure} | {r.ours:.2f} | {base} | {ratio} | {r.base_name} "
            f"| {rss} | {r.note} |",
            flush=True,
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="the 692k scan only, fewer repeats")
    ap.add_argument("--repeat", type=int, default=None, help="runs per figure (default 3)")
    ap.add_argument("--only", default="load,cli,smooth,spectral", help="figures to run")
    ap.add_argument("--keep", type=Path, default=None, help="keep/reuse the scans in this folder")
    ap.add_argument("--big-only", action="store_true", help="the 2.77M scan only")
    args = ap.parse_args()
    repeat = args.repeat or (2 if args.quick else 3)
    only = set(args.only.split(","))
    print(f"load average before: {os.getloadavg()}", flush=True)
    tmp = None
    folder = args.keep
    if folder is None:
        tmp = tempfile.mkdtemp(prefix="meshlap_scans_")
        folder = Path(tmp)
    folder.mkdir(parents=True, exist_ok=True)
    try:
        scans = make_scans(folder, big=not args.quick or args.big_only)
        if args.big_only:
            scans = scans[1:]
        eigsh_mesh = SHARED / "armadillo_igl.obj"
        rows: list[Row] = []
        for scan in scans:
            big = "2770k" in scan.name
            reps = 1 if big else repeat  # the 2.77M scan once
            if "load" in only:
                rows += fig_load(scan, reps)
            if "cli" in only:
                rows += fig_cli(scan, reps)
            if "smooth" in only:
                rows += fig_smooth(scan, reps)
                rows += fig_smooth_window(scan, reps)
            if "spectral" in only and not big:
                rows += fig_spectral(scan, reps, eigsh_mesh if eigsh_mesh.is_file() else None)
            for fig in VIEWER_FIGURES:
                rows += fig(scan, reps)
            print_rows(rows)
            print()
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
