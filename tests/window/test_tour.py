"""The viewer in a real window: ``meshlap view`` under Xvfb, driven with xdotool like a user.

One viewer per window size (1280×720 on the default mesh, 1920×1080 on ``assets/torus.obj``)
serves two tests, in this order:

- ``test_scripted_tour``: pick a mesh from the list, then every panel through its shortcut (1–5)
  with its widgets (curvature field and side by side, click a vertex and type one, compute the
  eigenbasis and drag k, open another mesh and compute its eigenbasis, type λ and press Enter,
  space to play and to pause, a surface and its u slider), export what is shown, the Help pane
  (H), and at 1280×720 a recording of the normal section turning (record, turn, stop: a GIF of
  several frames), then the Deform view (a handle clicked and dragged: the shape changes on
  screen; Z undoes it) and the Flatten view (the checkerboard, the layout, another map). After
  each step the test checks what a user sees on a screenshot: the subject left of meshlap's
  panel and not running behind it, the second mesh (side by side, reconstruction, smoothed
  copy, layout) beside it, λ applied on Enter and not before, the export message, the
  window's title naming the mesh shown, and that the process is alive with nothing on stderr
  but polyscope's own ``[polyscope]`` lines. A failing step is recorded (the
  viewer is restarted if it died) and the tour goes on, so one run reports every failing step.
- ``test_monkey``: ``MESHLAP_MONKEY_ACTIONS`` (default 40, about 20 s when idle) random clicks,
  drags and keys anywhere, drawn from ``MESHLAP_MONKEY_SEED``; the viewer survives. A failure
  names the seed and the action's index, and the command that replays exactly those actions.

Widgets are found on each screenshot by colour and layout (:mod:`tests.support.imgui_screen`); the
order of widgets inside each panel is stated once, in the step functions below (the harness, with
the Spectral step the keys test shares, is :mod:`tests.support.window_session`). Every wait is for
a visible outcome or for frames the viewer drew after an input event (:meth:`xwindow.App.drawn`,
counted with X DAMAGE), and bounded (a loaded machine draws few frames per second; a timeout
fails with what was awaited): no step sleeps a guessed time. The mouse rests in the scene's
bottom-left corner between actions, so no tooltip covers a widget on a screenshot.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots (``docs/img/window/`` holds the
1280×720 ones).
"""

from __future__ import annotations

import os
import struct
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from tests.support.imgui_screen import Layout, changed_fraction, parse, subject_point, subjects
from tests.support.window_session import (
    STILL,
    WAIT,
    Session,
    foreign_lines,
    keep_shots,
    panel_box,
    pixels,
    scene_box,
    scroll_to_end,
    scroll_to_top,
    section_box,
    spectral,
)
from tests.support.xwindow import missing_tools, read_png, read_xwd, write_png

ROOT = Path(__file__).resolve().parents[2]
SIZES = ((1280, 720), (1920, 1080))
SECOND_MESH = ROOT / "assets" / "torus.obj"
MESH_LIST = ("bumpy.obj", "cube.obj", "grid.obj", "icosphere.obj", "torus.obj")  # assets/, sorted
TITLE = "meshlap — "  # the window title: meshlap — <file>


# ------------------------------------------------------------------ steps
def opened(s: Session) -> None:
    """The window as it opens: titled after the file, the mesh framed left of the panel."""
    assert s.app is not None
    title = s.app.title()
    if not title.startswith(TITLE):
        raise AssertionError(f"window title {title!r}, want 'meshlap — <file>'")
    s.subject_ok(parse(s.img), 1, "on open")


