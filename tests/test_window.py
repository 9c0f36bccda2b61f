"""The viewer in a real window: ``meshlap view`` under Xvfb, driven with xdotool like a user.

A scripted tour (open the mesh list and pick a mesh, every panel, type λ, drag k, click a vertex,
play/pause, export) runs at 1280×720 and 1920×1080, then a seeded "monkey" clicks, drags and
types at random. After every step the test takes a screenshot (``xwd``, decoded and written as
PNG by :mod:`tests.xwindow`) and checks that the process is alive and that its stderr holds
nothing but polyscope's own ``[polyscope]`` lines.

A step that kills the viewer is recorded with the viewer's stderr, the viewer is started again,
and the tour goes on, so one run reports every failing step; the test fails at the end with the
list. Widgets are found on each screenshot by colour and layout (:mod:`tests.imgui_screen`); the
order of widgets inside each section of meshlap's panel is stated once, in the step functions
below.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots (the default-size panel pictures
in ``docs/img/window/`` come from there); ``MESHLAP_MONKEY_SECONDS`` sets the monkey's time per
size (30 s).
"""

from __future__ import annotations

import os
import shutil
import struct
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from imgui_screen import Layout, changed_fraction, parse, popup_lines, subject_point
from xwindow import App, XServer, missing_tools, read_png, read_xwd, write_png

ROOT = Path(__file__).resolve().parents[1]
PANELS = ("curvature", "onering", "spectral", "smoothing", "surfaces")  # the "view" combo
SIZES = ((1280, 720), (1920, 1080))
SECOND_MESH = ROOT / "assets" / "torus.obj"
SETTLE = 0.35  # seconds for the viewer to draw a frame after an input event


def meshlap_command() -> list[str]:
    """The console script of this environment (``meshlap``), as a user runs it."""
    exe = Path(sys.executable).parent / "meshlap"
    if not exe.exists():
        found = shutil.which("meshlap")
        if found is None:
            pytest.skip("the `meshlap` console script is not installed (pip install -e .)")
        exe = Path(found)
    return [str(exe), "view"]


