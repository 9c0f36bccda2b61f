"""Issue 23 (the window tells the truth): each item driven through the widgets (ScriptedUI on
polyscope's openGL_mock backend, the ``viewer`` fixture)."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.viewer import Viewer  # noqa: E402

from tests.support.readme import README, readme_keys  # noqa: E402


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def frames(viewer: Viewer, n: int = 1) -> None:
    """Run ``n`` frames; nothing may be an internal error."""
    for _ in range(n):
        ps.frame_tick()
    internal = {k: m for k, m in viewer.state.errors.items() if "internal error" in m}
    assert not internal, internal


def drive(viewer: Viewer, label: str, *values) -> None:
    """Give widget ``label`` one value per frame; it must have been drawn."""
    for value in values:
        viewer.ui.script(label, value)
        frames(viewer)
        assert not viewer.ui.pending(), f"widget {label!r} was not drawn"


# ---------------------------------------------------------------- item 2: κₙ against φ
def test_euler_plot_is_in_the_geometric_angle(viewer):
    viewer.set_panel("surfaces")
    frames(viewer)
    s = viewer.panels["surfaces"].state
    assert s.name == "helicoid"
    for u, v in ((0.0, 0.0), (0.7, 0.4), (-1.2, 1.5)):
        drive(viewer, "u", u)
        drive(viewer, "v", v)
        plots = {label: rec for (sec, label), rec in viewer.ui.plots.items() if sec == "surfaces"}
        _kind, phi_deg, kn = plots["k_n"]
        phi_deg, kn = np.asarray(phi_deg), np.asarray(kn)
        p = s.point
        # the plotted extremes are 90° apart (the parameter-angle curve had them 99–109° apart)
        i_max, i_min = int(np.argmax(kn[:-1])), int(np.argmin(kn[:-1]))
        gap = abs(phi_deg[i_max] - phi_deg[i_min]) % 180.0
        assert gap == pytest.approx(90.0, abs=2.1)  # 2° sampling
        # Euler's formula on the plotted curve
        phi = np.radians(phi_deg)
        euler = p.k1 * np.cos(phi) ** 2 + p.k2 * np.sin(phi) ** 2
        assert np.allclose(kn, euler, atol=1e-9 * max(1.0, abs(p.k1), abs(p.k2)))
        # k1 and k2 are marked (named with their values) where the curve reaches them
        for name, k in (("k1", p.k1), ("k2", p.k2)):
            at = np.asarray(plots[f"{name} = {k:.3g}"][1])
            assert np.allclose(np.interp(at, phi_deg, kn), k)
        assert list(plots[f"k1 = {p.k1:.3g}"][1]) == [0.0, 180.0, 360.0]
        assert list(plots[f"k2 = {p.k2:.3g}"][1]) == [90.0, 270.0]
    # the parameter angle θ is kept, labelled as such, and the section is marked at its φ
    tip = viewer.ui.tooltips[("surfaces", "section theta")]
    assert "(u, v) plane" in tip and "tangent plane from the first principal" in tip
    drive(viewer, "section theta", 40.0)
    marked = viewer.ui.plots[("surfaces", "section")][1][0]
    assert marked == pytest.approx(s.section_phi_deg())
    t, kn = s.section()
    e1 = s.point.dir1
    assert np.degrees(np.arccos(abs(t @ e1))) == pytest.approx(
        min(marked % 180.0, 180.0 - marked % 180.0), abs=1e-6
    )
    phi = np.radians(marked)
    assert kn == pytest.approx(s.point.k1 * np.cos(phi) ** 2 + s.point.k2 * np.sin(phi) ** 2)
    assert "in (u, v), φ = " in s.section_caption()


# ---------------------------------------------------------------- item 4: play beyond the limit
def test_play_beyond_the_stable_limit_stops_at_the_first_growing_step(viewer):
    viewer.set_panel("smoothing")
    frames(viewer)
    st = viewer.panels["smoothing"].state
    drive(viewer, "method", "explicit")
    drive(viewer, "noise alpha", 0.01)
    limit = st.smoother.stability.max_stable_lam
    assert limit is not None
    drive(viewer, "lambda", str(1.5 * limit))
    assert st.smoother.stability.message()  # the warning is shown

    def rms_move(before: np.ndarray) -> float:
        return float(np.sqrt(np.mean(np.sum((np.array(st.V) - before) ** 2, axis=1))))

    before = np.array(st.V)
    drive(viewer, "play", True)  # the frame that presses play takes the first step
    moves = [rms_move(before)]
    for _ in range(60):
        if not st.playing:
            break
        before = np.array(st.V)
        frames(viewer)
        moves.append(rms_move(before))
    assert not st.playing, "play ran on beyond the stable limit"
    assert "play stopped at iteration" in st.error and "stable limit" in st.error
    # it stopped at the first step that grew (the last one), well before the mesh blows up
    assert len(moves) >= 2 and moves[-1] > moves[-2]
    assert all(b <= a for a, b in pairwise(moves[:-1]))
    assert f"iteration {st.smoother.iteration}:" in st.error
    drift = float(np.sqrt(np.mean(np.sum((np.array(st.V) - st.V_start) ** 2, axis=1))))
    diagonal = float(np.linalg.norm(np.ptp(st.V_start, axis=0)))
    assert drift < 0.5 * diagonal
    # the panel shows why (in red, under the buttons); a stable lambda plays on
    drive(viewer, "reset", True)
    drive(viewer, "lambda", str(0.5 * limit))
    drive(viewer, "play", True)
    frames(viewer, 30)
    assert st.playing and st.smoother.iteration >= 30 and not st.error
    viewer.ui.script("key space", True)
    frames(viewer)
    assert not st.playing


# ---------------------------------------------------------------- item 3: typed-value errors
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


# ---------------------------------------------------------------- class check: every legend
KEPT_ON_PURPOSE = {"curvature": "the views that shows_curvature keep the mesh's field"}


def legend_problems(viewer: Viewer, ledger, where: str) -> list[str]:
    """Every visible colour-mapped quantity has an on-screen colour bar with its name and a
    range, and belongs to the active view (or to the curvature field a view keeps)."""
    active = viewer.active()
    out = []
    for structure, qs in ledger.quantities.items():
        for name, q in qs.items():  # polyscope draws these bars even for a hidden structure
            if q.enabled and q.colorbar and not ledger.structure_enabled(structure):
                out.append(f"{where}: colour bar of hidden {structure} / {name!r} on screen")
    for (structure, name), q in ledger.visible().items():
        if q.kind != "scalar":
            continue  # RGB colours carry no colour map (their meaning is in the panel's text)
        if not (q.colorbar and name and q.vminmax is not None):
            out.append(f"{where}: {structure} / {name!r} is visible without a colour bar")
        kept = q.owner in KEPT_ON_PURPOSE and active.shows_curvature
        if q.owner != active.name and not kept:
            out.append(f"{where}: {structure} / {name!r} of {q.owner!r} visible in {active.name}")
    return out


def test_every_visible_quantity_has_a_legend_and_belongs_to_the_view(viewer, sphere, monkeypatch):
    from meshlap_app.registry import VIEWS

    from meshlap_core.options import CURVATURE_FIELD_LABELS
    from tests.support.legend_ledger import Ledger

    ledger = Ledger().install(monkeypatch)
    assert viewer.open(sphere)  # everything registered again, through the ledger
    frames(viewer)
    problems: list[str] = []
    fields = list(CURVATURE_FIELD_LABELS)
    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)  # the ring and the inspector's weights are on screen
    assert viewer.panels["onering"].state.vertex == 5
    for basis in (False, True):
        if basis:
            viewer.set_panel("spectral")
            drive(viewer, "modes to compute", 12)
            drive(viewer, "compute eigenbasis", True)
            st = viewer.panels["spectral"].state
            while st.busy:
                frames(viewer)
            frames(viewer, 2)
            assert st.basis is not None
        for i, field in enumerate(fields):
            for side in (False, True):
                viewer.set_panel("curvature")
                drive(viewer, "field", field)
                c = viewer.state.curv
                if c.side_by_side != side:
                    drive(viewer, "side by side", side)
                if side:
                    drive(viewer, "second field", fields[(i + 1) % len(fields)])
                for view in VIEWS:
                    viewer.set_panel(view)
                    frames(viewer, 2)
                    where = f"basis={basis} field={field} side={side} view={view}"
                    problems += legend_problems(viewer, ledger, where)
    assert not problems, "\n".join(dict.fromkeys(problems))


# ---------------------------------------------------------------- item 1: second mesh, basis
def compute_basis(viewer: Viewer, modes: int = 12) -> None:
    viewer.set_panel("spectral")
    drive(viewer, "modes to compute", modes)
    drive(viewer, "compute eigenbasis", True)
    st = viewer.panels["spectral"].state
    while st.busy:
        frames(viewer)
    frames(viewer, 2)
    assert st.basis is not None


def test_second_mesh_then_eigenbasis_shows_the_reconstruction(viewer):

    recon = "reconstruction"
    compute_basis(viewer)
    assert ps.get_surface_mesh(recon).is_enabled()
    viewer.set_panel("curvature")  # the copy is hidden with its view
    frames(viewer)
    assert not ps.get_surface_mesh(recon).is_enabled()
    second = Path(__file__).parents[2] / "assets" / "icosphere.obj"
    assert viewer.open(second)
    frames(viewer)
    compute_basis(viewer)
    sm = ps.get_surface_mesh(recon)
    assert sm.is_enabled(), "the reconstruction came back hidden"
    st = viewer.panels["spectral"].state
    before = np.array(st.reconstruction)
    drive(viewer, "k (reconstruct)", 3)
    assert st.k == 3 and sm.is_enabled()
    assert not np.allclose(before, st.reconstruction)  # the k slider changes what is shown


# ---------------------------------------------------------------- item 9: --ui-scale --session
def test_view_accepts_ui_scale_with_a_session(viewer, tmp_path, sphere, monkeypatch):
    import meshlap_app.viewer as viewer_module
    from meshlap_app.state.session import Session, write_session

    from meshlap_core.cli import main

    path = write_session(tmp_path / "s.json", Session(mesh=sphere, panel="curvature"))
    seen: dict = {}

    def show() -> None:  # the window's loop: read what the viewer was given instead
        seen["ok"] = True

    monkeypatch.setattr(viewer_module, "init_polyscope", lambda backend: None)
    monkeypatch.setattr(ps, "show", show)
    applied = []
    real = viewer_module.Viewer.set_ui_scale
    monkeypatch.setattr(
        viewer_module.Viewer, "set_ui_scale", lambda v, s: (applied.append(s), real(v, s))
    )
    assert main(["view", "--ui-scale", "2", "--session", str(path)]) == 0
    assert seen["ok"] and applied[-1] == 2.0  # the typed scale wins over the session's


# ---------------------------------------------------------------- class check: every key
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
    return (viewer.state.panel, help_panel.shown, sm.playing, it, sp.k, camera)


def test_every_documented_key_does_something(viewer):
    keys = help_keys(viewer)
    documented = {k for k, _ in keys}
    missing = set(readme_keys()) - documented
    assert not missing, f"keys in the README but not in the Help window: {missing}"
    compute_basis(viewer)
    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)
    viewer.set_panel("smoothing")
    drive(viewer, "noise alpha", 0.01)
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


# ---------------------------------------------------------------- items 10, 11: small ones
def test_genus_none_is_explained_and_small_texts(viewer, tmp_path):
    from meshlap_app.panels.mesh_info import genus_reason
    from meshlap_app.state.surfaces import SurfaceState
    from meshlap_app.text_numbers import plural

    from meshlap_core.frames import VIDEO_EXTRA

    fin = tmp_path / "fin.obj"  # three triangles on one edge: not a manifold
    fin.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 1 2 5\n")
    assert viewer.open(fin)
    frames(viewer)
    info = viewer.state.mesh.info
    assert info["genus"] is None
    why = genus_reason(info)
    assert "not a manifold" in why and "boundary is not a set of loops" in why
    # "1 step", the README's install hint in the MP4 error, κₙ round-off shown as 0
    assert plural(1, "step") == "1 step" and plural(3, "step") == "3 steps"
    assert "pip install -e '.[video]'" in VIDEO_EXTRA
    assert "pip install -e '.[video]'" in README.read_text(encoding="utf-8")
    s = SurfaceState()
    s.set_surface("saddle")
    s.set_section(45.0)  # κₙ = 4.4e-16 in floating point
    assert "κₙ = 0 " in s.section_caption()


def test_k_sweep_error_colour_bar_keeps_one_range(viewer, monkeypatch):
    from tests.support.legend_ledger import Ledger

    ledger = Ledger().install(monkeypatch)
    compute_basis(viewer, 12)
    panel = viewer.panels["spectral"]
    ranges = []
    for _ in panel.frames(viewer, {"k": (1, 8)}):
        q = ledger.quantities["reconstruction"]["error |x - x_k|"]
        assert q.colorbar
        ranges.append(q.vminmax)
    assert len(ranges) == 8 and len(set(ranges)) == 1, ranges


def test_path_field_opens_a_session_and_empties(viewer, tmp_path, sphere):
    from meshlap_app.state.session import Session, write_session

    path = write_session(tmp_path / "s.json", Session(mesh=sphere, panel="smoothing"))
    viewer.set_panel("curvature")
    drive(viewer, "path", str(path))
    assert viewer.state.panel == "smoothing" and "mesh_info" not in viewer.state.errors
    assert viewer.panels["mesh_info"].path_text == ""
    drive(viewer, "path", str(sphere))
    assert viewer.panels["mesh_info"].path_text == ""  # not the old path any more
    drive(viewer, "path", str(tmp_path / "missing.json"))
    assert viewer.state.errors["mesh_info"]  # refused, said under the field
    assert viewer.panels["mesh_info"].path_text.endswith("missing.json")


def test_a_missing_export_folder_is_reported_with_where_files_go(viewer, tmp_path):
    from meshlap_core.errors import MeshError

    with pytest.raises(MeshError, match="create it first") as err:
        viewer.state.set_folder(str(tmp_path / "nope"))
    assert str(viewer.state.folder) in str(err.value)


def test_hovering_a_neighbour_sphere_shows_its_weight(viewer, monkeypatch):
    from types import SimpleNamespace

    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)
    panel = viewer.panels["onering"]
    r = panel.state
    hit = SimpleNamespace(is_hit=True, structure_name="one-ring neighbours", local_index=2)
    monkeypatch.setattr(ps, "pick", lambda screen_coords: hit)
    text = panel.hover_text(viewer, (10.0, 10.0))
    j = r.neighbors[2]
    w = next(t.weight_cotan for t in r.inspection.neighbors if t.index == j)
    assert text == f"neighbour 2 = vertex {j}: w_ij = {w:.4g}"
    assert panel.hovered_vertex == j  # its table row is lit


# ---------------------------------------------------------------- item 8: UI scale 1e308
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


# ---------------------------------------------------------------- item 7: frame the ring
@pytest.mark.parametrize("scale", [1.0, 1.5])
def test_f_frames_the_ring_clear_of_the_colour_bars_and_the_panel(viewer, scale):
    from meshlap_app import scene
    from meshlap_app.camera import project_to_screen

    ps.set_window_size(1280, 720)  # another module's test may have left another size
    viewer.set_ui_scale(scale)
    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)
    ps.look_at((5.0, 2.0, 3.0), (0.0, 0.0, 0.0))
    viewer.ui.script("key f", True)
    frames(viewer, 2)
    r = viewer.panels["onering"].state
    params = ps.get_view_camera_parameters()
    w, h = ps.get_window_size()
    pts = viewer.state.display.points(np.vstack([r.polyline, viewer.state.mesh.V[[r.vertex]]]))
    xy, front = project_to_screen(pts, params.get_view_mat(), params.get_fov_vertical_deg(), w, h)
    assert front.all()  # nothing behind the camera (or cut by the near plane)
    bars = scene.COLORBAR_PX * scale
    pane = w - ps.get_right_gui_pane_width() * scale
    assert (xy[:, 0] > bars).all() and (xy[:, 0] < pane).all(), (xy[:, 0], bars, pane)
    assert (xy[:, 1] > 0).all() and (xy[:, 1] < h).all()


# ---------------------------------------------------------------- item 9: the k sweep's play
def test_play_and_pause_are_one_width(viewer):
    compute_basis(viewer)
    st = viewer.panels["spectral"].state
    drive(viewer, "play what", "k sweep")
    widths = viewer.ui.button_widths
    drive(viewer, "play", True)
    assert st.playing
    frames(viewer, 2)
    drive(viewer, "pause", True)
    assert not st.playing
    frames(viewer)
    # play and pause take turns in one place: the same width, wide enough for either label
    w_play, w_pause = widths[("spectral", "play")], widths[("spectral", "pause")]
    assert w_play == w_pause > 0
    assert w_play >= max(ps.imgui.CalcTextSize(t)[0] for t in ("play", "pause"))


def test_the_caption_shows_the_k_of_the_slider_drawn_in_the_same_frame(viewer):
    compute_basis(viewer)
    st = viewer.panels["spectral"].state
    drive(viewer, "play what", "k sweep")
    drive(viewer, "play", True)
    assert st.playing
    viewer.ui.overlays.clear()
    for _ in range(5):
        frames(viewer)
        # the slider drawn this frame and the caption under the copy name the same k
        k = viewer.ui.drawn[("spectral", "k (reconstruct)")]
        assert k == st.k
        captions = [t for _, t in viewer.ui.overlays if t.startswith("k = ")]
        assert captions == [f"k = {k} of {st.basis.k_max} modes"]
        viewer.ui.overlays.clear()
    drive(viewer, "pause", True)


# ---------------------------------------------------------------- item 10: file names whole
def test_the_recorded_file_name_is_never_broken_at_its_dot(viewer, tmp_path):
    from meshlap_app.record import RECORD_HEADER
    from meshlap_app.text_wrap import wrap_at_spaces

    viewer.set_panel("smoothing")
    frames(viewer)
    folder = tmp_path / ("a_long_folder_name_" * 4)
    folder.mkdir()
    path = folder / "smoothing.gif"

    def opened(label: str, value) -> None:  # the record header is open in that frame
        viewer.ui.script(RECORD_HEADER, True)
        drive(viewer, label, value)

    opened("record file", str(path))
    opened("record", True)
    for _ in range(3):
        opened("step", True)
    opened("stop", True)
    assert path.exists()
    viewer.ui.lines.clear()
    viewer.ui.script(RECORD_HEADER, True)
    frames(viewer)
    lines = [line for sec, line in viewer.ui.lines if sec == "smoothing"]
    assert any(line.startswith("wrote ") for line in lines), lines
    # the status is wider than the panel: wrapped, but the path stays one word, whole
    assert len(lines) > 1 and str(path) in lines
    assert " ".join(lines) == viewer.panels["smoothing"].recorder.status
    # only at spaces: a dotted name is never split (imgui's own wrap breaks after the dot)
    assert wrap_at_spaces("to smoothing.gif", 1.0, len) == ["to", "smoothing.gif"]


# ---------------------------------------------------------------- item 10: text under the panel
def test_hover_labels_and_captions_end_left_of_the_panel(viewer, monkeypatch):
    from meshlap_app.scene import scene_width
    from meshlap_app.state.onering import HoverThrottle

    viewer.set_panel("onering")
    frames(viewer)
    panel = viewer.panels["onering"]
    t = [0.0]
    panel.clock, panel.throttle = (lambda: t[0]), HoverThrottle()
    label = "vertex 12345   field value -0.000123456"
    monkeypatch.setattr(panel, "hover_text", lambda host, pos: label)
    w, _ = ps.get_window_size()
    right = scene_width(w, viewer.state.ui_scale)
    for x in (40.0, right - 30.0, w - 5.0):  # clear of the panel, near it, under it
        for _ in range(3):  # the cursor rests: picked, then shown
            viewer.ui.overlays.clear()
            drive(viewer, "hover", (x, 100.0))
            t[0] += 0.2
        shown = [pos for pos, text in viewer.ui.overlays if text == label]
        assert shown, f"no hover label at x={x}"
        (lx, _), width = shown[-1], ps.imgui.CalcTextSize(label)[0]
        assert lx + width <= viewer.ui.overlay_right <= right
        if x + 16 + width <= right:
            assert lx == x + 16  # where it was when there is room
    # captions of side-by-side copies too (curvature side by side)
    viewer.set_panel("curvature")
    drive(viewer, "side by side", True)
    viewer.ui.overlays.clear()
    frames(viewer, 2)
    captions = viewer.ui.overlays
    assert captions
    for (cx, _), text in captions:
        assert 0 <= cx and cx + ps.imgui.CalcTextSize(text)[0] <= right
    drive(viewer, "side by side", False)


# ---------------------------------------------------------------- item 5: the primary's side
def test_the_primary_keeps_the_left_side_whichever_front_the_mesh_has(viewer, tmp_path):
    from meshlap_app.camera import project_to_screen
    from meshlap_app.scene import FRONT_VIEWS, MESH, MESH_B

    from meshlap_core import primitives
    from meshlap_core.io import save_mesh

    V, F = primitives.icosphere(2)
    V = V * np.array([2.0, 1.0, 0.5])  # not symmetric: the copy's width is the screen's
    # the default front (eye at -z) and a mesh known to face +z (its eye on the other side)
    names = ["blob.obj", next(iter(FRONT_VIEWS))]
    for name in names:
        path = tmp_path / name
        save_mesh(path, V, F)
        assert viewer.open(path)
        viewer.set_panel("curvature")
        frames(viewer)
        if not viewer.state.curv.side_by_side:
            drive(viewer, "side by side", True)
        frames(viewer, 2)
        params = ps.get_view_camera_parameters()
        w, h = ps.get_window_size()
        centres = np.array(
            [viewer.structure_points(n).mean(axis=0) for n in (MESH, MESH_B)], dtype=float
        )
        xy, front = project_to_screen(
            centres, params.get_view_mat(), params.get_fov_vertical_deg(), w, h
        )
        assert front.all()
        assert xy[0, 0] < xy[1, 0], f"{name}: the copy is left of the mesh"
    drive(viewer, "side by side", False)
