"""The window's figures of issue 21 on a big scan: open → first coloured frame, the longest UI
stall while the job runs, idle CPU, the viewer's peak RSS, and the smoothing panel's implicit
cotan stepper (its build job's longest UI stall, live steps per second).

Usage::

    python benchmarks/bench_window_scale.py [SCAN.obj] [--repeat N]

Without ``SCAN`` the 692k armadillo is made once in the temp folder (one ``igl.upsample`` of
``../shared/meshes/armadillo_loop.obj``, as ``tests/window/test_scale.py`` does). Each run is
a fresh child process (``python benchmarks/bench_window_scale.py --child SCAN``) that renders
with polyscope's EGL backend at 1280×720 through the viewer's own frame loop, paced as in the
window (:class:`meshlap_app.pacing.Pacer`): it opens the bundled mesh, then opens ``SCAN`` as
the Mesh section's job, ticks frames until the scan is on screen coloured, then stays idle
6 s and measures 5 s of its CPU time; then opens the smoothing panel with the implicit cotan
stepper (built as the panel's job, frames ticking meanwhile) and plays 10 frames. The parent
prints one table; no threshold is checked (timings on a shared machine are noisy): the load
average is printed before and after.

:func:`figures` is the hook for ``benchmarks/bench_scale.py`` (``VIEWER_FIGURES``) once both
sides of issue 21 are merged: ``VIEWER_FIGURES.append(lambda scan, repeat: figures(scan,
repeat, Row))``.
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
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT.parent / "shared" / "meshes" / "armadillo_loop.obj"


def default_scan() -> Path:
    """The 692k scan in the temp folder (made once)."""
    folder = Path(tempfile.gettempdir()) / "meshlap-scans"
    path = folder / "armadillo_692k.obj"
    if not path.exists():
        import igl

        folder.mkdir(exist_ok=True)
        V, F = igl.read_triangle_mesh(str(SOURCE))
        V2, F2 = igl.upsample(V, F)
        tmp = folder / f".armadillo_692k.{os.getpid()}.obj"
        igl.write_triangle_mesh(str(tmp), V2, F2)
        tmp.replace(path)
    return path


def child(scan: Path, smoothing: bool = True) -> dict[str, float]:
    """One measurement in this process (see the module docstring); returns the figures."""
    import polyscope as ps
    from meshlap_app.jobs import warm_up
    from meshlap_app.state import AppState
    from meshlap_app.viewer import Viewer, init_polyscope

    warm_up()  # as `meshlap view` does before it creates the window
    if os.environ.get("BENCH_PIPELINE"):  # steps on their way at once (1: no running ahead)
        from meshlap_app import smoother_process

        smoother_process.PIPELINE = int(os.environ["BENCH_PIPELINE"])
    init_polyscope("openGL3_egl")
    ps.set_max_fps(-1)
    ps.set_window_size(1280, 720)
    state = AppState()
    state.mesh.load(None)
    viewer = Viewer(state)
    viewer.sync_mesh()
    ps.set_user_callback(viewer.callback)
    ps.frame_tick()
    viewer.background = viewer.pace = True
    state.jobs.processes = True  # as `meshlap view` sets up the window
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    t0 = time.perf_counter()
    viewer.open(scan)
    last, stall, frames, upload = t0, 0.0, 0, 0.0
    preview_at, preview_draw = float("nan"), float("nan")
    while True:
        previewing = viewer.preview is not None
        ps.frame_tick()  # the frame that adopts the scan also draws it (colour map included)
        now = time.perf_counter()
        dt, last, frames = now - last, now, frames + 1
        if state.mesh.name == scan.name and not state.jobs.busy:
            upload = dt
            break
        if viewer.preview is not None and not previewing:
            # the frame that showed the preview drew it: the first coloured frame of the scan
            preview_at, preview_draw = now - t0, dt
        else:
            stall = max(stall, dt)
        if now - t0 > 900:
            raise RuntimeError("the scan did not load in 900 s")
    first_frame = last - t0
    rss_view = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    end = time.perf_counter() + 6.0
    while time.perf_counter() < end:  # 1 s to fall idle, 5 s more without input
        ps.frame_tick()
    c0, w0 = sum(os.times()[:2]), time.perf_counter()
    while time.perf_counter() - w0 < 5.0:
        ps.frame_tick()
    idle = (sum(os.times()[:2]) - c0) / (time.perf_counter() - w0)
    figures: dict[str, float] = {}
    if smoothing:
        figures = smoothing_figures(viewer, state)
        if os.environ.get("BENCH_SMOOTH_THREAD"):  # the former way beside it, same process
            state.jobs.processes = False
            thread = smoothing_figures(viewer, state, steps=3)
            figures.update({f"thread_{k}": v for k, v in thread.items()})
            state.jobs.processes = True
    return {
        **figures,
        "open_to_preview_s": preview_at,
        "preview_draw_s": preview_draw,
        "open_to_coloured_s": first_frame,
        "max_stall_loading_s": stall,
        "first_draw_s": upload,
        "frames_while_loading": float(frames),
        "idle_cpu_fraction": idle,
        "rss_before_mb": rss_before,
        "rss_view_mb": rss_view,
    }


def smoothing_figures(viewer: Any, state: Any, steps: int = 10) -> dict[str, float]:
    """The smoothing panel on the loaded scan: its implicit cotan stepper built as the panel's
    job (the longest frame meanwhile: the UI stall; then the frame that adopts it, registering
    and first drawing the smoothed copy, and the next, registering the input copy: one
    registration per frame), then *play* until ``steps`` steps are on screen. While playing,
    two rates counted apart: the steps the stepper computed per second and the frames that
    showed a new step per second (the child runs ahead: a frame shows the newest step done);
    the longest frame; the median frame that showed a step and the panel's upload in it (UI
    thread); the step's own time in the stepper (``history[-1]["time_ms"]``).

    With ``state.jobs.processes`` (the window's setting) the stepper lives in a child process
    (:mod:`meshlap_app.smoother_process`) and *play* asks for each step without waiting; without
    it, the stepper is built in a worker thread and each frame takes one step (the former way:
    the side-by-side baseline)."""
    import numpy as np
    import polyscope as ps

    panel = viewer.panels["smoothing"]
    st = panel.state
    st.method, st.laplacian = "implicit", "cotan"
    push_s: list[float] = []
    plain_push = panel.push

    def timed_push(host: Any, force: bool = False) -> None:
        t = time.perf_counter()
        plain_push(host, force)
        push_s.append(time.perf_counter() - t)

    panel.push = timed_push  # the panel's upload on the UI thread, frame by frame
    t0 = last = time.perf_counter()
    viewer.set_panel("smoothing")  # starts the build job
    if st.smoother is None and not panel.building(viewer):  # already the panel shown
        panel.start_build(viewer, raise_errors=False)
    stall, adopt, adopt_push = 0.0, 0.0, 0.0
    while st.smoother is None or panel.building(viewer):
        had = st.smoother
        push_s.clear()
        ps.frame_tick()
        now = time.perf_counter()
        if st.smoother is had:
            stall = max(stall, now - last)  # the job computing: the window should answer
        else:  # the frame that adopted the stepper: the smoothed copy registered
            adopt, adopt_push = now - last, sum(push_s)
        last = now
        if now - t0 > 900:
            raise RuntimeError("the smoother was not built in 900 s")
    built = last - t0
    push_s.clear()
    ps.frame_tick()
    adopt_input = time.perf_counter() - last  # the next frame: the input copy registered
    adopt_input_push = sum(push_s)
    t1 = time.perf_counter()
    ps.frame_tick()  # the next: the camera frames the two copies (both drawn)
    framing = time.perf_counter() - t1
    st.toggle_play()
    start, t = st.smoother.iteration, time.perf_counter()
    last, play_stall, shown, solve_ms, pushes = t, 0.0, [], [], []
    while st.smoother.iteration - start < steps and last - t < 300:
        it = st.smoother.iteration
        push_s.clear()
        ps.frame_tick()
        now = time.perf_counter()
        play_stall = max(play_stall, now - last)
        if st.smoother.iteration != it:
            shown.append(now - last)  # the frame that uploaded the step and drew it
            pushes.append(sum(push_s))
            solve_ms.append(st.smoother.history[-1]["time_ms"])
        last = now
    elapsed = last - t
    meter_steps, meter_frames = st.meter.rates(last)
    st.toggle_play()
    ps.frame_tick()  # pause: the input copy shown again
    panel.push = plain_push
    done = st.smoother.iteration - start
    remote = bool(getattr(st.smoother, "asynchronous", False))
    panel.on_new_mesh(viewer)  # the stepper (and its process) goes: the next run starts afresh
    return {
        "smoother_build_s": built,
        "max_stall_smoother_build_s": stall,
        "adopt_frame_s": adopt,
        "adopt_input_frame_s": adopt_input,
        "adopt_push_s": adopt_push,
        "framing_frame_s": framing,
        "adopt_input_push_s": adopt_input_push,
        "live_steps_per_s": done / elapsed,
        "shown_frames_per_s": len(shown) / elapsed,
        "meter_steps_per_s": meter_steps,
        "meter_frames_per_s": meter_frames,
        "max_stall_playing_s": play_stall,
        "upload_frame_s": float(np.median(shown)) if shown else -1.0,
        "push_s": float(np.median(pushes)) if pushes else -1.0,
        "step_solve_s": float(np.median(solve_ms)) / 1e3 if solve_ms else -1.0,
        "child_process": float(remote),
    }


def run_child(scan: Path, smoothing: bool = True) -> dict[str, float]:
    """:func:`child` in a fresh process (its peak RSS is the viewer's alone)."""
    out = subprocess.run(
        [
            sys.executable,
            __file__,
            "--child",
            str(scan),
            *([] if smoothing else ["--no-smoothing"]),
        ],
        capture_output=True,
        text=True,
        check=True,
        timeout=1800,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def figures(scan: Path, repeat: int, row: Callable[..., Any] | None = None) -> list[Any]:
    """The window figures of ``scan``, best of ``repeat`` runs (smallest time; idle CPU and RSS
    of the same run): ``row(scan=, figure=, ours=, base=, base_name=, ...)`` objects (the
    ``Row`` of ``bench_scale.py``) or dicts when ``row`` is ``None``."""
    runs = [run_child(scan) for _ in range(repeat)]
    best = min(runs, key=lambda r: r["open_to_coloured_s"])
    make = row or (lambda **kw: kw)
    name = scan.name
    return [
        make(
            scan=name,
            figure="window: open → first coloured frame [s]",
            ours=best["open_to_coloured_s"],
            base=None,
            base_name="",
            rss_ours=best["rss_view_mb"],
            note=f"max stall while loading {best['max_stall_loading_s']:.2f} s, "
            f"first draw {best['first_draw_s']:.2f} s",
        ),
        make(
            scan=name,
            figure="window: idle CPU [fraction of a core]",
            ours=best["idle_cpu_fraction"],
            base=None,
            base_name="",
        ),
        make(
            scan=name,
            figure="window: implicit cotan stepper built (the panel's job) [s]",
            ours=best["smoother_build_s"],
            base=None,
            base_name="",
            note=f"longest UI stall meanwhile {best['max_stall_smoother_build_s']:.2f} s, then "
            f"the frames registering its two copies {best['adopt_frame_s']:.2f} s and "
            f"{best['adopt_input_frame_s']:.2f} s",
        ),
        make(
            scan=name,
            figure="window: live implicit cotan steps per second (upload and draw included)",
            ours=best["live_steps_per_s"],
            base=10.0,
            base_name="target 10 steps/s",
            note=f"{best['shown_frames_per_s']:.2f} frames/s showing a step",
        ),
    ]


def smoothing_line(r: dict[str, float]) -> str:
    """The smoothing figures of one run, the thread baseline beside them when measured."""
    where = "child process" if r["child_process"] else "thread"
    out = (
        f"smoothing ({where}): build {r['smoother_build_s']:.2f} s, longest stall "
        f"{r['max_stall_smoother_build_s']:.2f} s, then the frame registering the smoothed "
        f"copy {r['adopt_frame_s']:.2f} s and the next, the input copy "
        f"{r.get('adopt_input_frame_s', float('nan')):.2f} s (polyscope's registration in "
        f"them {r.get('adopt_push_s', float('nan')):.2f} s, "
        f"{r.get('adopt_input_push_s', float('nan')):.2f} s), the next, framing both "
        f"{r.get('framing_frame_s', float('nan')):.2f} s; play "
        f"{r['live_steps_per_s']:.2f} steps/s computed and "
        f"{r.get('shown_frames_per_s', float('nan')):.2f} frames/s showing a step (the "
        f"panel's meter: {r.get('meter_steps_per_s', float('nan')):.2f} and "
        f"{r.get('meter_frames_per_s', float('nan')):.2f}), longest stall "
        f"{r['max_stall_playing_s']:.2f} s, frame showing a step "
        f"{r['upload_frame_s']:.2f} s (the panel's upload in it "
        f"{r.get('push_s', float('nan')):.2f} s), step in the stepper "
        f"{r['step_solve_s']:.3f} s"
    )
    if "thread_smoother_build_s" in r:
        out += (
            f"\nsmoothing (thread, before): build {r['thread_smoother_build_s']:.2f} s, longest "
            f"stall {r['thread_max_stall_smoother_build_s']:.2f} s, then "
            f"{r['thread_adopt_frame_s']:.2f} s; play "
            f"{r['thread_live_steps_per_s']:.2f} steps/s, longest stall "
            f"{r['thread_max_stall_playing_s']:.2f} s; ratios child/thread: build "
            f"{r['smoother_build_s'] / r['thread_smoother_build_s']:.2f}, stall "
            f"{r['max_stall_smoother_build_s'] / r['thread_max_stall_smoother_build_s']:.2f}, "
            f"steps/s {r['live_steps_per_s'] / r['thread_live_steps_per_s']:.2f}"
        )
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scan", nargs="?", type=Path)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    parser.add_argument(
        "--no-smoothing", action="store_true", help="skip the smoothing panel's figures"
    )
    args = parser.parse_args()
    smoothing = not args.no_smoothing
    if args.child is not None:
        print(json.dumps(child(args.child, smoothing)))
        return
    scan = args.scan or default_scan()
    print(f"load average before: {os.getloadavg()}")
    for _ in range(args.repeat):
        r = run_child(scan, smoothing)
        print(
            f"{scan.name}: open → first coloured frame (the preview) "
            f"{r['open_to_preview_s']:.2f} s "
            f"(its first draw {r['preview_draw_s']:.2f} s); open → curvature colours "
            f"{r['open_to_coloured_s']:.2f} s; longest UI "
            f"stall while loading {r['max_stall_loading_s']:.2f} s "
            f"({r['frames_while_loading']:.0f} frames); first draw of the scan "
            f"{r['first_draw_s']:.2f} s; idle CPU {100 * r['idle_cpu_fraction']:.1f} % of a "
            f"core; peak RSS {r['rss_view_mb']:.0f} MiB (bundled mesh only: "
            f"{r['rss_before_mb']:.0f} MiB)"
        )
        if smoothing:
            print(smoothing_line(r))
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
