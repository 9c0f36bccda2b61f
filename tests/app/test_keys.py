"""Every documented key does something: the **Keys:** item of the window's page (docs/window.md)
and the Help window's rows agree, and each key, pressed in a view where it acts, changes what is
shown (the real keys in a real window: ``tests/window/test_keys.py``)."""

from __future__ import annotations

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.viewer import Viewer  # noqa: E402

from tests.support.drivers.deform import click as deform_click  # noqa: E402
from tests.support.drivers.deform import settle as deform_settle  # noqa: E402
from tests.support.widgets import compute_basis, drive, frames  # noqa: E402
from tests.support.window_page import window_page_keys  # noqa: E402

# where a key can act (the panel named in its help row, else this view)
DEFAULT_VIEW = "onering"


def help_keys(viewer: Viewer) -> list[tuple[str, str]]:
    """(key, panel it belongs to) for every key row of the Help window."""
    from meshlap_app.panels.help import shortcut_rows

    out = []
    for key, what in shortcut_rows(viewer):
        if key in ("mouse", "drop"):
            continue  # gestures: driven by their own tests
        panel = what.split(":")[0] if ":" in what and " " not in what.split(":")[0] else ""
        if "-" in key and key[0].isdigit():
            lo, hi = key.split("-")
            out += [(str(i), "") for i in range(int(lo), int(hi) + 1)]
        else:
            out += [(k.strip().lower(), panel) for k in key.split("/")]
    return out


def snapshot(viewer: Viewer) -> tuple:
    sm, sp = viewer.panels["smoothing"].state, viewer.panels["spectral"].state
    help_panel = viewer.panels["help"]
    camera = np.round(np.asarray(ps.get_camera_view_matrix()), 6).tobytes()
    it = sm.smoother.iteration if sm.smoother is not None else None
    moves = repr(viewer.panels["deform"].state.moves)  # undo, redo, reset of a deformation
    return (viewer.state.panel, help_panel.shown, sm.playing, it, sp.k, camera, moves)


def test_every_documented_key_does_something(viewer):
    keys = help_keys(viewer)
    documented = {k for k, _ in keys}
    missing = set(window_page_keys()) - documented
    assert not missing, f"keys in docs/window.md but not in the Help window: {missing}"
    compute_basis(viewer)
    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)
    viewer.set_panel("smoothing")
    drive(viewer, "noise alpha", 0.01)
    viewer.set_panel("deform")  # a handle turned: something to undo, redo and reset
    frames(viewer)
    deform_click(viewer, 7)
    deform_settle(viewer)
    drive(viewer, "turn (deg)", 30.0)
    deform_settle(viewer)
    failures = []
    for key, panel in keys:
        view = panel or DEFAULT_VIEW
        if key.isdigit():
            view = "curvature" if key != "1" else "spectral"  # away from the key's own view
        viewer.set_panel(view)
        frames(viewer, 2)
        ps.look_at((3.0, 1.0, 2.0), (0.0, 0.0, 0.0))  # a camera F and R must change
        before = snapshot(viewer)
        viewer.ui.script(f"key {key}", True)
        frames(viewer, 2)
        if snapshot(viewer) == before:
            failures.append(f"{key!r} in the {view} view did nothing")
        if key == "space" and viewer.panels["smoothing"].state.playing:
            viewer.ui.script("key space", True)
            frames(viewer)
    assert not failures, failures
    # R is not F in the one-ring: F frames the ring, R the whole mesh
    viewer.set_panel("onering")
    frames(viewer)
    cams = []
    for key in ("f", "r"):
        viewer.ui.script(f"key {key}", True)
        frames(viewer, 2)
        cams.append(np.asarray(ps.get_camera_view_matrix()))
    assert not np.allclose(cams[0], cams[1]), "R did the same as F"
