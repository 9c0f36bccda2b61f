"""One ``meshlap view`` on one Xvfb, driven like a user (xdotool), read from screenshots.

:class:`Session` starts the viewer (the installed console script) on a virtual X display,
sends real clicks, drags and keys, and waits for visible outcomes or for the frames the viewer
drew after an input event (never a guessed sleep); its failures are recorded so a tour reports
every failing step. Widgets are found on a screenshot by colour and layout
(:mod:`tests.support.imgui_screen`). :func:`spectral` is the tour's step for the Spectral view,
which the keys test takes too.
"""

from __future__ import annotations

import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from tests.support.imgui_screen import (
    Layout,
    behind_panel,
    changed_fraction,
    parse,
    popup_lines,
    subjects,
)
from tests.support.xwindow import App, XServer, write_png

STILL = 3e-5  # fraction of changed pixels that is no change (a blinking text cursor)


WAIT = 30.0  # seconds a change shown after an input may take (only a failure waits it out)


FRAME_TIMEOUT = 30.0  # seconds the viewer may take to draw the frames after one input event


def meshlap_command() -> list[str]:
    """The console script of this environment (``meshlap``), as a user runs it."""
    exe = Path(sys.executable).parent / "meshlap"
    if not exe.exists():
        found = shutil.which("meshlap")
        if found is None:
            pytest.skip("the `meshlap` console script is not installed (pip install -e .)")
        exe = Path(found)
    return [str(exe), "view"]


def foreign_lines(text: str) -> list[str]:
    """stderr lines that are not polyscope's own ``[polyscope] ...`` messages."""
    return [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("[polyscope]")]


