"""Every widget of every panel, driven through the UI adapter on polyscope's openGL_mock backend.

The adapter (``meshlap_app.ui.UI``, as the tests' ``ScriptedUI`` in ``tests/scripted_ui.py``)
calls the real ``polyscope.imgui`` each frame and lets a test say what a widget returns on that
frame ("combo ``field`` returns ``gaussian``", "field ``lambda`` receives ``0``, then ``0.5``").
Each widget gets good values and bad ones (empty, 0, negative, NaN, 1e309, out of range): the
session never ends, bad input is shown in red in its panel and the last good state stays.
``test_every_widget_is_driven`` runs ``drive_panel_<name>(viewer, tmp_path)`` of every registered
panel (each panel's test module defines its own) and fails when a panel draws a widget that no
driver drives, or when a setting its spec declares has a widget no driver drove.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.ui import EXPECTED, UIApiMismatch, check_return  # noqa: E402
from meshlap_app.viewer import Viewer  # noqa: E402
from scripted_ui import parse_number  # noqa: E402

from meshlap_core import primitives  # noqa: E402
from meshlap_core.io import load_mesh, save_mesh  # noqa: E402

BAD_NUMBERS = ["", "0", "-1", "nan", "1e309", "abc"]


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def frames(viewer: Viewer, n: int = 1) -> None:
    """Run ``n`` frames; no exception may end the session and nothing may be an internal error."""
    for _ in range(n):
        ps.frame_tick()
    internal = {k: m for k, m in viewer.state.errors.items() if "internal error" in m}
    assert not internal, internal


def drive(viewer: Viewer, label: str, *values, panel: str | None = None) -> None:
    """Give widget ``label`` one value per frame (with the Export header open if needed)."""
    for value in values:
        if panel is not None:
            viewer.set_panel(panel)
        viewer.ui.script(label, value)
        if label in EXPORT_WIDGETS:
            viewer.ui.script("Export", True)
        if label in HELP_WIDGETS:
            viewer.ui.script("Help and window (H)", True)
        frames(viewer)
        assert not viewer.ui.pending(), f"widget {label!r} was not drawn"


EXPORT_WIDGETS = ("folder", "screenshot", "export what is shown")
HELP_WIDGETS = ("polyscope's own panels", "UI scale")


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
    drive(viewer, "bundled / shared", "assets/bumpy.obj")
    assert viewer.state.mesh.name == "bumpy.obj"
    assert ps.get_surface_mesh("mesh").n_vertices() == len(viewer.state.mesh.V)
    n = len(viewer.state.mesh.V)
    bad = tmp_path / "broken.off"
    bad.write_text("OFF\n10 5 0\n0 0 0\n")
    for text in ("", str(tmp_path / "missing.obj"), str(bad), str(tmp_path)):
        viewer.panels["mesh_info"].path_text = text
        drive(viewer, "Open", True)
        assert len(viewer.state.mesh.V) == n  # the last good mesh stays
    assert viewer.state.mesh.error  # said in the Mesh panel
    drive(viewer, "path", str(sphere))  # Enter in the path field opens it
    assert viewer.state.mesh.name == "sphere.obj" and not viewer.state.mesh.error
    # the recent-files entry appears in the list and opens the file again
    drive(viewer, "bundled / shared", "assets/bumpy.obj", "recent: sphere.obj")
    assert viewer.state.mesh.name == "sphere.obj"
    viewer.ui.script("bundled / shared", "no such mesh")
    ps.frame_tick()
    assert "not in the list" in viewer.state.errors["mesh_info"]


def test_view_combo_switches_every_panel(viewer):
    for panel in ("onering", "spectral", "smoothing", "surfaces", "curvature"):
        drive(viewer, "view", panel)
        assert viewer.state.panel == panel
    viewer.ui.script("view", "nonsense")
    ps.frame_tick()
    assert viewer.state.panel == "curvature" and "nonsense" in viewer.state.errors["view"]


# ---------------------------------------------------------------- Curvature
def test_curvature_widgets(viewer):
    c = viewer.state.curv
    drive(viewer, "field", "gaussian")
    assert c.field_name == "gaussian"
    drive(viewer, "area", "voronoi")
    assert c.area == "voronoi" and "gaussian" in c.fields
    drive(viewer, "boundary rule", "pi")
    for good in (5.0, 0.0, 49.0):
        drive(viewer, "clip %", good)
        assert c.percentile == good
    drive(viewer, "clip %", 80.0, -3.0)  # out of range (Ctrl+click types any value): clamped
    assert c.percentile == 0.0
    drive(viewer, "clip %", "nan", "1e309")
    assert c.percentile == 0.0 and "clip %" in viewer.state.errors["curvature"]
    drive(viewer, "side by side", True)
    assert ps.has_surface_mesh("mesh (second estimator)")
    drive(viewer, "second field", "k1")
    assert viewer.state.curv.second_field == "k1"
    drive(viewer, "side by side", False)
    assert not ps.has_surface_mesh("mesh (second estimator)")
    lo, hi = c.color_range("gaussian")
    assert lo < hi and np.isfinite(lo)


# ---------------------------------------------------------------- One-ring
def test_onering_widgets(viewer):
    viewer.set_panel("onering")
    drive(viewer, "vertex", 7)
    assert (
        viewer.panels["onering"].state.vertex == 7 and viewer.panels["onering"].state.valence >= 5
    )
    before = list(viewer.panels["onering"].state.neighbors)
    for bad in ["", "-1", "nan", "1e309", "abc", str(len(viewer.state.mesh.V)), 10**9]:
        drive(viewer, "vertex", bad)
        assert viewer.panels["onering"].state.vertex == 7  # the selection stays
        assert "vertex" in viewer.state.errors["onering"]
    drive(viewer, "clockwise (reverse)", True)
    assert viewer.panels["onering"].state.neighbors == before[::-1]
    drive(viewer, "clockwise (reverse)", False)
    assert (
        viewer.panels["onering"].state.neighbors == before and "onering" not in viewer.state.errors
    )


# ---------------------------------------------------------------- Spectral
def wait_for_basis(viewer: Viewer) -> None:
    st = viewer.panels["spectral"].state
    t0 = time.monotonic()
    while st.busy:
        assert time.monotonic() - t0 < 300, "the eigen worker never finished"
        time.sleep(0.02)
    frames(viewer, 2)  # the panel adopts the finished basis


def test_spectral_widgets(viewer):
    viewer.set_panel("spectral")
    st = viewer.panels["spectral"].state
    n = len(viewer.state.mesh.V)
    drive(viewer, "modes to compute", 30)
    assert st.k_request == 30
    for bad in ("", "nan", "1e309", "abc"):
        drive(viewer, "modes to compute", bad)
        assert st.k_request == 30
    drive(viewer, "modes to compute", -5, 0, 10**9)  # clamped to [2, n]
    assert st.k_request == n
    drive(viewer, "modes to compute", 30)
    drive(viewer, "compute eigenbasis", True)
    wait_for_basis(viewer)
    assert st.basis is not None and st.basis.k_max == 30
    assert ps.has_surface_mesh("reconstruction")
    drive(viewer, "eigenmode i", 3)
    _, lam = st.eigenfunction()
    assert st.mode == 3 and lam == pytest.approx(st.basis.eigenvalues[3])
    drive(viewer, "eigenmode i", -1, 10**6)
    assert st.mode == 29  # clamped
    drive(viewer, "k (reconstruct)", 12)
    assert st.k == 12
    np.testing.assert_allclose(st.reconstruction, st.basis.reconstruct(12))
    drive(viewer, "k (reconstruct)", 0, 10**6, "nan")
    assert st.k == 30 and "k (reconstruct)" in viewer.state.errors["spectral"]


# ---------------------------------------------------------------- Smoothing
def test_smoothing_lambda_typed_keeps_the_mesh(viewer):
    """The crash of issue 13: typing ``0.5`` passes through ``0``; nothing may end the session."""
    viewer.set_panel("smoothing")
    st = viewer.panels["smoothing"].state
    frames(viewer)
    drive(viewer, "noise alpha", 0.01)
    drive(viewer, "step", True, True, True)
    smoother, V = st.smoother, np.array(st.V)
    assert smoother.iteration == 3
    for bad in BAD_NUMBERS:
        drive(viewer, "lambda", bad)
        assert st.lam == 0.5 and "lambda" in viewer.state.errors["smoothing"]
    drive(viewer, "lambda", "0.25")
    assert st.lam == 0.25 and "smoothing" not in viewer.state.errors
    # a λ edit keeps the current mesh, its noise and the iteration count (set_lam only)
    assert st.smoother is smoother and smoother.lam == 0.25 and smoother.iteration == 3
    np.testing.assert_array_equal(st.V, V)


def test_smoothing_widgets(viewer):
    viewer.set_panel("smoothing")
    st = viewer.panels["smoothing"].state
    frames(viewer)
    for method in ("explicit", "taubin", "implicit"):
        drive(viewer, "method", method)
        assert st.smoother.method == method
    drive(viewer, "Laplacian", "cotan")
    assert st.smoother.laplacian == "cotan"
    drive(viewer, "noise alpha", 0.02)
    assert st.noise_alpha == 0.02
    start = np.array(st.V_start)
    for bad in ("nan", "1e309", -0.5):
        drive(viewer, "noise alpha", bad)
        assert st.noise_alpha == 0.02 and "alpha" in viewer.state.errors["smoothing"]
        np.testing.assert_array_equal(st.V_start, start)
    drive(viewer, "noise seed", 3)
    assert st.seed == 3
    for bad in (-1, "", "1e309", "abc"):
        drive(viewer, "noise seed", bad)
        assert st.seed == 3
    drive(viewer, "play", True)
    assert st.playing
    frames(viewer, 3)
    drive(viewer, "pause", True)
    assert not st.playing and st.smoother.iteration >= 3
    drive(viewer, "reset", True)
    assert st.smoother.iteration == 0


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
    viewer.set_panel("surfaces")
    s = viewer.panels["surfaces"].state
    frames(viewer)
    drive(viewer, "surface", "torus")
    assert s.name == "torus" and ps.has_surface_mesh("surface")
    drive(viewer, "resolution", 24)
    assert s.res == 24 and s.mesh is not None
    for bad in (0, -3, 2, 10**6, "", "nan", "1e309"):
        drive(viewer, "resolution", bad)
        assert s.res == 24 and viewer.state.errors["surfaces"]
    drive(viewer, "u", 1.0)
    drive(viewer, "v", 0.5)
    assert (s.u, s.v) == (1.0, 0.5)
    _, u1, _, _ = s.domain
    drive(viewer, "u", u1 + 10.0)  # out of range: clamped into the domain
    assert s.u == u1
    for bad in ("nan", "1e309"):
        drive(viewer, "v", bad)
        assert s.v == 0.5


# ---------------------------------------------------------------- Export
def test_export_writes_what_is_on_screen(viewer, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    drive(viewer, "folder", str(tmp_path / "does-not-exist"))
    assert "export folder" in viewer.state.errors["export"]
    drive(viewer, "folder", str(out))
    assert viewer.state.folder == out.resolve()
    # smoothing: the smoothed mesh as it is now, not the original vertices
    viewer.set_panel("smoothing")
    frames(viewer)
    drive(viewer, "step", True, True)
    drive(viewer, "export what is shown", True)
    status = viewer.panels["export"].status
    assert str(out.resolve()) in status
    st = viewer.panels["smoothing"].state
    name = f"sphere_{st.method}_{st.laplacian}_it{st.smoother.iteration}.ply"
    assert status == f"wrote {name}, sphere_input.ply in {out.resolve()}"
    back = load_mesh(out / name)
    np.testing.assert_allclose(back.V, st.V, atol=1e-6)
    assert not np.allclose(back.V, viewer.state.mesh.V, atol=1e-6)
    drive(viewer, "screenshot", True)
    assert (out / "sphere_smoothing.png").is_file()


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


def test_shortcuts(viewer):
    from meshlap_app.registry import VIEWS as PANELS

    for i, panel in enumerate(PANELS):
        drive(viewer, f"key {i + 1}", True)
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


def test_click_and_drop(viewer, tmp_path, sphere):
    before = viewer.panels["onering"].state.vertex
    drive(viewer, "click", (10.0, 10.0), (-5.0, 1e9))  # nothing there: nothing happens
    assert viewer.panels["onering"].state.vertex == before
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    n = len(viewer.state.mesh.V)
    viewer.files_dropped([str(bad)])
    assert "bad.obj" in viewer.state.mesh.error and len(viewer.state.mesh.V) == n
    viewer.files_dropped([])
    viewer.files_dropped([str(tmp_path / "assets_missing.ply")])
    frames(viewer)
    viewer.files_dropped([str(sphere)])
    assert viewer.state.mesh.name == "sphere.obj" and not viewer.state.mesh.error


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
def panel_drivers() -> dict[str, Callable[..., None]]:
    """``drive_panel_<name>(viewer, tmp_path)`` of every registered panel, found in the test
    module that defines it (``tests/test_*.py``): a new panel brings its driver in its own test
    file and this tour runs it, without a line here. KeyError names a panel without one."""
    from meshlap_app.registry import REGISTRY

    sources = {p.stem: p.read_text() for p in sorted(Path(__file__).parent.glob("test_*.py"))}
    drivers: dict[str, Callable[..., None]] = {}
    for entry in REGISTRY:
        name = f"drive_panel_{entry.name}"
        homes = [stem for stem, text in sources.items() if f"\ndef {name}(" in text]
        if len(homes) != 1:
            raise KeyError(f"{entry.name}: {name} is defined in {homes or 'no test module'}")
        drivers[entry.name] = getattr(importlib.import_module(homes[0]), name)
    return drivers


def test_every_panel_has_one_driver():
    from meshlap_app.registry import REGISTRY

    assert list(panel_drivers()) == [e.name for e in REGISTRY]


def sphere_file(folder: Path) -> Path:
    """An icosphere (level 2) written to ``folder`` (the ``sphere`` fixture's mesh)."""
    path = folder / "sphere.obj"
    if not path.is_file():
        save_mesh(path, *primitives.icosphere(2))
    return path


def drive_panel_mesh_info(viewer, tmp_path: Path) -> None:
    """The mesh section: the list, the path field and bad files."""
    test_mesh_panel_list_path_and_bad_files(viewer, tmp_path, sphere_file(tmp_path))


def drive_panel_curvature(viewer, tmp_path: Path) -> None:
    test_view_combo_switches_every_panel(viewer)
    test_curvature_widgets(viewer)
    from test_curvature_lab import drive_curvature_estimator  # estimator, shape operator

    drive_curvature_estimator(viewer)


def drive_panel_onering(viewer, tmp_path: Path) -> None:
    test_onering_widgets(viewer)
    from test_viewer_inspector import drive_inspector  # the inspector's widgets

    drive_inspector(viewer)


def drive_panel_spectral(viewer, tmp_path: Path) -> None:
    test_spectral_widgets(viewer)


def drive_panel_smoothing(viewer, tmp_path: Path) -> None:
    test_smoothing_widgets(viewer)
    test_smoothing_lambda_typed_keeps_the_mesh(viewer)


def drive_panel_surfaces(viewer, tmp_path: Path) -> None:
    test_surfaces_widgets(viewer)


def drive_panel_export(viewer, tmp_path: Path) -> None:
    test_export_writes_what_is_on_screen(viewer, tmp_path)


def drive_panel_help(viewer, tmp_path: Path) -> None:
    test_help_widgets(viewer)
    test_shortcuts(viewer)
    from test_session import drive_session_widgets  # the session widgets (Help and window)

    drive_session_widgets(viewer, tmp_path)


def test_every_widget_is_driven(viewer, tmp_path):
    """Run every registered panel's driver on one adapter, then the widgets every panel shares
    (play/record, isolines): every widget label drawn must have been scripted."""
    for drive in panel_drivers().values():
        drive(viewer, tmp_path)
    from test_viewer_record import drive_record_widgets  # play, θ and record widgets

    drive_record_widgets(viewer, tmp_path)
    from test_isolines import drive_isolines  # every view's isoline toggle and count

    drive_isolines(viewer)
    test_click_and_drop(viewer, tmp_path, sphere_file(tmp_path))  # a pick, a dropped file
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
    A session keeps every declared setting (``tests/test_panel_contract.py``): so every
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