def pick_mesh(s: Session) -> None:
    """The mesh list (first combo of the Mesh section): the torus, or with the torus open,
    bumpy; the Mesh section describes the new mesh, the scene shows it and the window's
    title names it (polyscope sets a title only when it creates the window)."""
    entry = 0 if s.mesh == SECOND_MESH else MESH_LIST.index("torus.obj")
    before = s.screenshot()
    mesh_box = section_box(parse(before), 0)
    s.choose(0, 0, entry)
    layout = parse(s.settled((0, 0, *s.size)))
    if changed_fraction(before, s.img, scene_box(s, layout)) < 0.02:
        raise AssertionError("the picked mesh did not replace the shown one")
    if changed_fraction(before, s.img, mesh_box) < 0.002:
        raise AssertionError("the Mesh section still describes the previous mesh")
    s.subject_ok(layout, 1, "the picked mesh")
    assert s.app is not None
    if s.app.title() != TITLE + MESH_LIST[entry]:
        raise AssertionError(f"window title {s.app.title()!r} after picking {MESH_LIST[entry]}")


def curvature(s: Session) -> None:
    """Key 1; field combo → gaussian (3rd entry); side by side on: a second mesh beside the
    first and a "second field" combo; drag clip %."""
    s.goto(1, "Curvature")
    s.choose(1, 0, 2)
    layout = s.layout()
    n = sum(it.kind == "combo" for it in layout.sections[1])
    s.click(layout.find(1, "checkbox", 0).center)
    s.until(
        lambda img: (
            len(subjects(img, parse(img))) >= 2
            and sum(it.kind == "combo" for it in parse(img).sections[1]) > n
        ),
        WAIT,
        "second mesh and second-field combo after 'side by side'",
    )
    layout = parse(s.settled((0, 0, *s.size)))
    s.subject_ok(layout, 2, "side by side")
    slider = layout.find(1, "slider", 0)
    y = slider.center[1]
    s.drag((slider.x0 + 10, y), (slider.x0 + (slider.x1 - slider.x0) // 2, y))
    s.settled((0, 0, *s.size))


def onering(s: Session) -> None:
    """Key 2; click the mesh: the panel lists the vertex and the camera turns to it; then type
    12 into the "vertex" field and press Enter."""
    layout = s.goto(2, "One-ring")
    s.subject_ok(layout, 1, "one-ring panel")
    point = subject_point(s.img, layout)
    if point is None:
        raise AssertionError("no mesh to click left of the panel")
    before = s.img
    s.click(point)
    panel = panel_box(s, layout)
    s.until(
        lambda img: (
            pixels(before, img, panel) > 200 and pixels(before, img, scene_box(s, layout)) > 200
        ),
        WAIT,
        f"vertex in the panel and its one-ring drawn after a click at {point}",
    )
    layout = parse(s.settled((0, 0, *s.size)))
    field = layout.find(1, "input", 0)
    s.click(field.center)  # returns once the viewer read the click: the field has the keys
    s.key("ctrl+a", "1", "2")
    typed = s.settled((0, 0, *s.size))
    s.key("Return")
    # the lines under the field ("vertex 12: ...", the inspector's tables), not the typed
    # digits: selecting a vertex may take the viewer a second or more to draw
    below = (layout.left, field.y1 + 4, layout.right, s.size[1])
    s.until(
        lambda img: pixels(typed, img, below) > 100,
        WAIT,
        "vertex 12 in the panel after typing 12 and Enter",
    )
    s.settled((0, 0, *s.size))


def second_mesh_spectral(s: Session) -> None:
    """Key 3 with the eigenbasis of the picked mesh shown; open another mesh by typing its
    path (bumpy after the torus, the torus after bumpy) and Enter, then compute its
    eigenbasis: the reconstruction is shown beside the new mesh (issue 23: it came back
    registered but hidden) and dragging k changes it (the steps of :func:`spectral`)."""
    layout = s.goto(3, "Spectral")
    name = "bumpy.obj" if s.mesh != SECOND_MESH else "torus.obj"
    before = s.img
    s.click(layout.find(0, "input", 0).center)  # the Mesh section's path field
    s.x.xdotool("type", "--delay", "30", str(ROOT / "assets" / name))
    s.drawn()
    s.key("Return")
    s.until(
        lambda img: changed_fraction(before, img, scene_box(s, layout)) > 0.02,
        30,
        f"{name} in place of the shown mesh",
    )
    s.settled((0, 0, *s.size))
    assert s.app is not None
    if s.app.title() != TITLE + name:
        raise AssertionError(f"window title {s.app.title()!r} after opening {name}")
    spectral(s, to=2 / 3)


def smoothing(s: Session) -> None:
    """Key 4; type λ = 0.25 in the third field: nothing applies until Enter (the keys 2 and 5
    typed go to the field, not to the panel shortcuts), Enter changes the g(μ) plot; space
    plays (the smoothed copy moves), space pauses (it stops)."""
    s.goto(4, "Smoothing")

    def both_shown(img: np.ndarray) -> bool:  # the stepper is built as a job on a first visit
        try:
            return len(subjects(img, parse(img))) >= 2
        except LookupError:
            return False

    s.until(both_shown, 30, "the input and its smoothed copy once the stepper is built")
    layout = parse(s.settled((0, 0, *s.size)))
    s.subject_ok(layout, 2, "input and smoothed copy")
    plot = layout.find(1, "plot", 0)
    plot_box = (plot.x0, plot.y0, plot.x1, plot.y1)
    before = s.img
    s.click(layout.find(1, "input", 0).center)  # the field has the keys once this returns
    s.key("ctrl+a", "0", "period", "2", "5")
    typed = s.settled((0, 0, *s.size))
    scene = scene_box(s, layout)
    if pixels(before, typed, plot_box) + pixels(before, typed, scene) > 10:
        raise AssertionError("λ applied before Enter (g(μ) or the caption changed while typing)")
    if len(parse(typed).sections[1]) != len(layout.sections[1]):
        raise AssertionError("typing 0.25 into λ changed the panel (a shortcut fired?)")
    s.key("Return")
    s.until(lambda img: pixels(typed, img, scene) > 20, WAIT, "new caption (λ = 0.25) after Enter")
    box = scene_box(s, layout)
    row = layout.find(1, "buttons", 0)  # step / play / reset: "play" reads "pause" while playing
    row_box = (row.x0, row.y0, min(row.x1 + 60, layout.right), row.y1)
    a = s.settled(box)
    s.key("space")
    playing = s.until(
        lambda img: changed_fraction(a, img, row_box) > 0.01, WAIT, "'pause' on the play button"
    )
    # a loaded machine draws a playing frame (one step) in up to ~2 s: give the copy time
    s.until(lambda img: changed_fraction(a, img, box) > 0.002, 30, "smoothed copy moving (space)")
    s.key("space")
    # a playing frame may take longer than a steady-picture check (one smoothing step moves
    # few pixels): first the button says the pause took effect, then the copy must be still
    s.until(
        lambda img: changed_fraction(playing, img, row_box) > 0.01,
        WAIT,
        "'play' on the button again after space",
    )
    c = s.settled(box)
    s.drawn(6)  # playing, each of these frames would step the copy
    if changed_fraction(c, s.screenshot(), box) > STILL:
        raise AssertionError("space again: the smoothed copy still moves")
    s.subject_ok(parse(s.img), 2, "after play/pause")


def surfaces(s: Session) -> None:
    """Key 5; surface combo → 2nd entry; drag u (the first slider)."""
    s.goto(5, "Surfaces")
    before = s.img
    s.choose(1, 0, 1)
    layout = parse(s.settled((0, 0, *s.size)))
    if changed_fraction(before, s.img, scene_box(s, layout)) < 0.02:
        raise AssertionError("the chosen surface did not replace the shown one")
    s.subject_ok(layout, 1, "the surface")
    slider = layout.find(1, "slider", 0)
    before, y = s.img, slider.center[1]
    s.drag((slider.x0 + 20, y), (slider.x1 - 30, y))
    s.until(
        lambda img: changed_fraction(before, img, section_box(layout, 1)) > 0.002,
        WAIT,
        "new (u, v) figures after dragging u",
    )
    s.settled((0, 0, *s.size))


def export(s: Session) -> None:
    """Open the Export header (the one before Help), click "export what is shown" (its last
    button): a .ply file appears and the panel says where it wrote. The panel is scrolled to
    its end first (the Surfaces panel with its record header reaches below 720 pixels)."""
    layout = scroll_to_end(s)
    s.click(layout.sections[-2][0].center)
    s.settled((0, 0, *s.size))
    for _ in range(12):  # the panel may now be taller than the window: scroll it
        if any(it.kind == "buttons" for it in parse(s.img).sections[-2]):
            break
        s.x.xdotool("mousemove", str(layout.left + 20), str(s.size[1] // 2))
        s.x.xdotool("click", "--repeat", "3", "5")
        s.park()
        s.settled((0, 0, *s.size))
    else:
        raise AssertionError("no buttons under the Export header, even scrolled down")
    layout = parse(s.settled((0, 0, *s.size)))
    row = layout.find(-2, "buttons", 0)
    before_files, before = set(s.tmp.rglob("*.ply")), s.img
    below = (layout.left, row.y1 + 2, layout.right, min(row.y1 + 60, layout.bottom))
    s.click(((row.buttons[-1][0] + row.buttons[-1][1]) // 2, row.center[1]))
    s.until(
        lambda img: (
            bool(set(s.tmp.rglob("*.ply")) - before_files)
            and changed_fraction(before, img, below) > 0.005
        ),
        15,
        "new .ply file and the 'wrote ...' message under the buttons",
    )
    s.settled((0, 0, *s.size))


def help_pane(s: Session) -> None:
    """Back to the one-ring panel, Export closed; H opens the Help pane at the panel's end
    (scrolled to: the inspector makes the panel tall): its session file field, save / load
    buttons, check box and UI-scale slider appear."""
    s.goto(2, "One-ring")
    layout = scroll_to_end(s)
    if any(it.kind == "buttons" for it in layout.sections[-2]):
        s.click(layout.sections[-2][0].center)
        s.until(
            lambda img: not any(it.kind == "buttons" for it in parse(img).sections[-2]),
            WAIT,
            "closed Export section",
        )
    before, box = s.img, (layout.left, 0, layout.right, s.size[1])
    s.key("h")
    s.until(lambda img: changed_fraction(before, img, box) > 0.001, WAIT, "the panel grown after H")
    scroll_to_end(s)

    def shown(img: np.ndarray) -> bool:
        kinds = {it.kind for it in parse(img).sections[-1]}
        return {"input", "buttons"} <= kinds and bool(kinds & {"checkbox", "slider"})

    s.until(shown, WAIT, "the Help pane's widgets after H (session file, buttons, UI scale)")
    s.settled((0, 0, *s.size))
    s.key("h")  # closed again, the panel scrolled back to its top for the next steps
    s.until(lambda img: not shown(img), WAIT, "the Help pane closed after H")
    scroll_to_top(s)


def surfaces_section(layout: Layout) -> int:
    """Index of the Surfaces section on screen (the one holding the k_n(θ) plot); the record
    header follows it."""
    for i, sec in enumerate(layout.sections):
        if any(it.kind == "plot" for it in sec):
            return i
    raise LookupError("the Surfaces section's plot is not on screen")


def record_buttons(img: np.ndarray) -> bool:
    """The opened record header's button row is on screen."""
    try:
        layout = parse(img)
        return bool(layout.find(surfaces_section(layout) + 1, "buttons", 0))
    except LookupError:
        return False


def record_turn(s: Session) -> None:
    """1280x720 only. Key 5, Help closed; open the *record* header (the section after the
    Surfaces section's plot), press record, press *turn* (right of the θ slider, the Surfaces
    section's last slider), let θ turn about a second, press stop (record's place): a GIF with
    more than one frame appears in the viewer's folder."""
    if s.size != SIZES[0]:
        return
    from PIL import Image

    s.goto(5, "Surfaces")
    layout = scroll_to_end(s)
    if len(layout.sections[-1]) > 1:  # the Help pane is open: H closes it
        s.key("h")
        s.until(lambda img: len(parse(img).sections[-1]) == 1, WAIT, "Help closed after H")
        layout = scroll_to_end(s)
    if not record_buttons(s.img):
        s.click(layout.sections[surfaces_section(layout) + 1][0].center)
        s.until(record_buttons, WAIT, "the record button under the opened record header")
    layout = parse(s.settled((0, 0, *s.size)))
    i = surfaces_section(layout)
    row = layout.find(i + 1, "buttons", 0)
    button = ((row.buttons[0][0] + row.buttons[0][1]) // 2, row.center[1])
    row_box = (layout.left, row.y0, layout.right, row.y1)
    before, gifs = s.img, set(s.tmp.rglob("*.gif"))
    s.click(button)
    s.until(lambda img: pixels(before, img, row_box) > 20, WAIT, "'stop' in record's place")
    theta = layout.find(i, "slider", -1)
    if not theta.buttons:
        raise AssertionError("no turn button right of the θ slider")
    scene = scene_box(s, layout)
    before = s.screenshot()
    s.click(((theta.buttons[0][0] + theta.buttons[0][1]) // 2, theta.center[1]))
    s.until(lambda img: pixels(before, img, scene) > 50, 15, "the normal section turning")
    # θ turns on each frame, and each frame with a new θ is recorded (slowly: a loaded
    # machine may take seconds per recorded frame): two more frames after the first turn seen
    s.drawn(2)
    s.click(button)  # stop
    s.until(lambda img: bool(set(s.tmp.rglob("*.gif")) - gifs), 20, "the recorded GIF")
    (gif,) = set(s.tmp.rglob("*.gif")) - gifs
    frames = Image.open(gif).n_frames
    if frames < 2:
        raise AssertionError(f"{gif.name} holds {frames} frame(s), want more than 1")
    s.drawn()  # the section goes on turning after stop: no steady picture to wait for


def deform(s: Session) -> None:
    """The Deform view: a handle clicked and dragged up, the shape read from the screen, Z
    undoing it (the step lives with the view's own window test)."""
    from tests.support.drivers.deform import drag_a_handle

    drag_a_handle(s)


def flatten(s: Session) -> None:
    """The Flatten view: the checkerboard, the layout and the distortion copy, then LSCM
    (the step lives with the view's widget driver)."""
    from tests.support.drivers.flatten import checkerboard_step

    checkerboard_step(s)


TOUR: list[tuple[str, Callable[[Session], None]]] = [
    ("window", opened),
    ("pick_mesh", pick_mesh),
    ("curvature", curvature),
    ("onering", onering),
    ("spectral", spectral),
    ("second_mesh_spectral", second_mesh_spectral),
    ("smoothing", smoothing),
    ("surfaces", surfaces),
    ("export", export),
    ("help", help_pane),
    ("record", record_turn),
    ("deform", deform),
    ("flatten", flatten),
]


@pytest.fixture(
    scope="module",
    params=[(SIZES[0], None), (SIZES[1], SECOND_MESH)],
    ids=["1280x720-default", "1920x1080-torus"],
)
def session(request, tmp_path_factory) -> Iterator[Session]:
    """One viewer per size, shared by the tour and then the monkey."""
    missing = missing_tools()
    if missing:
        pytest.skip(
            f"real-window tests need {', '.join(missing)} (apt-get install xvfb xdotool "
            "x11-apps; .ci/run installs them)"
        )
    size, mesh = request.param
    t0 = time.monotonic()
    s = Session(size, mesh, tmp_path_factory.mktemp(f"window{size[0]}"))
    print(f"{size[0]}x{size[1]} start: {time.monotonic() - t0:.1f} s")
    try:
        yield s
    finally:
        keep_shots(s)
        s.close()


@pytest.mark.window
def test_scripted_tour(session):
    for name, action in TOUR:
        session.step(name, action)
    assert not session.failures, "\n".join(session.failures)


KEYS = "space Right Left Up Down 1 2 3 4 5 f h r Tab Return BackSpace 0 period minus a x".split()
# MESHLAP_MONKEY_ACTIONS overrides. Each action waits for the viewer to have drawn its outcome:
# a click on the scene (a pick) costs the viewer ~0.5 s when idle but seconds on a loaded
# machine (40 actions took 104 s at load 6.5 on 2 cores); 40 is about the old 20 s when idle
MONKEY_ACTIONS = 40
MONKEY_SEED = 20261124  # + the window's width (MESHLAP_MONKEY_SEED overrides, as printed)

Action = tuple[str, tuple[int, int], tuple[int, int], str]  # kind, a, b, key


def monkey_actions(seed: int, n: int, size: tuple[int, int]) -> list[Action]:
    """``n`` random actions in a ``size`` window, a function of ``seed`` alone: 60 % clicks at
    ``a``, 20 % drags from ``a`` to ``b``, 20 % key presses (a key of :data:`KEYS`)."""
    rng = np.random.default_rng(seed)
    w, h = size
    actions: list[Action] = []
    for _ in range(n):
        r = rng.random()
        a = (int(rng.integers(0, w)), int(rng.integers(0, h)))
        if r < 0.6:
            actions.append(("click", a, a, ""))
        elif r < 0.8:
            b = (int(rng.integers(0, w)), int(rng.integers(0, h)))
            actions.append(("drag", a, b, ""))
        else:
            actions.append(("key", a, a, str(rng.choice(KEYS))))
    return actions


def act(s: Session, action: Action) -> None:
    """Do one monkey action and return once the viewer drew the frames after it.

    The events of a click (move, press, release) go in one ``xdotool`` call: ImGui's input
    queue spreads a move and a press that arrive together over two frames, so nothing between
    them needs a wait. A drag waits once with the button down (the moves read), then after
    the release.
    """
    kind, a, b, key = action
    x = s.x.xdotool
    if kind == "click":
        x("mousemove", str(a[0]), str(a[1]), "click", "1")
    elif kind == "drag":
        moves: list[str] = []
        for t in (0.25, 0.5, 0.75, 1.0):
            moves += [
                "mousemove",
                *(str(round(p + t * (q - p))) for p, q in zip(a, b, strict=True)),
            ]
        x("mousemove", str(a[0]), str(a[1]), "mousedown", "1", *moves)
        s.drawn()
        x("mouseup", "1")
    else:
        x("key", key)
    s.drawn()


def test_monkey_actions_replay_from_the_seed():
    one, two = monkey_actions(7, 50, (640, 480)), monkey_actions(7, 80, (640, 480))
    assert one == two[:50] and one != monkey_actions(8, 50, (640, 480))
    assert {kind for kind, *_ in two} == {"click", "drag", "key"}
    assert all(0 <= a[0] < 640 and 0 <= b[1] < 480 for _, a, b, _ in two)


@pytest.mark.window
def test_monkey(session, request):
    """Seeded random clicks, drags and keys anywhere in the window; the viewer survives each
    (it draws the frames after every action and writes nothing but polyscope's lines)."""
    s = session
    if s.app is None or not s.app.alive():
        s.start()
    w, h = s.size
    n = int(os.environ.get("MESHLAP_MONKEY_ACTIONS", str(MONKEY_ACTIONS)))
    seed = int(os.environ.get("MESHLAP_MONKEY_SEED", str(MONKEY_SEED + w)))
    actions = monkey_actions(seed, n, s.size)
    t0 = time.monotonic()
    for i, action in enumerate(actions):
        try:
            act(s, action)
            problem = s.problem()
        except AssertionError as exc:
            problem = s.problem() or str(exc)
        if problem:
            s.screenshot("monkey_fail")
            replay = (
                f"MESHLAP_MONKEY_SEED={seed} MESHLAP_MONKEY_ACTIONS={i + 1} "
                f"pytest tests/window/test_tour.py -k '{request.node.callspec.id}'"
            )
            pytest.fail(
                f"monkey action {i} of {n} (seed {seed}, {w}x{h}): {action}: {problem}\n"
                f"the actions before it: {actions[max(0, i - 8) : i]}\nreplay: {replay}"
            )
    print(f"{w}x{h} monkey: {n} actions (seed {seed}) in {time.monotonic() - t0:.1f} s")
    s.screenshot("monkey_end")
    assert s.problem() is None


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
