"""Every widget of every panel, driven through the UI adapter on polyscope's openGL_mock backend.

The adapter (``meshlap_app.ui.UI``, as the tests' ``ScriptedUI`` in
``tests/support/scripted_ui.py``)
calls the real ``polyscope.imgui`` each frame and lets a test say what a widget returns on that
frame ("combo ``field`` returns ``gaussian``", "field ``lambda`` receives ``0``, then ``0.5``").
Each widget gets good values and bad ones (empty, 0, negative, NaN, 1e309, out of range): the
session never ends, bad input is shown in red in its panel and the last good state stays.
``test_every_widget_is_driven`` runs ``drive_panel_<name>(viewer, tmp_path)`` of every registered
panel (each panel's driver is ``tests/support/drivers/<name>.py``) and fails when a panel draws a
widget that no driver drives, or when a setting its spec declares has a widget no driver drove.
"""

from __future__ import annotations

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.ui import EXPECTED, UIApiMismatch, check_return  # noqa: E402

from tests.support.drivers import panel_drivers  # noqa: E402
from tests.support.drivers.curvature import drive_curvature_widgets  # noqa: E402
from tests.support.drivers.export import drive_export_writes_what_is_on_screen  # noqa: E402
from tests.support.drivers.help import drive_help_widgets, drive_shortcuts  # noqa: E402
from tests.support.drivers.host import (  # noqa: E402
    drive_click_and_drop,
    drive_view_combo_switches_every_panel,
)
from tests.support.drivers.isolines import drive_isolines  # noqa: E402
from tests.support.drivers.mesh_info import drive_mesh_panel_list_path_and_bad_files  # noqa: E402
from tests.support.drivers.onering import drive_onering_widgets  # noqa: E402
from tests.support.drivers.record import drive_record_widgets  # noqa: E402
from tests.support.drivers.smoothing import (  # noqa: E402
    drive_smoothing_lambda_typed_keeps_the_mesh,
    drive_smoothing_widgets,
)
from tests.support.drivers.spectral import drive_spectral_widgets  # noqa: E402
from tests.support.drivers.surfaces import drive_surfaces_widgets  # noqa: E402
from tests.support.scripted_ui import parse_number  # noqa: E402
from tests.support.widgets import drive, frames, sphere_file  # noqa: E402


# ---------------------------------------------------------------- the adapter itself
def test_adapter_pins_return_types():
    assert check_return("Combo", (True, 2)) == (True, 2)
    with pytest.raises(UIApiMismatch, match="Selectable"):
        check_return("Selectable", (True, False))  # the shape older bindings returned
    with pytest.raises(UIApiMismatch):
        check_return("Combo", (True, "gaussian"))
    with pytest.raises(UIApiMismatch):
        check_return("InputInt", (True, True))  # a bool is not an int here


def test_installed_polyscope_returns_what_the_adapter_expects(mock):
    """Call every pinned imgui/implot function of the installed polyscope inside a frame."""
    import polyscope.imgui as psim
    import polyscope.implot as psimplot

    calls = {
        "Combo": lambda: psim.Combo("c", 0, ["a", "b"]),
        "Selectable": lambda: psim.Selectable("s"),
        "BeginCombo": lambda: psim.BeginCombo("bc", "preview"),
        "Checkbox": lambda: psim.Checkbox("cb", False),
        "Button": lambda: psim.Button("b"),
        "CollapsingHeader": lambda: psim.CollapsingHeader("h"),
        "SliderFloat": lambda: psim.SliderFloat("sf", 0.5, 0.0, 1.0),
        "SliderInt": lambda: psim.SliderInt("si", 1, 0, 3),
        "InputFloat": lambda: psim.InputFloat("if", 0.5),
        "InputInt": lambda: psim.InputInt("ii", 1),
        "InputText": lambda: psim.InputText("it", "x"),
        "BeginPlot": lambda: psimplot.BeginPlot("p"),
        "BeginTable": lambda: psim.BeginTable("t", 2),
        # inside the plot (ImPlot refuses it elsewhere): called in BeginPlot's branch
        "DragPoint": lambda: psimplot.DragPoint(0, 0.5, 0.5, (1.0, 0.0, 0.0, 1.0)),
    }
    assert set(calls) == set(EXPECTED)
    results = {}

    def callback():
        for name, call in calls.items():
            if name == "DragPoint":
                continue
            results[name] = call()
            if name == "BeginCombo" and results[name]:
                psim.EndCombo()
            if name == "BeginPlot" and results[name]:
                results["DragPoint"] = calls["DragPoint"]()
                psimplot.EndPlot()
            if name == "BeginTable" and results[name]:
                psim.EndTable()

    ps.set_user_callback(callback)
    ps.frame_tick()
    ps.clear_user_callback()
    for name, result in results.items():
        check_return(name, result)  # raises UIApiMismatch when polyscope changed