class Session:
    """One viewer on one X server: input helpers, screenshots, and the failures recorded."""

    def __init__(self, size: tuple[int, int], mesh: Path | None, tmp: Path) -> None:
        self.size, self.mesh, self.tmp = size, mesh, tmp
        self.x = XServer(*size).start()
        self.app: App | None = None
        self.shots = tmp / "shots"
        self.shots.mkdir(parents=True, exist_ok=True)
        self.failures: list[str] = []
        self.n_shot = 0
        self.img = np.zeros((size[1], size[0], 3), dtype=np.uint8)
        self.start()

    # -------------------------------------------------------------- process
    def start(self) -> None:
        home = self.tmp / f"run{len(list(self.tmp.glob('run*')))}"
        home.mkdir()
        argv = meshlap_command() + ([str(self.mesh)] if self.mesh is not None else [])
        self.app = App(self.x, argv, cwd=home).start(title="meshlap")
        self.panel = 1  # the curvature panel
        w, h = self.size
        self.x.xdotool("windowmove", self.app.window, "0", "0")
        self.x.xdotool("windowsize", self.app.window, str(w), str(h))
        self.park()

        def ready(img: np.ndarray) -> bool:  # the panel drawn at the new size, a mesh framed
            try:
                layout = parse(img)
            except LookupError:
                return False
            return (
                layout.right >= w - 40 and len(layout.sections) >= 3 and bool(subjects(img, layout))
            )

        self.until(ready, 60, "the viewer's panel and mesh at the window's size")

    def close(self) -> None:
        if self.app is not None:
            self.app.stop()
        self.x.stop()

    def problem(self) -> str | None:
        """Why the viewer is not fine (dead, or stderr beyond polyscope's lines), else None."""
        assert self.app is not None
        err = self.app.stderr()
        if not self.app.alive():
            code = self.app.proc.returncode if self.app.proc else None
            return f"viewer exited with code {code}; stderr: {err.strip()!r}"
        extra = foreign_lines(err)
        if extra:
            return f"stderr holds more than polyscope's lines: {extra!r}"
        return None

    # -------------------------------------------------------------- screen
    def screenshot(self, name: str = "") -> np.ndarray:
        self.img = self.x.screenshot()
        if name:
            self.n_shot += 1
            w, h = self.size
            write_png(self.shots / f"{w}x{h}_{self.n_shot:02d}_{name}.png", self.img)
        return self.img

    def layout(self) -> Layout:
        return parse(self.screenshot())

    def until(self, test: Callable[[np.ndarray], bool], timeout: float, what: str) -> np.ndarray:
        """Screenshots until ``test(img)`` holds (returns that one); AssertionError naming
        ``what`` after ``timeout`` seconds or when the viewer died."""
        deadline = time.monotonic() + timeout
        while True:
            img = self.screenshot()
            if test(img):
                return img
            if self.app is not None and not self.app.alive():
                raise AssertionError(f"the viewer died while waiting for {what}")
            if time.monotonic() > deadline:
                raise AssertionError(f"after {timeout:.0f} s still no {what}")
            time.sleep(0.1)

    def settled(self, box: tuple[int, int, int, int], timeout: float = WAIT) -> np.ndarray:
        """Wait until ``box`` is the same on two screenshots in a row (up to a text cursor's
        blink: 3e-5 of its pixels)."""
        prev, calm = [self.screenshot()], [0]

        def same(img: np.ndarray) -> bool:  # no change over 3 screenshots, frames between
            calm[0] = calm[0] + 1 if changed_fraction(prev[0], img, box) < STILL else 0
            prev[0] = img
            self.drawn(2)  # at least one whole frame before the next screenshot
            return calm[0] >= 2

        return self.until(same, timeout, "steady picture")

    # -------------------------------------------------------------- input
    def drawn(self, n: int = 2) -> None:
        """Wait until the viewer drew ``n`` frames after the input event just sent (it read
        the event and drew its outcome); AssertionError when it died or hangs."""
        assert self.app is not None
        self.app.drawn(n, FRAME_TIMEOUT)

    def park(self) -> None:
        """Rest the mouse in the scene's bottom-left corner (no hover, no tooltip)."""
        self.x.xdotool("mousemove", "3", str(self.size[1] - 3))

    def click(self, xy: tuple[int, int]) -> None:
        """Move to ``xy``, click, park; returns once the viewer read the click (a field
        clicked has the keyboard, a button clicked has acted)."""
        x, y = (str(int(v)) for v in xy)
        self.x.xdotool("mousemove", x, y)
        self.drawn()  # the hover frame first: ImGui acts on a press over a hovered item
        self.x.xdotool("click", "1")
        self.drawn()  # the press and release read at ``xy``, before the mouse parks
        self.park()

    def key(self, *keys: str) -> None:
        """Press the ``keys`` one after the other, each once the viewer read the one before
        (typed text arrives in order; a shortcut acts before the next key)."""
        for k in keys:
            self.x.xdotool("key", k)
            self.drawn()

    def drag(self, a: tuple[int, int], b: tuple[int, int], steps: int = 6) -> None:
        """Press at ``a``, move to ``b`` in ``steps`` moves, release, park; the viewer draws
        frames after each event (ImGui reads a press over a hovered item, follows each move
        with the button down, and releases where the last move went)."""
        self.x.xdotool("mousemove", str(a[0]), str(a[1]))
        self.drawn()
        self.x.xdotool("mousedown", "1")
        self.drawn()
        for t in np.linspace(0, 1, steps + 1)[1:]:
            x, y = (round(p + t * (q - p)) for p, q in zip(a, b, strict=True))
            self.x.xdotool("mousemove", str(x), str(y))
            # also the last move: a release in the same frame as the last move ends the drag
            # before ImGui reads the new position
            self.drawn()
        self.x.xdotool("mouseup", "1")
        self.drawn()
        self.park()

    def choose(self, section: int, nth: int, entry: int) -> None:
        """Open the ``nth`` combo of a section and pick its ``entry``-th line."""
        combo = self.layout().find(section, "combo", nth)
        self.click(combo.center)
        seen: list[list[tuple[int, int]]] = [[]]

        def opened(img: np.ndarray) -> bool:  # enough lines, the same on two screenshots
            found = popup_lines(img, combo)
            done = len(found) > max(entry, 1) and found == seen[-1]
            seen.append(found)
            return done

        self.until(opened, WAIT, f"list of at least {entry + 1} entries under the combo")
        self.click(seen[-1][entry])
        self.until(lambda img: len(popup_lines(img, combo)) < 2, WAIT, "closed list after a pick")

    def goto(self, number: int, header: str) -> Layout:
        """Press the view's number key (``1``–``9``, ``0`` for the tenth); wait until the
        panel's section changed."""
        before = self.layout()
        # the whole panel below the mesh section: two headers alone can differ by < 1 % of
        # their pixels ("Curvature lab" → "Curvature")
        box = panel_box(self, before)
        old = self.img
        self.key(str(number % 10))
        if self.panel != number:
            self.until(lambda img: changed_fraction(old, img, box) > 0.01, WAIT, f"{header} panel")
        self.panel = number
        return parse(self.settled((0, 0, *self.size)))

    def subject_ok(self, layout: Layout, n: int, what: str) -> None:
        """At least ``n`` objects left of the panel, none running behind it."""
        found = subjects(self.img, layout)
        if len(found) < n:
            raise AssertionError(f"{what}: {len(found)} object(s) left of the panel, want {n}")
        if behind_panel(self.img, layout):
            raise AssertionError(f"{what}: the subject runs behind meshlap's panel")

    # -------------------------------------------------------------- the tour
    def step(self, name: str, action: Callable[[Session], None]) -> None:
        """Run one step; record an exception, a death or foreign stderr; restart if dead."""
        err, t0 = None, time.monotonic()
        try:
            action(self)
        except Exception as exc:
            err = f"{type(exc).__name__}: {exc}"
        self.screenshot(name)
        print(f"{self.size[0]}x{self.size[1]} {name}: {time.monotonic() - t0:.1f} s")
        problem = self.problem()
        if problem or err:
            self.failures.append(f"{name}: " + "; ".join(p for p in (err, problem) if p))
        assert self.app is not None
        if not self.app.alive():  # exited: its last words are all in the stderr file
            self.failures[-1] += f"; stderr: {self.app.stderr().strip()!r}"
            self.start()


def scene_box(s: Session, layout: Layout) -> tuple[int, int, int, int]:
    """The scene left of meshlap's panel."""
    return 0, 0, layout.left, s.size[1]


