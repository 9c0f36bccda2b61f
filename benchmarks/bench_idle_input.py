"""Input after idle (issue 33): how long the real window takes to show a key pressed after
seconds without input, at rest (the bundled mesh) and on the 692k scan, and the idle CPU.

Usage::

    python benchmarks/bench_idle_input.py [SCAN.obj] [--presses N] [--idle S] [--no-scan]

Each mesh gets a ``meshlap view`` under Xvfb at 1280×720 (the tests' real-window harness,
``tests/xwindow.py``: the child gets ``tests/`` on its ``PYTHONPATH``, as pytest gives it to
the tests). Once the mesh is on screen and the picture still, the viewer is left alone for
``--idle`` seconds (default 6: past the deep idle rate of :mod:`meshlap_app.pacing`), its CPU
time measured over the last 5 of them (``/proc/<pid>/stat``), then a key is pressed with
``xdotool``: ``H`` (the Help pane: the panel changes, the scene is not redrawn) and ``2`` (the
one-ring view: the scene is redrawn, which costs a software OpenGL a few tenths of a second
whatever the pacing); each is then pressed back (``H``, ``1``) right after a mouse move, at
the full frame rate, for comparison. The latency is the time from the key press to the first
frame that differs from the picture before it: each frame the viewer draws is counted with X
DAMAGE and read at once with ``XGetImage`` (a few milliseconds). Also printed: when the frame
that read the key ended its pause (from the viewer's ``MESHLAP_PACING_TRACE``), the frames
drawn from the key to the changed one, and the load average before and after (timings on a shared
machine are noisy). No threshold is checked.

Without ``SCAN`` the 692k armadillo is made once in the temp folder (one ``igl.upsample`` of
``../shared/meshes/armadillo_loop.obj``, as ``tests/test_window_scale.py`` does).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SIZE = (1280, 720)
CHANGED = 1e-3  # fraction of the window's pixels a view key changes (a panel section: ~5 %)


def cpu_seconds(pid: int) -> float:
    """``utime + stime`` of process ``pid`` in seconds."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def press_latency(session: Any, key: str, timeout: float = 120.0) -> tuple[float, int, float]:
    """Press ``key`` on a still window; seconds until the first frame that differs from the
    picture before, the frames drawn up to it (that one included), and the time the key
    was pressed (``time.monotonic``, the clock the pacing trace uses)."""
    from imgui_screen import changed_fraction

    frames = session.app.frames
    before = frames.grab()
    box = (0, 0, before.shape[1], before.shape[0])
    frames.mark()
    t0 = time.monotonic()
    session.x.xdotool("key", key)
    seen = 0
    while time.monotonic() - t0 < timeout:
        if not frames.wait(seen + 1, timeout, session.app.alive):
            break
        t = time.monotonic()
        seen = frames.count
        if changed_fraction(before, frames.grab(), box) > CHANGED:
            return t - t0, seen, t0
    raise RuntimeError(f"no changed frame {timeout:.0f} s after the key {key}")


def read_after(trace: Path, t0: float) -> float:
    """Seconds from ``t0`` to the start of the first frame of the pacing trace that read
    input (the pause before the answer), NaN when the trace has none."""
    for line in trace.read_text().splitlines():
        rec = json.loads(line)
        if rec["input"] and rec["start"] >= t0:
            return rec["end"] - t0
    return float("nan")