def test_shortcut_keys_are_any_letter_or_digit_or_a_named_key(mock):
    """A new panel declares a new shortcut (``ui.key("g")``) without editing ``ui.py``; the
    production adapter, unscripted, asks imgui and records nothing."""
    import polyscope.imgui as psim
    from meshlap_app.keys import KEYS, imgui_key
    from meshlap_app.ui import UI

    assert imgui_key("space") == "ImGuiKey_Space" and imgui_key("left") == "ImGuiKey_LeftArrow"
    assert imgui_key("g") == imgui_key("G") == "ImGuiKey_G" and imgui_key("0") == "ImGuiKey_0"
    for name in [*KEYS, *"abcdefghijklmnopqrstuvwxyz0123456789"]:
        assert isinstance(getattr(psim, imgui_key(name)), int), name  # a key imgui knows
    for bad in ("", "ctrl", "é", "f1x", "+"):
        with pytest.raises(ValueError, match="shortcut key"):
            imgui_key(bad)
    ui, pressed = UI(), {}

    def callback():
        pressed.update({name: ui.key(name) for name in ("g", "7", "escape", "space")})

    ps.set_user_callback(callback)
    ps.frame_tick()
    ps.clear_user_callback()
    assert pressed == {"g": False, "7": False, "escape": False, "space": False}
    assert not hasattr(ui, "script") and not hasattr(ui, "seen")  # no test harness inside


def test_parse_number_reads_like_imgui():
    assert parse_number("0.5", "x") == 0.5
    assert np.isnan(parse_number("nan", "x"))
    assert parse_number("1e309", "x") == float("inf")
    assert parse_number("12", "n", integer=True) == 12
    for bad in ("", "  ", "abc"):
        with pytest.raises(ValueError, match="x"):
            parse_number(bad, "x")
    with pytest.raises(ValueError, match="whole"):
        parse_number("1e309", "n", integer=True)


# ---------------------------------------------------------------- the Mesh panel and view
def test_mesh_panel_list_path_and_bad_files(viewer, tmp_path, sphere):
    drive_mesh_panel_list_path_and_bad_files(viewer, tmp_path, sphere)


def test_view_combo_switches_every_panel(viewer):
    drive_view_combo_switches_every_panel(viewer)


# ---------------------------------------------------------------- Curvature
def test_curvature_widgets(viewer):
    drive_curvature_widgets(viewer)


# ---------------------------------------------------------------- One-ring
def test_onering_widgets(viewer):
    drive_onering_widgets(viewer)


# ---------------------------------------------------------------- Spectral
def test_spectral_widgets(viewer):
    drive_spectral_widgets(viewer)


# ---------------------------------------------------------------- Smoothing
def test_smoothing_lambda_typed_keeps_the_mesh(viewer):
    """The crash of issue 13: typing ``0.5`` passes through ``0``; nothing may end the session."""
    drive_smoothing_lambda_typed_keeps_the_mesh(viewer)