@pytest.fixture(scope="module")
def x_tools() -> None:
    missing = missing_tools()
    if missing:
        pytest.skip(
            f"real-window tests need {', '.join(missing)} (apt-get install xvfb xdotool "
            "x11-apps; .ci/run installs them)"
        )


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
        self.img: np.ndarray | None = None
        self.start()

    # -------------------------------------------------------------- process
    def start(self) -> None:
        home = self.tmp / f"run{len(list(self.tmp.glob('run*')))}"
        home.mkdir()
        argv = meshlap_command() + ([str(self.mesh)] if self.mesh is not None else [])
        self.app = App(self.x, argv, cwd=home).start()
        self.panel = "curvature"
        w, h = self.size
        self.x.xdotool("windowmove", self.app.window, "0", "0")
        self.x.xdotool("windowsize", self.app.window, str(w), str(h))
        deadline = time.monotonic() + 60
        while True:  # until the panel is drawn at the new size
            time.sleep(0.5)
            try:
                layout = self.layout()
                if len(layout.sections) >= 2 and layout.right >= w - 40:
                    return
            except LookupError:
                pass
            if time.monotonic() > deadline or not self.app.alive():
                raise RuntimeError(f"the viewer did not show its panel: {self.app.stderr()}")

    def close(self) -> None:
        if self.app is not None:
            self.app.stop()
        self.x.stop()

    @property
    def cwd(self) -> Path:
        assert self.app is not None
        return self.app.cwd

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

    def scene_box(self, layout: Layout) -> tuple[int, int, int, int]:
        """The part of the window left of meshlap's panel (where the subject is drawn)."""
        return int(0.25 * self.size[0]), 0, layout.left, self.size[1]

    def hidden(self, before: np.ndarray) -> str:
        """Say whether a change the scene did not show happened behind meshlap's panel."""
        img = self.screenshot()
        layout = parse(img)
        box = (layout.left, layout.top, layout.right, layout.bottom)
        panel = changed_fraction(before, img, box)
        return (
            f"left of the panel (behind meshlap's panel {100 * panel:.1f}% of its pixels "
            "changed: the subject is hidden by the panel)"
            if panel > 0.002
            else "(nor anywhere in the window)"
        )

    # -------------------------------------------------------------- input
    def click(self, xy: tuple[int, int]) -> None:
        x, y = (str(int(v)) for v in xy)
        self.x.xdotool("mousemove", x, y)
        time.sleep(0.12)  # the hover frame first: ImGui acts on a press over a hovered item
        self.x.xdotool("click", "1")
        time.sleep(SETTLE)

    def drag(
        self, a: tuple[int, int], b: tuple[int, int], steps: int = 8, pause: float = 1.5
    ) -> None:
        self.x.xdotool("mousemove", str(a[0]), str(a[1]))
        time.sleep(0.12)
        self.x.xdotool("mousedown", "1")
        time.sleep(pause)
        for t in np.linspace(0, 1, steps + 1)[1:]:
            x, y = (round(p + t * (q - p)) for p, q in zip(a, b, strict=True))
            time.sleep(0.1)
            self.x.xdotool("mousemove", str(x), str(y))
        # a release in the same frame as the last moves ends the drag before ImGui reads
        # the new position: let the viewer draw a frame with the button still down
        time.sleep(pause)
        self.x.xdotool("mouseup", "1")
        time.sleep(SETTLE)

    def type_into(self, xy: tuple[int, int], text: str) -> None:
        """Click a text field, select all, type ``text`` key by key, press Enter."""
        self.click(xy)
        time.sleep(1.0)  # the field becomes active on the next frame
        self.x.xdotool("key", "ctrl+a")
        time.sleep(0.5)
        self.x.xdotool("type", "--delay", "150", text)
        time.sleep(1.0)
        self.x.xdotool("key", "Return")
        time.sleep(1.0)

    def until(self, test: Callable[[np.ndarray], bool], timeout: float = 15.0) -> np.ndarray | None:
        """Screenshots until ``test(img)`` holds; the last one, or None on timeout/death.

        The viewer may draw only a few frames per second on a loaded machine, so every wait
        is for a visible outcome, not a fixed time."""
        deadline = time.monotonic() + timeout
        while True:
            img = self.screenshot()
            if test(img):
                return img
            if time.monotonic() > deadline or (self.app is not None and not self.app.alive()):
                return None
            time.sleep(0.2)

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

        if self.until(opened) is None:
            raise LookupError(f"the list opened by the combo shows {len(seen[-1])} entries")
        lines = seen[-1]
        self.click(lines[entry])
        if self.until(lambda img: len(popup_lines(img, combo)) < 2) is None:
            raise AssertionError("the combo's list did not close after a click on an entry")

    def goto(self, panel: str) -> Layout:
        """Switch meshlap's panel with the "view" combo (the last combo of the Mesh section);
        wait until the panel's second section (its own header and widgets) changed."""
        before = self.layout()
        header = before.sections[1][0] if len(before.sections) > 1 else before.sections[0][0]
        box = (header.x0, header.y0, header.x1, header.y1)
        old = self.img
        self.choose(0, -1, PANELS.index(panel))
        if self.panel != panel:
            self.until(lambda img: changed_fraction(old, img, box) > 0.01)
        self.panel = panel
        time.sleep(SETTLE)
        return self.layout()

    def wait_for(self, test: Callable[[Layout], bool], timeout: float) -> Layout:
        deadline = time.monotonic() + timeout
        while True:
            layout = self.layout()
            if test(layout) or time.monotonic() > deadline:
                return layout
            if self.app is not None and not self.app.alive():
                return layout
            time.sleep(0.5)

    # -------------------------------------------------------------- the tour
    def step(self, name: str, action: Callable[[Session], None]) -> None:
        """Run one step; record an exception, a death or foreign stderr; restart if dead."""
        err = None
        try:
            action(self)
        except Exception as exc:
            err = f"{type(exc).__name__}: {exc}"
        time.sleep(SETTLE)
        self.screenshot(name)
        problem = self.problem()
        if problem:  # an error message comes before the exit: let the viewer finish
            time.sleep(1.5)
            problem = self.problem()
        if problem or err:
            self.failures.append(f"{name}: " + "; ".join(p for p in (err, problem) if p))
        assert self.app is not None
        if not self.app.alive():
            self.start()


