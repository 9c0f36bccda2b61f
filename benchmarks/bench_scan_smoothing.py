"""Smoothing a 692k scan at the speed of the fastest solve, and the scan's other figures, side by
side in one run (issue 38).

Run from the repository root (the ``fast`` extra installed: scikit-sparse's CHOLMOD)::

    python benchmarks/bench_scan_smoothing.py              # every figure, 2 rounds
    python benchmarks/bench_scan_smoothing.py --only steps,window --rounds 3

The scan is ``igl.upsample`` of ``../shared/meshes/armadillo_loop.obj`` (691,858 vertices),
made once in ``/tmp/meshlap-scans/`` (``--scans DIR`` elsewhere) and reused. Every figure runs
in fresh child processes; ours and its baseline alternate within a child, and each child runs
``--rounds`` times (the figures are the medians, the ranges in the notes). The load average is
printed with every row: on a machine shared with other work the wall times move, the CPU
times (given where they mean something) less.

Figures (implicit cotan smoothing, ``λ = 1e-5``, as ``meshlap smooth SCAN --method implicit
--laplacian cotan --lam 1e-5``):

* ``first``: ``Smoother(...).step()``'s first step (the factorization inside it, and the
  helper's start) against CHOLMOD's factorization alone and cholespy's, one after the other
  in one child;
* ``steps``: a run of steps as ``meshlap smooth`` takes them (``Smoother.step`` with its
  per-step figures): the step-to-step interval while CHOLMOD answers and after cholespy's
  helper has taken over, alternating (after the hand-over) blocks of steps with blocks of
  CHOLMOD's and cholespy's three-column solves made in the same child (target: a step
  <= 1.0x the faster solve); the choice and reason ``meshlap smooth --json`` reports for 10
  and for 300 steps;
* ``window``: the window's stepper child (``meshlap_app.smoother_process.RemoteSmoother``,
  asked for steps as *play* asks) and the CLI's stepper (``Smoother`` as ``meshlap smooth``
  makes it) in one process, both after their hand-over, stepping in alternate 10 s spans:
  steps computed per second (target: equal);
* ``screenshot``: ``meshlap view SCAN --screenshot OUT.png`` as a whole process: wall time and
  peak RSS (target < 1 GB);
* ``curvature``: ``meshlap curvature SCAN --method cotan`` against the libigl script of
  ``bench_scale.py`` (read + cotmatrix + massmatrix + H), alternating, wall and CPU (target
  <= 0.9x).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "meshes"
PY = sys.executable
MESHLAP = [PY, "-m", "meshlap_core.cli"]
LAM = 1e-5

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


def load() -> float:
    return os.getloadavg()[0]


def run(argv: list[str], env: dict[str, str] | None = None) -> tuple[float, float, float, str]:
    """Run ``argv``; (wall s, CPU s user + system, peak RSS MiB, stdout) of that child."""
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(argv, stdout=out, stderr=err, env={**os.environ, **(env or {})})
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            raise RuntimeError(f"{' '.join(argv[:5])}... failed:\n{err.read().decode()[-3000:]}")
        out.seek(0)
        text = out.read().decode()
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0, text


def python(code: str, *args: str) -> dict:
    """Run a snippet in a fresh process; its last stdout line is a JSON object."""
    *_, text = run([PY, "-c", textwrap.dedent(code), *args])
    return json.loads(text.strip().splitlines()[-1])


def make_scan(folder: Path) -> Path:
    scan = folder / "armadillo_692k.obj"
    if scan.is_file():
        return scan
    src = SHARED / "armadillo_loop.obj"
    if not src.is_file():
        sys.exit(f"{src} is needed (the real meshes live beside the checkout)")
    folder.mkdir(parents=True, exist_ok=True)
    print(f"making {scan} ...", flush=True)
    tmp = folder / f".{scan.name}.{os.getpid()}.obj"
    code = f"""
        import igl
        V, F = igl.read_triangle_mesh({str(src)!r})
        V, F = igl.upsample(V, F)
        igl.write_triangle_mesh({str(tmp)!r}, V, F)
        print("{{}}")
        """
    python(code)
    os.replace(tmp, scan)
    return scan


def med(xs: list[float]) -> float:
    return statistics.median(xs)


def span(xs: list[float], unit: str = "s", scale: float = 1.0) -> str:
    return f"{min(xs) * scale:.3g}-{max(xs) * scale:.3g} {unit}"


# ------------------------------------------------------------------------------ children

FIRST = """
import json, sys, time, numpy as np, scipy.sparse as sp
from meshlap_core.io import load_mesh
from meshlap_core.smoothing import Smoother
from meshlap_core.smoothing.stability import operator_parts
m = load_mesh(sys.argv[1]); lam = float(sys.argv[2]); what = sys.argv[3]
out = {}
if what == "first":  # as meshlap smooth does it: the stepper, then its first step
    s = Smoother(m.V, m.F, "implicit", "cotan", lam=lam, warn=False)
    t = time.perf_counter(); s.step(); out["s"] = time.perf_counter() - t
    out["backend"] = s.solver_report()["first"]
    s.close()
