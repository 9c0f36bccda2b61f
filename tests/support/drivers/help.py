"""The Help and window section's widgets: the help pane, polyscope's panels, the UI scale, the
shortcut keys, and the session file's *save* / *load*."""

from __future__ import annotations

from pathlib import Path

import polyscope as ps

from tests.support.widgets import drive, frames


def drive_help_widgets(viewer):
    help_panel = viewer.panels["help"]
    frames(viewer)
    before = help_panel.shown
    drive(viewer, "key h", True)
    frames(viewer)  # the header follows on the next frame
    assert help_panel.shown == (not before)
    drive(viewer, "polyscope's own panels", True)
    assert help_panel.polyscope_panels
    drive(viewer, "polyscope's own panels", False)
    drive(viewer, "UI scale", 1.5)
    assert viewer.state.ui_scale == 1.5 and viewer.ui.scale == 1.5
    drive(viewer, "UI scale", 10.0)
    assert viewer.state.ui_scale == 3.0  # clamped
    for bad in ("nan", -1.0, "1e309"):
        drive(viewer, "UI scale", bad)
        assert viewer.state.ui_scale == 3.0 and "UI scale" in viewer.state.errors["help"]
    drive(viewer, "UI scale", 1.0)
    drive(viewer, "key h", True)
    frames(viewer)
    assert help_panel.shown == before


def drive_shortcuts(viewer):
    from meshlap_app.registry import VIEW_KEYS, VIEWS

    for key, panel in zip(VIEW_KEYS, VIEWS, strict=False):
        drive(viewer, f"key {key}", True)
        assert viewer.state.panel == panel
    drive(viewer, "key 4", True)  # smoothing
    st = viewer.panels["smoothing"].state
    it0 = st.smoother.iteration
    drive(viewer, "key right", True, True)
    assert st.smoother.iteration == it0 + 2
    drive(viewer, "key space", True)
    assert st.playing
    drive(viewer, "key space", True)
    assert not st.playing
    drive(viewer, "key r", True)
    assert st.smoother.iteration == 0
    drive(viewer, "key 3", True)  # spectral: arrows move k once a basis exists
    spec = viewer.panels["spectral"].state
    spec.k_request = 12
    spec.start(viewer.state.mesh.V, viewer.state.mesh.F, background=False)
    frames(viewer)
    spec.set_k(5)
    drive(viewer, "key right", True)
    assert spec.k == 6
    drive(viewer, "key left", True, True)
    assert spec.k == 4
    drive(viewer, "key f", True)
    assert not viewer.reframe  # framed at the end of that frame
    drive(viewer, "key 1", True)
    drive(viewer, "key r", True)  # outside the smoothing panel: re-frame the camera


def tick(viewer, label=None, value=None):
    """One frame; ``label`` (a widget of the Help and window section, opened) gets ``value``."""
    if label is not None:
        viewer.ui.script(label, value)
        viewer.ui.script("Help and window (H)", True)
    ps.frame_tick()
    assert not viewer.ui.pending()
    internal = {k: m for k, m in viewer.state.errors.items() if "internal error" in m}
    assert not internal, internal


def drive_session_widgets(viewer, tmp_path) -> None:
    """Drive the session widgets (Help and window section) with good and bad values; the
    every-widget tour (``tests/app/test_viewer_widgets.py``) runs this too."""
    from meshlap_app import session

    tick(viewer)
    tick(viewer)  # a pending re-frame happens first
    before = session.capture(viewer)
    tick(viewer, "session file", str(tmp_path / "no-such-folder" / "s.json"))
    tick(viewer, "save session", True)
    assert "does not exist" in viewer.state.errors["help"]
    tick(viewer, "session file", "")  # empty: <mesh>.session.json in the export folder
    tick(viewer, "save session", True)
    saved = viewer.state.folder / f"{viewer.state.mesh.path.stem}.session.json"
    assert saved.is_file() and viewer.panels["help"].session.text == str(saved.resolve())
    assert "help" not in viewer.state.errors
    for bad in ("{", '{"format": "meshlap-session", "version": 3}', "[]"):
        (tmp_path / "bad.json").write_text(bad)
        tick(viewer, "session file", str(tmp_path / "bad.json"))
        tick(viewer, "load session", True)
        assert str(tmp_path / "bad.json") in viewer.state.errors["help"]  # red, in that section
        assert session.capture(viewer) == before  # nothing changed
    tick(viewer, "session file", str(saved))
    tick(viewer, "load session", True)
    assert "help" not in viewer.state.errors and session.capture(viewer).settings == before.settings


def drive_panel_help(viewer, tmp_path: Path) -> None:
    drive_help_widgets(viewer)
    drive_shortcuts(viewer)
    drive_session_widgets(viewer, tmp_path)
