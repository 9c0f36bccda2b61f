"""The real window as it opens (issue 23): ``meshlap view`` under Xvfb at 1280×720 and
1920×1080, the window left where the viewer put it (no ``xdotool windowmove``): the whole
window on the screen (polyscope opened it at (20, 20), cut at the edge of a 1280×720 screen),
meshlap's panel whole inside it, and the title naming the mesh shown. The tour
(``tests/window/test_tour.py``) checks that the title follows a mesh picked later.

Set ``MESHLAP_WINDOW_SHOTS=<folder>`` to keep the screenshots.
"""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from tests.support.imgui_screen import parse, subjects
from tests.support.window_session import meshlap_command
from tests.support.xwindow import App, XServer, missing_tools, write_png

SIZES = ((1280, 720), (1920, 1080))


def keep(img: np.ndarray, tmp: Path, name: str) -> None:
    write_png(tmp / name, img)
    target = os.environ.get("MESHLAP_WINDOW_SHOTS")
    if target:
        Path(target).mkdir(parents=True, exist_ok=True)
        shutil.copy2(tmp / name, Path(target) / name)


def drawn_panel(img: np.ndarray) -> bool:
    """meshlap's panel with its sections and a mesh left of it."""
    try:
        layout = parse(img)
    except LookupError:
        return False
    return len(layout.sections) >= 3 and bool(subjects(img, layout))


@pytest.mark.window
@pytest.mark.parametrize("size", SIZES, ids=[f"{w}x{h}" for w, h in SIZES])
def test_the_window_opens_whole_on_the_screen_titled_after_its_mesh(size, tmp_path):
    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    sw, sh = size
    x = XServer(sw, sh).start()
    app = App(x, meshlap_command(), cwd=tmp_path).start(title="meshlap")
    try:
        deadline = time.monotonic() + 60
        while not drawn_panel(img := x.screenshot()):
            assert app.alive(), app.stderr()
            assert time.monotonic() < deadline, "no panel and mesh in 60 s"
            time.sleep(0.2)
        keep(img, tmp_path, f"{sw}x{sh}_open_default_size.png")
        gx, gy, gw, gh = app.geometry()
        assert gx >= 0 and gy >= 0, (gx, gy)
        assert gx + gw <= sw and gy + gh <= sh, f"window {(gx, gy, gw, gh)} on a {size} screen"
        assert gw >= min(1280, sw) * 0.9 and gh >= min(720, sh) * 0.9  # not shrunk for nothing
        layout = parse(img)
        # the panel ends inside the window, and the window is on the screen: no part cut
        assert gx <= layout.left and layout.right <= gx + gw
        assert app.title() == "meshlap — bumpy.obj"
        assert [ln for ln in app.stderr().splitlines() if not ln.startswith("[polyscope]")] == []
    finally:
        app.stop()
        x.stop()