def test_smoothing_widgets(viewer):
    drive_smoothing_widgets(viewer)


def test_diverging_explicit_run_stops_with_the_stable_lambda(viewer):
    viewer.set_panel("smoothing")
    st = viewer.panels["smoothing"].state
    frames(viewer)
    drive(viewer, "method", "explicit")
    drive(viewer, "lambda", "1.5")  # uniform Laplacian: stable below 1 on this mesh
    drive(viewer, "play", True)
    frames(viewer, 60)
    s = st.smoother
    assert not st.playing and s.diverged
    assert "diverged" in st.error and "stable" in st.error
    # stopped at the first step past the bound (RMS move from the input > the bounding-box
    # diagonal); that step was discarded, so the mesh on screen is the last good one
    assert s.history[-1]["drift_rms"] <= s.diagonal
    assert s.iteration < 60


# ---------------------------------------------------------------- Surfaces
def test_surfaces_widgets(viewer):
    drive_surfaces_widgets(viewer)


# ---------------------------------------------------------------- Export
def test_export_writes_what_is_on_screen(viewer, tmp_path):
    drive_export_writes_what_is_on_screen(viewer, tmp_path)


def test_internal_error_is_shown_and_logged_once(viewer, capsys, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(viewer.panels["curvature"], "sync", broken)
    for _ in range(3):
        viewer.ui.script("field", "k2")
        ps.frame_tick()  # the session goes on
    message = viewer.state.errors["curvature"]
    assert "internal error: RuntimeError: boom" in message and "details" in message
    err = capsys.readouterr().err
    assert err.count("RuntimeError: boom") == 1
    monkeypatch.undo()
    drive(viewer, "field", "cotan")
    assert "curvature" not in viewer.state.errors  # a good change clears the message


# ---------------------------------------------------------------- Help, shortcuts, mouse, drop
def test_help_widgets(viewer):
    drive_help_widgets(viewer)


def test_shortcuts(viewer):
    drive_shortcuts(viewer)


def test_click_and_drop(viewer, tmp_path, sphere):
    drive_click_and_drop(viewer, tmp_path, sphere)


def test_captions_name_what_is_side_by_side(viewer):
    viewer.set_panel("smoothing")
    drive(viewer, "noise alpha", 0.004)
    drive(viewer, "step", True, True)
    caps = viewer.captions()
    assert caps["smoothing input"] == "input, noisy alpha = 0.004"
    assert caps["smoothed"] == "implicit, lambda = 0.5, 2 steps"
    viewer.set_panel("curvature")
    drive(viewer, "side by side", True)
    caps = viewer.captions()
    assert caps["mesh"].startswith("mean curvature H") and "second estimator" in " ".join(caps)


# ---------------------------------------------------------------- coverage
def test_every_panel_has_one_driver():
    from meshlap_app.registry import REGISTRY

    assert list(panel_drivers()) == [spec.name for spec in REGISTRY]


def test_a_panel_without_a_driver_is_named(monkeypatch):
    """A registered panel with no ``tests/support/drivers/<name>.py`` fails the tour naming the
    panel and the file it needs (it is never skipped)."""
    from types import SimpleNamespace

    from meshlap_app import registry

    monkeypatch.setattr(registry, "REGISTRY", [*registry.REGISTRY, SimpleNamespace(name="nope")])
    with pytest.raises(KeyError, match=r"nope: no driver module tests/support/drivers/nope\.py"):
        panel_drivers()


def test_every_widget_is_driven(viewer, tmp_path, request):
    """Run every registered panel's driver on one adapter, then the widgets every panel shares
    (play/record, isolines): every widget label drawn must have been scripted, and every setting
    a panel's spec declares must have had its own widget driven."""
    import polyscope as ps

    # a window tall enough for every panel: ImGui draws no plot scrolled out of view, and
    # the tour leaves headers open (the panels are longer than after their own tests)
    size = ps.get_window_size()
    ps.set_window_size(size[0], 4000)
    request.addfinalizer(lambda: ps.set_window_size(*size))
    for driver in panel_drivers().values():
        driver(viewer, tmp_path)
    drive_record_widgets(viewer, tmp_path)  # play, θ and record widgets
    drive_isolines(viewer)  # every view's isoline toggle and count
    drive_click_and_drop(viewer, tmp_path, sphere_file(tmp_path))  # a pick, a dropped file
    ui = viewer.ui
    undriven = sorted(set(ui.seen) - ui.driven)
    assert not undriven, f"widgets no test drives: {undriven}"
    from meshlap_app.registry import REGISTRY

    declared = {(spec.name, x) for spec in REGISTRY for s in spec.settings for x in s.labels}
    assert len(declared) >= 40
    missing = sorted(declared - ui.driven)  # each declared setting's own widgets, driven
    assert not missing, f"declared settings whose widget no driver drove: {missing}"
    assert not widget_audit(ui.seen), "\n".join(widget_audit(ui.seen))
    untipped = sorted(k for k, kind in ui.seen.items() if kind not in ("key", "click", "hover"))
    untipped = sorted(set(untipped) - set(ui.tooltips))
    assert not untipped, f"widgets without a tooltip: {untipped}"
    assert len(ui.seen) >= 25


HOST_WIDGETS = {
    "view": "the view combo: the session keeps the view on screen (its panel)",
    "keys": "shortcut keys: actions (a view's number, play, a step, framing, the Help pane)",
    "scene": "a click or the hover over the 3D view: a click sets a panel's declared vertex "
    "or sources",
    "jobs": "Cancel: an action on a running job",
}
"""The host's own widgets (sections that are no panel), and why none is a setting."""


def widget_audit(seen: dict[tuple[str, str], str]) -> list[str]:
    """Every widget drawn (``(section, label)`` of the scripted adapter) is a declared
    setting's (:attr:`Setting.labels`) or says why it is not (its spec's ``unsaved``, or the
    host's :data:`HOST_WIDGETS`); every ``unsaved`` entry is a widget drawn (no stale one).
    A session keeps every declared setting (``tests/app/test_panel_contract.py``): so every
    widget a user can change is kept, or its reason is written down."""
    from meshlap_app.registry import REGISTRY

    specs = {spec.name: spec for spec in REGISTRY}
    problems = []
    for (section, label), kind in sorted(seen.items()):
        spec = specs.get(section)
        if spec is None:
            if section not in HOST_WIDGETS and not label.startswith("Cancel##"):
                problems.append(f"{section} / {label!r} ({kind}): a host widget with no reason")
        elif not any(label in s.labels for s in spec.settings) and label not in spec.unsaved:
            problems.append(
                f"{section} / {label!r} ({kind}): neither a declared setting nor in its "
                "spec's unsaved (declare it, or say why it is not a setting)"
            )
    for spec in REGISTRY:
        for label in spec.unsaved:
            if (spec.name, label) not in seen:
                problems.append(f"{spec.name} / {label!r}: unsaved, but no widget has it")
    return problems


def test_histogram_bars_take_the_colour_of_their_value_on_the_mesh():
    from matplotlib import colormaps
    from meshlap_app.panels.curvature import _bar_colors

    centers = np.array([-2.0, 0.0, 2.0, 5.0])
    signed = _bar_colors(centers, -2.0, 2.0, signed=True)
    cool = colormaps["coolwarm"]
    np.testing.assert_allclose(signed[0], cool(0.0))  # the low end of the range
    np.testing.assert_allclose(signed[1], cool(0.5))  # zero: the middle (white) of coolwarm
    np.testing.assert_allclose(signed[3], cool(1.0))  # clipped like the mesh's colours
    unsigned = _bar_colors(centers, 0.0, 5.0, signed=False)
    np.testing.assert_allclose(unsigned[3], colormaps["viridis"](1.0))
