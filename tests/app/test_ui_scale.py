"""The UI scale: ``meshlap view --ui-scale`` wins over a session's, and a typed scale keeps
meshlap's panel within half the window (a bad value refused, nothing changed; an out-of-range
one clamped)."""

from __future__ import annotations

import pytest

ps = pytest.importorskip("polyscope")


from tests.support.widgets import drive, frames  # noqa: E402


def test_view_accepts_ui_scale_with_a_session(viewer, tmp_path, sphere, monkeypatch):
    import meshlap_app.viewer as viewer_module
    from meshlap_app.state.session import Session, write_session

    from meshlap_core.cli import main

    path = write_session(tmp_path / "s.json", Session(mesh=sphere, panel="curvature"))
    seen: dict = {}

    def show() -> None:  # the window's loop: read what the viewer was given instead
        seen["ok"] = True

    monkeypatch.setattr(viewer_module, "init_polyscope", lambda backend: None)
    monkeypatch.setattr(viewer_module, "run_frames", show)
    applied = []
    real = viewer_module.Viewer.set_ui_scale
    monkeypatch.setattr(
        viewer_module.Viewer, "set_ui_scale", lambda v, s: (applied.append(s), real(v, s))
    )
    assert main(["view", "--ui-scale", "2", "--session", str(path)]) == 0
    assert seen["ok"] and applied[-1] == 2.0  # the typed scale wins over the session's


def test_ui_scale_keeps_the_panel_within_half_the_window(viewer):
    ps.set_window_size(1280, 720)  # another module's test may have left another size
    frames(viewer, 1)
    w = ps.get_window_size()[0]
    help_header = "Help and window (H)"

    def set_scale(value) -> None:
        viewer.ui.script(help_header, True)
        drive(viewer, "UI scale", value)

    set_scale(1.0)
    assert ps.get_right_gui_pane_width() * 1.0 <= w / 2 + 1
    before = (viewer.state.ui_scale, ps.get_right_gui_pane_width())
    for refused in ("nan", "-1", "1e309"):
        set_scale(refused)
        assert "UI scale" in viewer.state.errors["help"]
        assert (viewer.state.ui_scale, ps.get_right_gui_pane_width()) == before  # nothing changed
    set_scale("1e308")  # a double, out of range: clamped to the largest scale, no error
    assert viewer.state.ui_scale == 3.0 and "help" not in viewer.state.errors
    assert ps.get_right_gui_pane_width() * viewer.state.ui_scale <= w / 2 + 1
    set_scale(1.0)
    assert ps.get_right_gui_pane_width() == 500