def pixels(a: np.ndarray, b: np.ndarray, box: tuple[int, int, int, int]) -> int:
    """How many pixels of ``box`` differ between two screenshots."""
    x0, y0, x1, y1 = box
    return round(changed_fraction(a, b, box) * max(x1 - x0, 0) * max(y1 - y0, 0))


def panel_box(s: Session, layout: Layout) -> tuple[int, int, int, int]:
    """meshlap's panel from its second section's header to the window's bottom."""
    return layout.left, layout.sections[1][0].y0, layout.right, s.size[1]


def section_box(layout: Layout, section: int) -> tuple[int, int, int, int]:
    sec = layout.sections[section]
    nxt = layout.sections[section + 1][0].y0 if section + 1 < len(layout.sections) else None
    return layout.left, sec[0].y0, layout.right, nxt or layout.bottom


def spectral(s: Session, to: float = 1 / 3) -> None:
    """Key 3; "compute eigenbasis": eigenmode and k sliders, the reconstruction beside the
    mesh; drag k (the last slider) to the fraction ``to`` of its range: the reconstruction
    changes (a later call drags elsewhere: a new basis keeps the k shown before, so a drag to
    the same place could leave the reconstruction as it was)."""
    layout = s.goto(3, "Spectral")
    row = layout.find(1, "buttons", 0)
    s.click(((row.buttons[0][0] + row.buttons[0][1]) // 2, row.center[1]))
    s.until(
        lambda img: sum(it.kind == "slider" for it in parse(img).sections[1]) >= 2,
        60,
        "eigenmode and k sliders after 'compute eigenbasis'",
    )
    layout = parse(s.settled((0, 0, *s.size)))
    s.subject_ok(layout, 2, "mesh and reconstruction")
    slider = layout.find(1, "slider", -1)
    before, y = s.img, slider.center[1]
    # the drag waits for the viewer at each stage (a new k may take a second or more to
    # draw, and a release queued behind a slow frame can lose the motion): press at the
    # left end (k = 1 shows), move to a third with the button down (k follows), release
    knob = (slider.x0, slider.y0, slider.x1, slider.y1)
    s.x.xdotool("mousemove", str(slider.x0 + 6), str(y))
    s.drawn()  # hovered before the press
    s.x.xdotool("mousedown", "1")
    try:
        pressed = s.until(
            lambda img: changed_fraction(before, img, knob) > 0.01, WAIT, "k = 1 on the slider"
        )
        s.x.xdotool("mousemove", str(slider.x0 + int((slider.x1 - slider.x0) * to)), str(y))
        s.until(
            lambda img: changed_fraction(pressed, img, knob) > 0.01, WAIT, "k following the mouse"
        )
    finally:
        s.x.xdotool("mouseup", "1")
        s.park()
    # a new k may take the viewer a second or more to draw (software GL compiles the error
    # map's shader): a still screen is no proof yet; wait for the mesh and the new
    # reconstruction (the press at the slider's left end shows k = 1 first: a single point)
    s.until(
        lambda img: (
            changed_fraction(before, img, scene_box(s, layout)) > 0.002
            and len(subjects(img, parse(img))) >= 2
        ),
        WAIT,
        "change of the reconstruction after dragging k, the mesh and the reconstruction shown",
    )
    s.subject_ok(parse(s.settled((0, 0, *s.size))), 2, "after dragging k")


def keep_shots(s: Session) -> None:
    target = os.environ.get("MESHLAP_WINDOW_SHOTS")
    if target:
        Path(target).mkdir(parents=True, exist_ok=True)
        for png in s.shots.glob("*.png"):
            shutil.copy2(png, Path(target) / png.name)


def scroll_to_end(s: Session) -> Layout:
    """Turn the mouse wheel over meshlap's panel until it scrolls no further (the one-ring
    panel with the vertex inspector is taller than the window); the last header is then
    the panel's last section (Help)."""
    layout = parse(s.settled((0, 0, *s.size)))
    for _ in range(20):
        before = s.img
        s.x.xdotool("mousemove", str(layout.left + 20), str(s.size[1] // 2))
        s.x.xdotool("click", "--repeat", "3", "5")
        s.park()
        s.drawn()  # the viewer read the wheel and drew the panel scrolled (or not)
        # the scroll bar's strip: hover highlights and tooltips over the panel do not count
        box = (layout.right - 18, layout.top + 30, layout.right + 1, s.size[1])
        if changed_fraction(before, s.screenshot(), box) <= 0.002:
            return parse(s.img)  # nothing moved: the end
        layout = parse(s.settled((0, 0, *s.size)))
    raise AssertionError("meshlap's panel still scrolls after 20 turns of the wheel")


def scroll_to_top(s: Session) -> Layout:
    """Turn the mouse wheel up over meshlap's panel (30 notches: more than any panel's
    length) and wait for the steady picture."""
    layout = parse(s.settled((0, 0, *s.size)))
    s.x.xdotool("mousemove", str(layout.left + 20), str(s.size[1] // 2))
    s.x.xdotool("click", "--repeat", "30", "4")  # wheel up
    s.park()
    return parse(s.settled((0, 0, *s.size)))
