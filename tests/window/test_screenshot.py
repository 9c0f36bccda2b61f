"""Export → *screenshot* in a real window (``meshlap view`` under Xvfb, driven with xdotool as in
``tests/test_window.py``), in every view of the registry.

Inside ``ps.show()`` polyscope refuses a picture with its UI ("Screenshot with includeUI=true is
not supported within show()", then a red "cannot reshape array of size 0") and no file was
written. The button now writes the 3D view as the window shows it: the part left of meshlap's
panel at the window's height, with its colour bars and captions. Here, in each view: its number
key, the Export header opened (the panel scrolled to its end), *screenshot*: a PNG appears in the
folder, named after the mesh and the view, and it is the screen's own pixels left of the panel.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.support.imgui_screen import parse
from tests.support.window_session import (
    WAIT,
    Session,
    keep_shots,
    scroll_to_end,
    scroll_to_top,
)
from tests.support.xwindow import missing_tools

SIZE = (1280, 720)


def read_rgb(path: Path) -> np.ndarray:
    """A PNG as ``(h, w, 3) uint8`` (Pillow: the viewer writes RGBA through matplotlib)."""
    from PIL import Image

    with Image.open(path) as img:
        return np.asarray(img.convert("RGB"))


def export_buttons(s: Session):
    """The Export section's button row (screenshot, export what is shown), the header opened
    and the panel scrolled so that the row is on screen."""
    layout = scroll_to_end(s)
    if not any(it.kind == "buttons" for it in layout.sections[-2]):
        s.click(layout.sections[-2][0].center)  # the Export header (Help is the last one)
        s.settled((0, 0, *s.size))
        layout = scroll_to_end(s)
    return layout.find(-2, "buttons", 0)


@pytest.mark.window
def test_screenshot_writes_the_view_as_on_screen_in_every_view(tmp_path_factory):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    from meshlap_app.registry import VIEWS

    s = Session(SIZE, None, tmp_path_factory.mktemp("screenshot"))
    problems: list[str] = []
    try:
        for number, view in enumerate(VIEWS, start=1):
            scroll_to_top(s)  # (the last view's Export row was scrolled to)
            s.goto(number, view)
            row = export_buttons(s)
            folder = s.tmp / f"run{len(list(s.tmp.glob('run*'))) - 1}"  # the viewer's cwd
            target = folder / f"bumpy_{view}.png"
            target.unlink(missing_ok=True)
            s.click(((row.buttons[0][0] + row.buttons[0][1]) // 2, row.center[1]))
            try:
                s.until(lambda img, t=target: t.is_file(), WAIT, f"{target.name} written")
            except AssertionError as exc:
                problems.append(f"{view}: {exc}")
                continue
            screen = s.settled((0, 0, *s.size))
            s.screenshot(f"screenshot_{view}")
            shot = read_rgb(target)
            layout = parse(screen)
            h, w = shot.shape[:2]
            if h != SIZE[1] or not SIZE[0] // 3 <= w <= layout.left:
                problems.append(f"{view}: {w}x{h}, want the window's height and the view's width")
                continue
            differ = np.abs(shot.astype(int) - screen[:h, :w].astype(int)).max(axis=2) > 24
            if differ.mean() > 0.002:  # the same pixels as on screen (a caret may blink)
                problems.append(f"{view}: {differ.mean():.2%} of the picture is not the screen's")
            if np.ptp(shot.reshape(-1, 3), axis=0).max() < 60:
                problems.append(f"{view}: the picture is blank")
        assert s.problem() is None, s.problem()
        assert not problems, "\n".join(problems)
    finally:
        keep_shots(s)
        s.close()