else:
    W, K = operator_parts(m.V, m.F, "cotan")
    A = (sp.diags(W) - lam * K).tocsr(); A.sum_duplicates(); A.sort_indices()
    if what == "cholmod":
        from meshlap_core.linalg.spd import SPDSolver
        t = time.perf_counter(); SPDSolver(A, "cholmod"); out["s"] = time.perf_counter() - t
    else:
        from cholespy import CholeskySolverD, MatrixType
        i32 = np.int32
        t = time.perf_counter()
        CholeskySolverD(A.shape[0], A.indptr.astype(i32), A.indices.astype(i32), A.data,
                        MatrixType.CSR)
        out["s"] = time.perf_counter() - t
print(json.dumps(out))
"""

STEPS = """
import json, sys, time, gc, os, numpy as np, scipy.sparse as sp
from meshlap_core.io import load_mesh
from meshlap_core.linalg.spd import SPDSolver
from meshlap_core.smoothing import Smoother
from cholespy import CholeskySolverD, MatrixType
m = load_mesh(sys.argv[1]); lam = float(sys.argv[2]); rounds = int(sys.argv[3])
s = Smoother(m.V, m.F, "implicit", "cotan", lam=lam, warn=False, history_limit=1000)
s.step()
before, last = [], time.perf_counter()
while s.solver_report()["answering"] != "cholespy (helper)" and len(before) < 400:
    s.step(); now = time.perf_counter(); before.append(now - last); last = now
rep = s.solver_report()
# the baselines in this process: CHOLMOD's and cholespy's factors of the same system
free = s._free; A = s._solver.A; w = s._solver.w
chol = SPDSolver(A, "cholmod")
espy = CholeskySolverD(A.shape[0], A.indptr.astype(np.int32), A.indices.astype(np.int32),
                       A.data, MatrixType.CSR)
B = np.ascontiguousarray(w[:, None] * s.V[free]); X = np.empty_like(B)
steps, cs, ch, cs_cpu, ch_cpu, loads, step_cpu = [], [], [], [], [], [], []
for r in range(rounds * 4):
    s.step(); last = time.perf_counter()
    for _ in range(5):
        c = time.thread_time(); s.step(); step_cpu.append(time.thread_time() - c)
        now = time.perf_counter(); steps.append(now - last); last = now
    for _ in range(3):
        t = time.perf_counter(); c = time.thread_time(); espy.solve(B, X)
        cs.append(time.perf_counter() - t); cs_cpu.append(time.thread_time() - c)
        t = time.perf_counter(); c = time.thread_time(); chol.solve(B)
        ch.append(time.perf_counter() - t); ch_cpu.append(time.thread_time() - c)
    loads.append(os.getloadavg()[0])