def measure(mesh: Path | None, presses: int, idle: float, tmp: Path) -> dict[str, Any]:
    """One viewer on ``mesh`` (``None``: the bundled mesh): idle CPU and key latencies, after
    ``idle`` seconds without input and right after a mouse move (the full rate)."""
    from test_window import Session
    from test_window_scale import strictly_loading

    trace = tmp / "pacing.jsonl"
    os.environ["MESHLAP_PACING_TRACE"] = str(trace)  # the viewer's environment
    s = Session(SIZE, mesh, tmp)
    try:
        if mesh is not None:  # the scan loads as a job after the window opened
            s.until(
                lambda img: mesh.name in s.app.title() and not strictly_loading(img),
                1800,
                "the loaded scan",
            )
        s.settled((0, 0, *SIZE), timeout=600)
        pid = s.app.proc.pid
        keys = {"panel": ("h", "h"), "view": ("2", "1")}  # after idle, then at full rate
        out: dict[str, Any] = {
            f"{kind}_{k}": [] for kind in keys for k in ("idle", "active", "read", "frames")
        }
        out["cpu"] = []
        for _ in range(presses):
            for kind, (key, back) in keys.items():
                s.park()
                time.sleep(max(idle - 5.0, 0.0))
                c0, w0 = cpu_seconds(pid), time.monotonic()
                time.sleep(min(idle, 5.0))
                out["cpu"].append((cpu_seconds(pid) - c0) / (time.monotonic() - w0))
                latency, n, t0 = press_latency(s, key)
                out[f"{kind}_idle"].append(latency)
                out[f"{kind}_frames"].append(n)
                out[f"{kind}_read"].append(read_after(trace, t0))
                s.settled((0, 0, *SIZE), timeout=600)
                # the key back at the full rate: the mouse moves, the key follows at once
                s.x.xdotool("mousemove", "5", str(SIZE[1] - 5))
                s.drawn(1)
                out[f"{kind}_active"].append(press_latency(s, back)[0])
                s.settled((0, 0, *SIZE), timeout=600)
        problem = s.problem()
    finally:
        s.close()
    return {
        "mesh": mesh.name if mesh is not None else "bundled (bumpy.obj)",
        **out,
        "problem": problem or "",
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scan", nargs="?", type=Path)
    parser.add_argument("--presses", type=int, default=4)
    parser.add_argument("--idle", type=float, default=6.0, help="seconds without input")
    parser.add_argument("--no-scan", action="store_true", help="the bundled mesh only")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        mesh = None if args.scan is None else args.scan
        with tempfile.TemporaryDirectory() as out:
            row = measure(mesh, args.presses, args.idle, Path(out))
        print(json.dumps(row))
        return
    from bench_window_scale import default_scan

    meshes: list[Path | None] = [None]
    if not args.no_scan:
        meshes.append(args.scan or default_scan())
    paths = [str(ROOT / "tests"), os.environ.get("PYTHONPATH", "")]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in paths if p)}
    print(f"load average before: {os.getloadavg()}", flush=True)
    rows = []
    for mesh in meshes:
        argv = [sys.executable, __file__, "--child", "--presses", str(args.presses)]
        argv += ["--idle", str(args.idle), *([str(mesh)] if mesh is not None else [])]
        proc = subprocess.run(argv, stdout=subprocess.PIPE, text=True, env=env, timeout=7200)
        if proc.returncode != 0:
            sys.exit(f"the measurement failed (exit code {proc.returncode}); stderr above")
        rows.append(json.loads(proc.stdout.strip().splitlines()[-1]))
        print(f"load average now: {os.getloadavg()}", flush=True)
    print(
        "| mesh | key | after idle → changed frame [s] | → the frame that reads it [s] "
        "| at full rate → changed frame [s] | frames after idle | idle CPU [% of a core] |"
    )
    print("|---|---|---|---|---|---|---:|")

    def cell(xs: list[float]) -> str:
        return f"{statistics.median(xs):.3f} ({', '.join(f'{x:.2f}' for x in xs)})"

    for r in rows:
        for kind, what in (
            ("panel", "H (the panel only)"),
            ("view", "2 / 1 (a view: redraws the scene)"),
        ):
            print(
                f"| {r['mesh']} | {what} | {cell(r[kind + '_idle'])} | {cell(r[kind + '_read'])} "
                f"| {cell(r[kind + '_active'])} | {r[kind + '_frames']} "
                f"| {100 * statistics.median(r['cpu']):.1f} |"
                + (f" {r['problem']}" if r["problem"] else "")
            )
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
