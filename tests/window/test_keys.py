"""Every documented key in the real window (issue 23): the keys of the **Keys:** item of
docs/window.md and of the Help window's table (:func:`meshlap_app.panels.help.shortcut_rows`,
the rows the Help pane draws), each pressed with xdotool in ``meshlap view`` under Xvfb at
1280×720, in the view its row names (a view's number from another view; F and R after the
camera was turned with a drag); each must change the picture. ``tests/app/test_keys.py``
checks the same keys through the widgets (which state each one changes).

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots (one after each key).
"""

from __future__ import annotations

import time
from types import SimpleNamespace

import pytest
from meshlap_app.registry import VIEWS

from tests.support.drivers.deform import drag_a_handle
from tests.support.imgui_screen import changed_fraction, parse
from tests.support.window_page import window_page_keys
from tests.support.window_session import WAIT, Session, keep_shots, scene_box, spectral
from tests.support.xwindow import missing_tools

XDOTOOL = {"right": "Right", "left": "Left", "space": "space"}
CHANGED = 5e-4  # fraction of the window's pixels a key must change (a caption: ~1e-3)


def documented_keys() -> list[tuple[str, str]]:
    """(key, view it acts in; "" for the host's own keys) of every key row of the Help
    window, the views' numbers one by one."""
    from meshlap_app.panels.help import shortcut_rows
    from meshlap_app.registry import REGISTRY

    panels = {spec.name: spec.panel_class() for spec in REGISTRY}
    out: list[tuple[str, str]] = []
    for key, what in shortcut_rows(SimpleNamespace(panels=panels)):
        if key in ("mouse", "drop"):
            continue  # gestures, driven by the tour
        head = what.split(":")[0]
        view = head if ":" in what and " " not in head else ""
        if key[0].isdigit() and "-" in key:
            lo, hi = key.split("-")
            out += [(str(i), "") for i in range(int(lo), int(hi) + 1)]
        else:
            out += [(k.strip().lower(), view) for k in key.split("/")]
    return out


def test_the_help_rows_hold_every_key_of_the_window_page():
    keys = {k for k, _ in documented_keys()}
    assert set(window_page_keys()) <= keys, set(window_page_keys()) - keys
    assert {"1", "5", "f", "r", "h", "space", "right", "left"} <= keys


def press_and_see(s: Session, key: str, what: str) -> str | None:
    """Press ``key`` on a steady picture; None when the picture changed, else the failure."""
    before = s.settled((0, 0, *s.size))
    s.key(XDOTOOL.get(key, key))
    try:
        s.until(lambda img: changed_fraction(before, img, (0, 0, *s.size)) > CHANGED, WAIT, what)
    except AssertionError as exc:
        return f"{key!r}: {exc}"
    return None


def turn_camera(s: Session) -> None:
    """Left-drag across the scene: the camera turns (F and R then have something to undo)."""
    layout = parse(s.settled((0, 0, *s.size)))
    x0, y0, x1, y1 = scene_box(s, layout)
    cy = (y0 + y1) // 2
    s.drag((x0 + (x1 - x0) // 3, cy), (x0 + 2 * (x1 - x0) // 3, cy + 40))


@pytest.mark.window
def test_every_documented_key_changes_the_window(tmp_path_factory):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    s = Session((1280, 720), None, tmp_path_factory.mktemp("keys"))
    failures: list[str] = []
    try:
        spectral(s)  # an eigenbasis, k > 1: → and ← have a k to change
        deform_ready = False
        keys = documented_keys()  # the deform view's in the order Y, Z, R: redo, undo, reset
        deform = [kv for kv in keys if kv[1] == "deform"]
        order = {"y": 0, "z": 1, "r": 2}
        deform.sort(key=lambda kv: order.get(kv[0], 3))
        keys = [kv for kv in keys if kv[1] != "deform"] + deform
        for key, view in keys:
            t0 = time.monotonic()
            if key.isdigit():
                other = 1 if key != "1" else 2
                s.goto(other, f"view {other}")
                problem = press_and_see(s, key, f"view {key} after pressing {key}")
                s.panel = int(key)
            elif view == "deform":  # a handle moved: Z undoes it, Y redoes it, R resets it
                if not deform_ready:
                    drag_a_handle(s)  # a handle, dragged and undone (Y has a move to redo)
                    deform_ready = True
                s.goto(VIEWS.index("deform") + 1, "Deform")
                if key == "r":  # Z left the rest shape: Y brings the move back for R to reset
                    s.key("y")
                    s.settled((0, 0, *s.size))
                problem = press_and_see(s, key, f"a change after {key} in the deform view")
            else:
                number = {"": 1, "spectral": 3, "smoothing": 4}.get(view, 1)
                s.goto(number, view or "curvature")
                if key in ("f", "r") and not view:
                    turn_camera(s)
                problem = press_and_see(s, key, f"a change after {key} in the {view} view")
                if key == "space":
                    s.key("space")  # pause again
            if problem:
                failures.append(problem)
            s.screenshot(f"key_{key}_{view or 'host'}")
            print(f"key {key} ({view or 'host'}): {time.monotonic() - t0:.1f} s")
            problem = s.problem()
            if problem:
                failures.append(f"{key!r}: {problem}")
                break
    finally:
        keep_shots(s)
        s.close()
    assert not failures, "\n".join(failures)