rep2 = s.solver_report()
print(json.dumps({"before": before, "steps": steps, "cholespy": cs, "cholmod": ch,
                  "cholespy_cpu": cs_cpu, "cholmod_cpu": ch_cpu, "loads": loads,
                  "handover": rep["handover_iteration"], "helper_factor_s": rep["helper_factor_s"],
                  "factor_s": rep["factor_s"], "helper_solve_ms": rep2["solve_ms"],
                  "helper_solve_cpu_ms": rep2["helper_solve_cpu_ms"], "step_cpu": step_cpu}))
"""

WINDOW = """
import json, sys, time, threading, os, numpy as np
from meshlap_core.io import load_mesh
from meshlap_core.cli.smooth import HISTORY_SAMPLES
from meshlap_core.smoothing import Smoother
from meshlap_app.jobs import Reporter
from meshlap_app.smoother_process import RemoteSmoother
m = load_mesh(sys.argv[1]); lam = float(sys.argv[2]); seconds = float(sys.argv[3])
rounds = int(sys.argv[4])
r = RemoteSmoother.start(m.V, m.F, ("implicit", "cotan", lam, 0.0, 0), Reporter(threading.Event()))
# the CLI's stepper (meshlap smooth: history_samples, no reference), open-ended
cli = Smoother(m.V, m.F, "implicit", "cotan", lam=lam, warn=False,
               history_samples=HISTORY_SAMPLES)
cli.step()
view = (0.0, 0.0, 0.0, 1.0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.0, 0.0, 0.0)
def play(until):
    # as *play* asks: up to PIPELINE requests on their way, a few steps each
    while not until():
        r.request_step(4, view)
        r.poll()
        time.sleep(0.002)
    r.finish(); r.poll()
t0 = time.perf_counter()
play(lambda: r.solver_report().get("answering") == "cholespy (helper)"
     or time.perf_counter() - t0 > 900)
while cli.solver_report()["answering"] != "cholespy (helper)" and time.perf_counter() - t0 < 900:
    cli.step()
