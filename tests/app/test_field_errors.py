"""A refused typed value: its error sits under its field and quotes the text typed; it goes when
the value is fixed, on another panel and with another mesh."""

from __future__ import annotations

import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.viewer import Viewer  # noqa: E402

from tests.support.widgets import drive, frames  # noqa: E402


def errors_under(viewer: Viewer, section: str) -> list[tuple[str, str]]:
    """(text, widget drawn just before) of the error lines drawn in ``section`` last frame."""
    ui = viewer.ui
    ui.errors_drawn.clear()
    frames(viewer)
    return [(t, label) for s, t, label in ui.errors_drawn if s == section]


def test_a_typed_value_error_sits_under_its_field_quotes_the_text_and_goes(viewer, sphere):
    viewer.set_panel("smoothing")
    frames(viewer)
    st = viewer.panels["smoothing"].state
    lam = st.lam
    drive(viewer, "lambda", "1e309")
    assert st.lam == lam
    shown = errors_under(viewer, "smoothing")
    assert len(shown) == 1, shown
    text, under = shown[0]
    assert under == "lambda" and "'1e309'" in text  # under its field, quoting what was typed
    # 1e308 is a double, not float32's inf: it is applied as typed
    drive(viewer, "lambda", "1e308")
    assert st.lam == 1e308 and "smoothing" not in viewer.state.errors
    drive(viewer, "lambda", "-2")
    assert "'-2'" in viewer.state.errors["smoothing"] or "-2" in viewer.state.errors["smoothing"]
    assert errors_under(viewer, "smoothing")[0][1] == "lambda"
    # fixed: the error goes
    drive(viewer, "lambda", "0.5")
    assert st.lam == 0.5 and not errors_under(viewer, "smoothing")
    # another panel: the error goes; coming back, it is not there
    drive(viewer, "lambda", "abc")
    assert errors_under(viewer, "smoothing")[0][1] == "lambda"
    viewer.set_panel("curvature")
    frames(viewer)
    viewer.set_panel("smoothing")
    assert not errors_under(viewer, "smoothing") and "smoothing" not in viewer.state.errors
    # another mesh: the error goes
    drive(viewer, "noise seed", "-1")
    assert errors_under(viewer, "smoothing")[0][1] == "noise seed"
    assert viewer.open(sphere)
    assert not errors_under(viewer, "smoothing")