# ------------------------------------------------------------------ steps
def pick_mesh(s: Session) -> None:
    """Open the mesh list (the first combo of the Mesh section) and pick assets/torus.obj
    (the list's 5th line: assets/ sorted by name) or, with the torus open, assets/bumpy.obj."""
    before = s.screenshot()
    s.choose(0, 0, 0 if s.mesh == SECOND_MESH else 4)
    layout = s.layout()
    if changed_fraction(before, s.img, s.scene_box(layout)) < 0.02:
        raise AssertionError("the picked mesh did not replace the shown one")


def visit(panel: str) -> Callable[[Session], None]:
    def action(s: Session) -> None:
        layout = s.goto(panel)
        if len(layout.sections) < 3:
            raise AssertionError(f"{panel}: expected Mesh, {panel} and Export sections")

    return action


def kinds(img: np.ndarray, section: int, kind: str) -> int:
    """How many widgets of ``kind`` a section of the panel on ``img`` holds."""
    try:
        layout = parse(img)
    except LookupError:
        return 0
    if not -len(layout.sections) <= section < len(layout.sections):
        return 0
    return sum(it.kind == kind for it in layout.sections[section])


def curvature_widgets(s: Session) -> None:
    """field combo → 3rd entry (gaussian); side by side on (a "second field" combo appears);
    drag clip %."""
    s.goto("curvature")
    s.choose(1, 0, 2)
    layout = s.layout()
    n = kinds(s.img, 1, "combo")
    s.click(layout.find(1, "checkbox", 0).center)
    if s.until(lambda img: kinds(img, 1, "combo") > n) is None:
        raise AssertionError("side by side: no second-field combo appeared")
    slider = s.layout().find(1, "slider", 0)
    y = slider.center[1]
    s.drag((slider.x0 + 10, y), (slider.x0 + (slider.x1 - slider.x0) // 2, y))


def click_vertex(s: Session) -> None:
    """Click the mesh in the scene: the one-ring panel shows the picked vertex."""
    layout = s.goto("onering")
    point = subject_point(s.img, layout)
    if point is None:
        raise AssertionError("no mesh visible left of the panel")
    before = s.img
    s.click(point)
    box = (layout.left, layout.top, layout.right, layout.bottom)
    if s.until(lambda img: changed_fraction(before, img, box) > 0.005, timeout=10) is None:
        raise AssertionError(f"clicking the mesh at {point} changed nothing in the panel")


def type_vertex(s: Session) -> None:
    """Type a vertex number into the one-ring panel's "vertex" field."""
    layout = s.goto("onering")
    s.type_into(layout.find(1, "input", 0).center, "12")


def spectral_k(s: Session) -> None:
    """Compute the eigenbasis, then drag the k slider (the last slider): the
    reconstruction beside the mesh changes."""
    layout = s.goto("spectral")
    button = layout.find(1, "buttons", 0)
    s.click(((button.buttons[0][0] + button.buttons[0][1]) // 2, button.center[1]))
    if s.until(lambda img: kinds(img, 1, "slider") >= 2, timeout=90) is None:
        raise AssertionError("no eigenmode/k sliders after computing the eigenbasis")
    layout = s.layout()
    slider = layout.find(1, "slider", -1)
    before = s.img
    y = slider.center[1]
    s.drag((slider.x0 + 6, y), (slider.x0 + (slider.x1 - slider.x0) // 3, y))
    box = s.scene_box(layout)
    if s.until(lambda img: changed_fraction(before, img, box) > 0.002, timeout=10) is None:
        raise AssertionError("dragging k changed nothing in the scene " + s.hidden(before))


def type_lambda(s: Session) -> None:
    """Type λ = 0.25 into the smoothing panel's first input field (λ)."""
    layout = s.goto("smoothing")
    s.type_into(layout.find(1, "input", 0).center, "0.25")


def play_pause(s: Session) -> None:
    """play (2nd button of the step/play/reset row): the smoothed copy moves; pause: it stops."""
    layout = s.goto("smoothing")
    row = layout.find(1, "buttons", 0)
    play = ((row.buttons[1][0] + row.buttons[1][1]) // 2, row.center[1])
    box = s.scene_box(layout)
    s.click(play)
    time.sleep(2.0)
    a = s.screenshot()
    moving = s.until(lambda img: changed_fraction(a, img, box) > 0.0005, timeout=10)
    s.click(play)
    time.sleep(2.0)
    c = s.screenshot()
    time.sleep(2.0)
    still = changed_fraction(c, s.screenshot(), box)
    if moving is None:
        raise AssertionError("play: the smoothed copy does not move " + s.hidden(a))
    if still > 0.0005:
        raise AssertionError("pause: the smoothed copy still moves")


def surfaces_widgets(s: Session) -> None:
    """surface combo → 2nd entry, then drag u (first slider)."""
    s.goto("surfaces")
    s.choose(1, 0, 1)
    time.sleep(SETTLE)
    slider = s.layout().find(1, "slider", 0)
    y = slider.center[1]
    s.drag((slider.x0 + 20, y), (slider.x1 - 30, y))


def export(s: Session) -> None:
    """Open the Export header, click its last button; a new .ply file appears."""
    layout = s.layout()
    s.click(layout.sections[-1][0].center)
    if s.until(lambda img: kinds(img, -1, "buttons") > 0) is None:
        raise AssertionError("the Export header shows no buttons")
    row = s.layout().find(-1, "buttons", 0)
    before = set(s.tmp.rglob("*.ply"))
    s.click(((row.buttons[-1][0] + row.buttons[-1][1]) // 2, row.center[1]))
    deadline = time.monotonic() + 15
    while not set(s.tmp.rglob("*.ply")) - before:
        if time.monotonic() > deadline:
            raise AssertionError("export wrote no .ply file")
        time.sleep(0.5)


TOUR: list[tuple[str, Callable[[Session], None]]] = [
    ("pick_mesh", pick_mesh),
    *[(f"panel_{p}", visit(p)) for p in PANELS],
    ("curvature_widgets", curvature_widgets),
    ("click_vertex", click_vertex),
    ("type_vertex", type_vertex),
    ("spectral_drag_k", spectral_k),
    ("type_lambda", type_lambda),
    ("play_pause", play_pause),
    ("surfaces_widgets", surfaces_widgets),
    ("export", export),
]


def keep_shots(s: Session) -> None:
    target = os.environ.get("MESHLAP_WINDOW_SHOTS")
    if target:
        Path(target).mkdir(parents=True, exist_ok=True)
        for png in s.shots.glob("*.png"):
            shutil.copy2(png, Path(target) / png.name)


@pytest.mark.window
@pytest.mark.parametrize(
    ("size", "mesh"),
    [(SIZES[0], None), (SIZES[1], SECOND_MESH)],
    ids=["1280x720-default", "1920x1080-torus"],
)
def test_scripted_tour(x_tools, tmp_path, size, mesh):
    s = Session(size, mesh, tmp_path)
    try:
        assert s.app is not None
        title = s.app.title()
        assert title == "Polyscope" or title.startswith("meshlap"), title
        for name, action in TOUR:
            s.step(name, action)
    finally:
        keep_shots(s)
        s.close()
    assert not s.failures, "\n".join(s.failures)


KEYS = "space Right Left Up Down 1 2 3 4 5 f h r Tab Return BackSpace 0 period minus a x".split()


@pytest.mark.window
@pytest.mark.parametrize(
    ("size", "mesh"),
    [(SIZES[0], None), (SIZES[1], SECOND_MESH)],
    ids=["1280x720-default", "1920x1080-torus"],
)
def test_monkey(x_tools, tmp_path, size, mesh):
    """Seeded random clicks, drags and keys anywhere in the window; the viewer survives."""
    seconds = float(os.environ.get("MESHLAP_MONKEY_SECONDS", "30"))
    rng = np.random.default_rng(20261124 + size[0])
    s = Session(size, mesh, tmp_path)
    w, h = size
    log: list[str] = []
    try:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            r = rng.random()
            a = (int(rng.integers(0, w)), int(rng.integers(0, h)))
            if r < 0.6:
                log.append(f"click {a}")
                s.x.xdotool("mousemove", str(a[0]), str(a[1]))
                time.sleep(0.06)
                s.x.xdotool("click", "1")
            elif r < 0.8:
                b = (int(rng.integers(0, w)), int(rng.integers(0, h)))
                log.append(f"drag {a} -> {b}")
                s.drag(a, b, steps=4, pause=0.2)
            else:
                key = str(rng.choice(KEYS))
                log.append(f"key {key}")
                s.x.xdotool("key", key)
            time.sleep(0.1)
            if len(log) % 10 == 0 and s.problem():
                break
        s.screenshot("monkey_end")
        problem = s.problem()
    finally:
        keep_shots(s)
        s.close()
    assert problem is None, f"{problem}\nlast actions: {log[-8:]}"


# ------------------------------------------------------------------ the harness's own pieces
def xwd_bytes(rgb: np.ndarray, byte_order: int) -> bytes:
    """An X Window Dump of ``rgb`` as Xvfb writes it (32 bpp TrueColor, 0x00RRGGBB)."""
    h, w, _ = rgb.shape
    name = b"test\x00"
    header = 100 + len(name)
    fields = [header, 7, 2, 24, w, h, 0, byte_order, 32, byte_order, 32, 32, 4 * w + 8]
    fields += [4, 0xFF0000, 0x00FF00, 0x0000FF, 8, 256, 1, w, h, 0, 0, 0]
    pix = (rgb[..., 0].astype(np.uint32) << 16) | (rgb[..., 1].astype(np.uint32) << 8)
    pix |= rgb[..., 2].astype(np.uint32)
    rows = np.zeros((h, w + 2), dtype="<u4" if byte_order == 0 else ">u4")  # padded lines
    rows[:, :w] = pix
    return struct.pack(">25I", *fields) + name + bytes(12) + rows.tobytes()


@pytest.mark.parametrize("byte_order", [0, 1], ids=["lsb-first", "msb-first"])
def test_xwd_decoder_and_png_round_trip(tmp_path, byte_order):
    rgb = np.random.default_rng(3).integers(0, 256, size=(7, 5, 3), dtype=np.uint8)
    decoded = read_xwd(xwd_bytes(rgb, byte_order))
    np.testing.assert_array_equal(decoded, rgb)
    write_png(tmp_path / "x.png", decoded)
    assert (tmp_path / "x.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    np.testing.assert_array_equal(read_png(tmp_path / "x.png"), rgb)


def test_foreign_lines_keep_only_what_polyscope_did_not_write():
    err = "[polyscope] Backend: openGL3_glfw\nmeshlap: error: lam: must be > 0\n\n"
    assert foreign_lines(err) == ["meshlap: error: lam: must be > 0"]