def cpu(pid):  # user + system seconds of a process
    with open(f"/proc/{pid}/stat") as fh:
        f = fh.read().rsplit(")", 1)[1].split()
    return (int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK")
def children(pid):
    with open(f"/proc/{pid}/task/{pid}/children") as fh:
        return [int(x) for x in fh.read().split()]
child = r.process.pid
grand = children(child)  # the child's helper process
mine = cli._solver.helper.process.pid
window, steps, loads, wcpu, ccpu = [], [], [], [], []
for _ in range(rounds):
    it0, t1 = r.iteration, time.perf_counter()
    c0 = (cpu(child), sum(cpu(g) for g in grand), time.process_time())
    play(lambda: time.perf_counter() - t1 > seconds)
    k = r.iteration - it0
    window.append(k / (time.perf_counter() - t1))
    c1 = (cpu(child), sum(cpu(g) for g in grand), time.process_time())
    wcpu.append([(b - a) / k for a, b in zip(c0, c1)])
    it0, t1 = cli.iteration, time.perf_counter()
    c0 = (time.process_time(), cpu(mine))
    while time.perf_counter() - t1 < seconds:
        cli.step()
    k = cli.iteration - it0
    steps.append(k / (time.perf_counter() - t1))
    c1 = (time.process_time(), cpu(mine))
    ccpu.append([(b - a) / k for a, b in zip(c0, c1)])
    loads.append(os.getloadavg()[0])
rep = r.solver_report(); r.close(); cli.close()
print(json.dumps({"window": window, "cli": steps, "loads": loads, "wcpu": wcpu, "ccpu": ccpu,
                  "handover": rep["handover_iteration"], "helper_solve_ms": rep["solve_ms"]}))
"""


def fig_first(scan: Path, rounds: int) -> list[list[str]]:
    """Each in a fresh process (each as cold as a user's first step), in turn."""
    res: dict[str, list[float]] = {"first": [], "cholmod": [], "cholespy": []}
    loads, backend = [], ""
    for r in range(rounds):
        order = ["first", "cholmod", "cholespy"]
        for what in order if r % 2 == 0 else order[::-1]:
            loads.append(load())
            out = python(FIRST, str(scan), str(LAM), what)
            res[what].append(out["s"])
            backend = out.get("backend", backend)
    first, chol, espy = med(res["first"]), med(res["cholmod"]), med(res["cholespy"])
    return [
        [
            "first implicit step (factorization inside)",
            f"{first:.2f} s",
            f"CHOLMOD factorization {chol:.2f} s / cholespy's {espy:.2f} s",
            f"{first / chol:.2f}x / {first / espy:.2f}x",
            f"{min(loads):.1f}-{max(loads):.1f}",
            f"each in a fresh process, in turn: first step {span(res['first'])}; CHOLMOD "
            f"{span(res['cholmod'])}; cholespy {span(res['cholespy'])}; answered by {backend}",
        ]
    ]


def fig_steps(scan: Path, rounds: int) -> list[list[str]]:
    r = python(STEPS, str(scan), str(LAM), str(rounds))
    step, cs, ch = med(r["steps"]), med(r["cholespy"]), med(r["cholmod"])
    fast = min(cs, ch)
    before = med(r["before"]) if r["before"] else float("nan")
    loads = f"{min(r['loads']):.1f}-{max(r['loads']):.1f}"
    rows = [
        [
            "step while CHOLMOD answers (before the hand-over)",
            f"{before:.3f} s",
            f"CHOLMOD's 3-column solve {ch:.3f} s",
            f"{before / ch:.2f}x",
            loads,
            f"{len(r['before'])} steps; CHOLMOD factorized in {r['factor_s']:.1f} s, the "
            f"helper's cholespy in {r['helper_factor_s']:.1f} s (in parallel); "
            f"hand-over at step {r['handover']}",
        ],
        [
            "median step after the hand-over (step to step, with its figures)",
            f"{step:.3f} s",
            f"faster solve {fast:.3f} s (cholespy {cs:.3f}, CHOLMOD {ch:.3f})",
            f"{step / fast:.2f}x",
            loads,
            f"{len(r['steps'])} steps in blocks of 5 alternating with the solves; CPU of the "
            f"solves: cholespy {med(r['cholespy_cpu']):.3f} s, CHOLMOD "
            f"{med(r['cholmod_cpu']):.3f} s; the helper's own solve "
            f"{r['helper_solve_ms']['cholespy (helper)']:.0f} ms, CPU "
            f"{r['helper_solve_cpu_ms']:.0f} ms; step CPU (this process) "
            f"{med(r['step_cpu']):.3f} s",
        ],
    ]
    for iters in (10, 300):
        *_, text = run(
            [
                *MESHLAP,
                "smooth",
                str(scan),
                "--method",
                "implicit",
                "--laplacian",
                "cotan",
                "--lam",
                str(LAM),
                "--iters",
                str(iters),
                "--json",
            ]
        )
        res = json.loads(text)
        sol = res["solver"]
        rows.append(
            [
                f"meshlap smooth --iters {iters}: solver",
                f"{res['timings']['smoothing_s']:.1f} s",
                "-",
                "-",
                f"{load():.1f}",
                f"{sol['answering']} (hand-over at {sol['handover_iteration']}): {sol['reason']}",
            ]
        )
    return rows


def fig_window(scan: Path, rounds: int) -> list[list[str]]:
    r = python(WINDOW, str(scan), str(LAM), "10", str(2 * rounds))
    win, cli = med(r["window"]), med(r["cli"])
    wc = [1e3 * med([c[i] for c in r["wcpu"]]) for i in range(3)]
    cc = [1e3 * med([c[i] for c in r["ccpu"]]) for i in range(2)]
    return [
        [
            "window's stepper child after the hand-over: steps computed per second",
            f"{win:.2f} steps/s",
            f"the CLI's stepper in the same process, alternating: {cli:.2f} steps/s",
            f"{win / cli:.2f}x",
            f"{min(r['loads']):.1f}-{max(r['loads']):.1f}",
            f"{len(r['window'])} spans of 10 s each; window {span(r['window'], 'steps/s')}, "
            f"CLI {span(r['cli'], 'steps/s')}; the child's hand-over at step "
            f"{r['handover']}, its helper's solve "
            f"{r['helper_solve_ms']['cholespy (helper)']:.0f} ms; CPU per step: window "
            f"child {wc[0]:.0f} + its helper {wc[1]:.0f} + window side {wc[2]:.0f} ms, CLI "
            f"{cc[0]:.0f} + its helper {cc[1]:.0f} ms (the larger share of each is the step "
            "rate's bound on two idle cores)",
        ]
    ]


def fig_screenshot(scan: Path, rounds: int) -> list[list[str]]:
    walls, rss, loads = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(rounds):
            loads.append(load())
            wall, _, peak, _ = run(
                [*MESHLAP, "view", str(scan), "--screenshot", str(Path(tmp) / f"shot{i}.png")]
            )
            walls.append(wall)
            rss.append(peak)
    return [
        [
            "meshlap view SCAN --screenshot: peak RSS",
            f"{max(rss):.0f} MiB",
            "target 1024 MiB",
            f"{max(rss) / 1024:.2f}x",
            f"{min(loads):.1f}-{max(loads):.1f}",
            f"peak RSS {span(rss, 'MiB')}; wall {span(walls)}",
        ]
    ]


def fig_curvature(scan: Path, rounds: int) -> list[list[str]]:
    ours, base, loads = [], [], []
    for i in range(rounds * 2):
        loads.append(load())
        o = run([*MESHLAP, "curvature", str(scan), "--method", "cotan"])
        b = run([PY, "-c", IGL_SCRIPT, str(scan)])
        if i % 2:  # the order alternates too
            b = run([PY, "-c", IGL_SCRIPT, str(scan)])
            o = run([*MESHLAP, "curvature", str(scan), "--method", "cotan"])
        ours.append(o)
        base.append(b)
    ow, bw = med([o[0] for o in ours]), med([b[0] for b in base])
    oc, bc = med([o[1] for o in ours]), med([b[1] for b in base])
    ratios = [o[0] / b[0] for o, b in zip(ours, base, strict=True)]
    return [
        [
            "meshlap curvature --method cotan, whole process",
            f"{ow:.2f} s",
            f"libigl script {bw:.2f} s",
            f"{ow / bw:.2f}x",
            f"{min(loads):.1f}-{max(loads):.1f}",
            f"pairwise ratios {span(ratios, 'x')}; CPU {oc:.2f} s vs {bc:.2f} s "
            f"({oc / bc:.2f}x); peak RSS {max(o[2] for o in ours):.0f} vs "
            f"{max(b[2] for b in base):.0f} MiB",
        ]
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default="first,steps,window,screenshot,curvature")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--scans", type=Path, default=Path(tempfile.gettempdir()) / "meshlap-scans")
    args = ap.parse_args()
    only = set(args.only.split(","))
    print(f"load average before: {os.getloadavg()}", flush=True)
    scan = make_scan(args.scans)
    rows: list[list[str]] = []
    figures = [
        ("first", lambda: fig_first(scan, args.rounds)),
        ("steps", lambda: fig_steps(scan, args.rounds)),
        ("window", lambda: fig_window(scan, args.rounds)),
        ("screenshot", lambda: fig_screenshot(scan, args.rounds)),
        ("curvature", lambda: fig_curvature(scan, args.rounds)),
    ]
    for name, fn in figures:
        if name not in only:
            continue
        out = fn()
        for row in out:
            print(" | ".join(row), flush=True)
        rows += out
    print()
    print("| figure | ours | baseline | ratio | load | note |")
    print("|---|---:|---|---:|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print(f"\nload average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
