"""A real scan in the real window (issue 21): ``meshlap view`` of the 691,858-vertex armadillo
(one ``igl.upsample`` of ``../shared/meshes/armadillo_loop.obj``, made once in a temp folder)
under Xvfb at 1280×720, driven with xdotool.

The window opens on the bundled mesh at once and loads the scan as a job; the test checks what
the issue asks, on screenshots and on ``/proc``:

- the screen changes at least once a second while the scan loads (the progress line's elapsed
  time moves; bound :data:`MAX_STILL_S`, generous: one second plus the time a screenshot takes
  on a loaded 2-core machine); the scan's geometry is shown coloured (the preview: a quick
  uniform H) while the job still runs, and its curvature colours then; the two draws of
  polyscope on the UI thread (the preview's 1.4M new triangles, buffers made on the thread
  that owns the GL context; the final colour map) are measured and bounded apart
  (:data:`MAX_UPLOAD_S`);
- a click on another section during the load is answered (the *Export* header opens);
- the viewer's CPU time falls below :data:`IDLE_CPU` of one core, measured over 5 s after 5 s
  without input (``utime + stime`` of ``/proc/<pid>/stat``).

It takes minutes on a loaded machine (the load alone is about 5 s of CPU); it is marked
``window`` like ``tests/window/test_tour.py`` and runs in CI (``.ci/run``).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from tests.support.imgui_screen import changed_fraction, parse, subject_mask, subjects
from tests.support.window_session import STILL, WAIT, Session
from tests.support.xwindow import missing_tools

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT.parent / "shared" / "meshes" / "armadillo_loop.obj"
MAX_STILL_S = 2.0
"""Longest time the screen may stay the same while the scan loads (the issue: once a second;
the rest is the screenshot's own time under load)."""
MAX_UPLOAD_S = 20.0
"""Longest still screen before the loaded scan appears: the mesh registered, coloured and drawn
for the first time (about 2 s of CPU with Mesa's llvmpipe; a loaded machine stretches it)."""
IDLE_CPU = 0.10
"""Most CPU (fraction of one core) the idle viewer may use (the issue's bound)."""
LOAD_TIMEOUT_S = 600.0


def scan_path() -> Path:
    """The 692k scan, made once per machine in the temp folder (never in the checkout)."""
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


def cpu_seconds(pid: int) -> float:
    """``utime + stime`` of process ``pid`` in seconds."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def job_row(section: list) -> bool:
    """The Mesh section holds its job's row (a progress bar and Cancel, parsed as a field with
    its button like *path* / *Open*: a second such row)."""
    return sum(it.kind == "input" for it in section) >= 2


def loading(img: np.ndarray) -> bool:
    """The Mesh section shows a job (its progress bar and Cancel button row)."""
    try:
        return job_row(parse(img).sections[0])
    except LookupError:
        return True  # the panel is being redrawn: not finished as far as we can tell


def coloured_pixels(img: np.ndarray) -> int:
    """Coloured pixels of the subject (the curvature colour map: the upsampled scan is mostly
    pale, near H = 0, with red and blue ridges)."""
    layout = parse(img)
    c = img[:, : layout.left].astype(np.int16)
    return int(((c.max(axis=-1) - c.min(axis=-1) > 30) & subject_mask(img, layout)).sum())


def subject_size(img: np.ndarray) -> int:
    """Pixels of the subject left of the panel."""
    return int(subject_mask(img, parse(img)).sum())


def export_header(img: np.ndarray):
    """The Export header (the third section's first item), or ``None`` while the panel is
    not fully drawn."""
    try:
        return parse(img).sections[2][0]
    except (LookupError, IndexError):
        return None


def export_opened(img: np.ndarray) -> bool:
    """The Export section shows more than its header."""
    try:
        return len(parse(img).sections[2]) > 1
    except (LookupError, IndexError):
        return False


def drawn_size(img: np.ndarray) -> int | None:
    """:func:`subject_size`, or ``None`` while the window shows no panel yet (its first
    frames may be black)."""
    try:
        return subject_size(img)
    except LookupError:
        return None


def strictly_loading(img: np.ndarray) -> bool:
    """The Mesh section shows a job's progress and Cancel row (a half-drawn panel: no)."""
    try:
        return job_row(parse(img).sections[0])
    except LookupError:
        return False


class ScanSession(Session):
    """A :class:`Session` that keeps the time line of its screenshots from the window's first
    one (the load may end while the session is still sizing the window on a fast machine)."""

    def screenshot(self, name: str = "") -> np.ndarray:
        img = super().screenshot(name)
        line = self.__dict__.setdefault("timeline", [])
        changed = not line or bool((img != line[-1][2]).any())
        if changed:
            line.append((time.monotonic(), strictly_loading(img), img))
        return img


def open_scan(tmp_path) -> ScanSession:
    """``meshlap view`` on the 692k scan at 1280×720 (skips without the window tools or the
    mesh the scan is made from)."""
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    if not SOURCE.exists():
        pytest.skip(f"{SOURCE} is absent (the scan is made from it with igl.upsample)")
    return ScanSession((1280, 720), scan_path(), tmp_path)


@pytest.mark.window
def test_a_692k_scan_opens_without_freezing_and_idles(tmp_path):
    s = open_scan(tmp_path)
    try:
        assert s.app is not None
        # the job's row appears once the file is read (the window may be up before)
        s.until(lambda img: any(busy for _, busy, _ in s.timeline), 60, "the scan loading as a job")
        line = s.timeline
        # the bundled mesh on the window's first picture; the load starts with the scan's
        # preview or the job's row, whichever shows first (the preview may come before the row)
        sizes = [drawn_size(img) for _, _, img in line]  # (None: not drawn yet)
        start = next(i for i, size in enumerate(sizes) if size is not None)
        before = sizes[start]
        first = next(
            i
            for i in range(start, len(line))
            if line[i][1] or (sizes[i] is not None and abs(sizes[i] - before) > 0.1 * before)
        )
        t0 = line[first][0]
        answered, clicked_at = False, None
        while loading(s.img):
            if time.monotonic() - t0 > LOAD_TIMEOUT_S:
                raise AssertionError(f"the scan did not load in {LOAD_TIMEOUT_S:.0f} s")
            export = export_header(s.img) if clicked_at is None else None
            if export is not None:  # the Export header, closed: clicked during the load
                s.x.xdotool("mousemove", str(export.center[0]), str(export.center[1]))
                s.x.xdotool("click", "1")
                s.park()
                clicked_at = time.monotonic()
            img = s.screenshot()
            if clicked_at is not None and not answered:
                answered = export_opened(img)
            assert s.app.alive(), f"the viewer died: {s.app.stderr()}"
        loaded_after = time.monotonic() - t0
        if clicked_at is not None and not answered:  # a load that ended right after the click
            s.until(
                export_opened,
                WAIT,
                "the Export header opened by the click made during the load",
            )
            answered = True
        s.screenshot("scale_loaded")
        # the changes of the screen from the first loading picture to the loaded scan
        shots = s.timeline[first:]
        times = [t for t, _, _ in shots]
        gaps = np.diff(times).tolist() or [0.0]
        # the preview: the scan's geometry on screen while the job still runs (its first
        # draw, like the final upload, is polyscope's on the UI thread: bounded apart)
        preview = next(
            (
                i
                for i, (_, busy, img) in enumerate(shots[:-1])  # (the last: the loaded scan)
                if abs((drawn_size(img) or before) - before) > 0.1 * before
            ),
            None,
        )
        assert preview is not None, "the scan was not shown before its load ended (no preview)"
        assert coloured_pixels(shots[preview][2]) > 1000, "the preview is not coloured"
        preview_draw = gaps[preview - 1] if preview > 0 else 0.0
        upload = gaps[-1]  # the last change shows the loaded scan with its curvature colours
        still = max(
            (g for i, g in enumerate(gaps[:-1]) if i != preview - 1),
            default=0.0,
        )
        print(
            f"loaded after {loaded_after:.1f} s; preview shown after "
            f"{times[preview] - t0:.1f} s (its first draw {preview_draw:.2f} s); longest still "
            f"screen while loading {still:.2f} s; before the final colours {upload:.2f} s"
        )
        assert still <= MAX_STILL_S, f"the screen stood still {still:.2f} s during the load"
        assert preview_draw <= MAX_UPLOAD_S, f"the preview's first draw took {preview_draw:.2f} s"
        assert upload <= MAX_UPLOAD_S, f"the first draw of the scan took {upload:.2f} s"
        if clicked_at is not None:  # the load outlived the window's sizing (else that was
            # the input answered during the load: the panel redrawn at the new size)
            assert answered, "the click on the Export header during the load was not answered"
        assert abs(subject_size(s.img) - before) > 0.1 * before, "the scan is not on screen"
        assert coloured_pixels(s.img) > 1000, "the loaded scan is not coloured"
        assert "armadillo_692k.obj" in s.app.title()
        # idle: nothing happens for 5 s, then 5 s of CPU time measured
        s.park()
        pid = s.app.proc.pid
        time.sleep(5.0)
        c0, w0 = cpu_seconds(pid), time.monotonic()
        time.sleep(5.0)
        idle = (cpu_seconds(pid) - c0) / (time.monotonic() - w0)
        print(f"idle CPU {100 * idle:.1f} % of a core")
        assert idle < IDLE_CPU, f"the idle viewer uses {100 * idle:.0f} % of a core"
        problem = s.problem()
        assert problem is None, problem
    finally:
        s.close()


MAX_SHOW_S = 60.0
"""Longest still screen before the stepper's two copies appear once it is built: the 1.4M-
triangle copies registered and drawn for the first time on the UI thread (polyscope owns the
GL context), one per frame: 1.1–3.8 s each at load 1.5–6.5 by
``benchmarks/bench_window_scale.py`` (both in one frame: 9–21 s at load 8–12 before)."""


def two_subjects(img: np.ndarray) -> bool:
    """The smoothing panel's input and smoothed copy are both on screen."""
    try:
        return len(subjects(img, parse(img))) >= 2
    except LookupError:
        return False


@pytest.mark.window
def test_a_692k_scan_smooths_without_freezing(tmp_path):
    """Key 4 on the loaded scan: the implicit stepper is built as a job (in a child process,
    so its factorization does not hold the window's GIL): the screen keeps changing at least
    every :data:`MAX_STILL_S` until the input and its smoothed copy appear; then *play* moves
    the copy and *pause* stops it."""
    s = open_scan(tmp_path)
    try:
        assert s.app is not None
        s.until(
            lambda img: "armadillo_692k.obj" in s.app.title() and not strictly_loading(img),
            LOAD_TIMEOUT_S,
            "the loaded scan",
        )
        s.settled((0, 0, *s.size), timeout=LOAD_TIMEOUT_S)
        s.timeline.clear()
        s.key("4")  # the smoothing panel: a first visit builds its stepper as a job
        t0 = time.monotonic()
        while not two_subjects(s.screenshot()):
            if time.monotonic() - t0 > LOAD_TIMEOUT_S:
                raise AssertionError(f"no smoothed copy after {LOAD_TIMEOUT_S:.0f} s")
            assert s.app.alive(), f"the viewer died: {s.app.stderr()}"
        times = [t for t, _, _ in s.timeline]
        gaps = np.diff(times).tolist() or [0.0]
        still = max(gaps[:-1], default=0.0)
        print(
            f"stepper shown after {time.monotonic() - t0:.1f} s; longest still screen while "
            f"it was built {still:.2f} s; before the copies appeared {gaps[-1]:.2f} s"
        )
        assert still <= MAX_STILL_S, f"the screen stood still {still:.2f} s during the build"
        assert gaps[-1] <= MAX_SHOW_S, f"the copies took {gaps[-1]:.2f} s to appear"
        layout = parse(s.settled((0, 0, *s.size), timeout=LOAD_TIMEOUT_S))
        box = (0, 0, layout.left, s.size[1])
        row = layout.find(1, "buttons", 0)  # back / step / play / reset
        row_box = (row.x0, row.y0, min(row.x1 + 60, layout.right), row.y1)
        before = s.img
        s.key("space")  # play: the child solves, the window shows each batch of steps
        # above 1M faces play hides the input at once: that change first, then a step's
        s.until(lambda img: changed_fraction(before, img, box) > 0.002, 300, "play started")
        started = s.settled(box, timeout=LOAD_TIMEOUT_S)
        s.until(lambda img: changed_fraction(started, img, box) > STILL, 300, "a smoothing step")
        playing = s.screenshot()
        s.key("space")  # pause, with steps on their way (the child runs ahead of the window)
        paused = s.until(
            lambda img: changed_fraction(playing, img, row_box) > 0.01, 300, "'play' again"
        )
        # issue 33: the steps the child computed after the press never reach the screen
        # (before, four more were applied after the pause)
        after = s.settled(box, timeout=LOAD_TIMEOUT_S)
        assert changed_fraction(paused, after, box) <= STILL, "steps shown after the pause"
        s.key("Left")  # one step back: the last 8 steps of the scan are kept
        s.until(lambda img: changed_fraction(after, img, box) > STILL, 300, "a step back")
        problem = s.problem()
        assert problem is None, problem
    finally:
        s.close()
