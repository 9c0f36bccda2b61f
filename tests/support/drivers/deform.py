"""The Deform view's widgets: handles and fixed discs by click, the gizmo and a screen-plane
drag, every method side by side, the colour, region and ARAP settings, undo/redo, reset; and
the real-window tour's step (:func:`drag_a_handle`)."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import polyscope as ps
import pytest
from meshlap_app.registry import VIEWS

from meshlap_core.deform import make_deformer
from tests.support.imgui_screen import Layout, changed_fraction, subject_mask, subject_point
from tests.support.widgets import drive, frames
from tests.support.window_session import WAIT, Session, scene_box


def settle(viewer) -> None:
    """Wait for the panel's jobs, then frames until nothing is due (ARAP converged)."""
    st = viewer.panels["deform"].state
    t0 = time.monotonic()
    while viewer.state.jobs.running("deform") is not None or st.due():
        assert time.monotonic() - t0 < 120, "the deform panel never settled"
        viewer.state.jobs.wait("deform", 1.0)
        frames(viewer, 1)
    frames(viewer, 1)


def press(viewer, vertex: int, *held: str, structure: str = "deformed") -> None:
    """A scripted press on the scene that polyscope's pick answers with ``vertex`` of the
    deformed copy (the modifier keys ``held``)."""
    P = viewer.panels["deform"]._positions(viewer, viewer.panels["deform"].state.methods[0])
    hit = SimpleNamespace(
        is_hit=True,
        structure_name=structure,
        structure_data={"element_type": "vertex", "index": vertex},
        position=P[vertex],
    )
    real = ps.pick
    ps.pick = lambda screen_coords: hit
    try:
        viewer.ui.script("click", (10.0, 10.0, *held))
        frames(viewer, 1)
    finally:
        ps.pick = real


def click(viewer, vertex: int, *held: str) -> None:
    """A press and a release in place: a click (the release is read on the next frame)."""
    press(viewer, vertex, *held)
    frames(viewer, 1)


def drive_panel_deform(viewer, tmp_path=None) -> None:
    """Every widget of the Deform panel, with good and bad values."""
    V, F = viewer.state.mesh.V, viewer.state.mesh.F
    panel = viewer.panels["deform"]
    st = panel.state
    viewer.set_panel("deform")
    frames(viewer)
    assert ps.has_surface_mesh("deformed") and not ps.has_surface_mesh("deform handles")
    click(viewer, 7)
    settle(viewer)
    assert st.handles == [7] and st.built is not None and ps.has_point_cloud("deform handles")
    np.testing.assert_allclose(st.shown["arap"].positions, V, atol=1e-9)  # nothing moved yet
    click(viewer, 100, "shift")  # one more handle
    settle(viewer)
    assert st.handles == [7, 100] and st.active == 1
    click(viewer, 150, "ctrl")  # a fixed disc: the region becomes "clicked"
    settle(viewer)
    assert st.fixed == [150] and st.fixed_region == "clicked"
    assert set(st.built.fixed.tolist()) >= {150}

    # the gizmo: moved as a user drags it (translation and a turn), the handle follows
    gizmo = panel.gizmo
    assert gizmo.shown
    T = gizmo.transform()
    T2 = T.copy()
    T2[:3, 3] += [0.0, 0.2, 0.0]
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    T2[:3, :3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ T[:3, :3]
    gizmo.set_transform(T2)
    frames(viewer, 1)
    m = st.moves[1]
    assert m["rotate"][3] == pytest.approx(30.0, abs=1e-3)
    d = viewer.state.display
    assert np.asarray(m["move"]) @ (d.rotation.T @ [0, 1, 0]) == pytest.approx(0.2 / d.scale)
    settle(viewer)
    b = st.built
    ref = make_deformer("arap", V, F, b.regions.vertices, b.fixed)
    ref.set_targets(st.targets("arap"))
    ref.run(b.deformers["arap"].iteration)
    np.testing.assert_allclose(st.shown["arap"].positions, ref.positions, atol=1e-9)
    moved = np.array(st.shown["arap"].positions)
    assert np.abs(moved - V).max() > 0.1

    # a handle dragged with the mouse in the screen plane (the camera stays put)
    seed = st.handles[0]
    press(viewer, seed)
    assert panel._drag is not None and st.active == 0
    drive(viewer, "scene drag", (10.0, 10.0, True), (60.0, 10.0, True), (60.0, 10.0, False))
    assert panel._drag is None
    assert np.linalg.norm(st.moves[0]["move"]) > 0  # moved, along the screen's x
    settle(viewer)
    undo_depth = len(st.undo_stack)

    for method in ("laplacian", "harmonic", "biharmonic", "triharmonic", "arap"):
        drive(viewer, "method", method)
        settle(viewer)
        assert st.handles == [7, 100] and method in st.shown  # the handles stay
    drive(viewer, "side by side", "biharmonic")
    settle(viewer)
    assert ps.has_surface_mesh("deformed (second method)")
    assert panel.captions(viewer) == {"deformed": "arap", "deformed (second method)": "biharmonic"}
    drive(viewer, "colour", "rotation error")
    err = st.field("arap")
    assert st.colour == "rotation error" and np.isfinite(err).all() and float(err.max()) > 0
    drive(viewer, "colour", "displacement")
    drive(viewer, "handle radius %", 8.0, 99.0)
    settle(viewer)
    assert st.radius == 50.0  # clamped
    drive(viewer, "handle radius %", 6.0)
    drive(viewer, "fixed region", "farthest")
    drive(viewer, "farthest share", 0.2, 0.0)
    assert st.fixed_fraction == 0.01  # not 0: a region to hold
    drive(viewer, "farthest share", 0.15)
    settle(viewer)
    drive(viewer, "ARAP energy", "spokes-and-rims")
    drive(viewer, "ARAP iterations per frame", 5, 0)
    assert st.arap_per_frame == 1  # clamped
    drive(viewer, "ARAP iterations per move", 50)
    for bad in (0, -3, "abc"):
        drive(viewer, "ARAP iterations per move", bad)
        assert st.arap_max == 50
    settle(viewer)
    f = st.figures("arap")
    assert 0 < f["iteration"] <= 50 and f["n_unknowns"] > 0 and f["factor_seconds"] >= 0
    table = viewer.ui.tables[("deform", "deform numbers")]
    assert table.headers == ["", "arap", "biharmonic"]
    assert table.column("arap")[0] == f"{f['energy']:.4g}"
    assert "ARAP energy" in viewer.ui.legend_at  # the energy against the iterations, plotted
    drive(viewer, "turn (deg)", 45.0, float("nan"))
    assert st.moves[st.active]["rotate"][3] == 45.0
    assert "turn" in st.error
    drive(viewer, "turn (deg)", 20.0)
    assert st.error == ""
    settle(viewer)
    before = [dict(m) for m in st.moves]
    drive(viewer, "undo", True)
    assert st.moves != before
    drive(viewer, "redo", True)
    assert st.moves == before
    assert len(st.undo_stack) > undo_depth
    drive(viewer, "key z", True)
    drive(viewer, "key y", True)
    assert st.moves == before
    drive(viewer, "reset", True)
    settle(viewer)
    np.testing.assert_allclose(st.shown["arap"].positions, V, atol=1e-6)
    drive(viewer, "key r", True)
    drive(viewer, "clear handles", True)
    frames(viewer, 2)
    assert st.handles == [] and not ps.has_point_cloud("deform handles")
    drive(viewer, "side by side", "none")


# ------------------------------------------------------------------ the real window's step
DEFORM_KEY = str(VIEWS.index("deform") + 1)  # the view's number key


def top_row(img: np.ndarray, layout: Layout) -> int:
    """The highest row of the mesh on screen (its silhouette's top)."""
    rows = np.flatnonzero(subject_mask(img, layout).any(axis=1))
    return int(rows[0]) if len(rows) else img.shape[0]


def handle_dots(img: np.ndarray, layout: Layout) -> int:
    """Pixels of the handle's disc drawn in yellow (the active handle's points) on the mesh."""
    c = img[:, : layout.left].astype(np.int16)
    r, g, b = c[..., 0], c[..., 1], c[..., 2]
    return int(((r > 200) & (g > 150) & (b < 80)).sum())


def drag_a_handle(s: Session) -> None:
    """The deform step of a tour (``tests/window/test_tour.py``'s): the view's key, a click on
    the mesh (a handle: its disc drawn), the handle dragged up (the mesh's top rises, its held
    bottom stays), Z (the rest shape back)."""
    layout = s.goto(int(DEFORM_KEY), "Deform")
    scene = scene_box(s, layout)
    before = s.settled(scene)
    s.screenshot("deform_opened")
    assert handle_dots(before, layout) < 20, "a handle drawn before any click"
    point = subject_point(before, layout)
    assert point is not None, "no mesh to click left of the panel"
    s.click(point)  # press and release in place: a click, the vertex becomes a handle
    s.until(
        lambda img: handle_dots(img, layout) >= 20,
        2 * WAIT,
        f"the handle's disc drawn after a click at {point}",
    )
    one = s.settled(scene)
    s.screenshot("deform_handle")
    rest_top = top_row(one, layout)
    # press on the handle's disc (beside its centre, where the gizmo's arrows start) and drag
    # it up: it follows the mouse in the screen plane, the mesh follows it
    a = (point[0] + 4, point[1] + 4)
    s.drag(a, (a[0], a[1] - 120), steps=8)
    s.until(
        lambda img: top_row(img, layout) < rest_top - 20,
        2 * WAIT,
        "the mesh's top rising after dragging the handle up",
    )
    # ARAP iterates live (one iteration a frame, up to 200 a move): a software-rendered
    # 1920x1080 window draws two frames a second, so the shape settles in up to ~100 s
    moved = s.settled(scene, timeout=300)
    s.screenshot("deform_dragged")
    assert changed_fraction(one, moved, scene) > 0.01
    h = s.size[1]
    low = (0, int(0.85 * h), layout.left, h)  # the held bottom (and its shadow) stays
    assert changed_fraction(one, moved, low) < 0.05
    s.key("z")  # undo the drag: the rest shape comes back
    back = s.until(
        lambda img: abs(top_row(img, layout) - rest_top) <= 3,
        2 * WAIT,
        "the rest shape back after Z (undo)",
    )
    s.screenshot("deform_undone")
    assert changed_fraction(one, back, scene) < changed_fraction(one, moved, scene)


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path) -> None:
    """A handle clicked and turned: the deformed copy with its displacement field."""
    click(viewer, 7)
    settle(viewer)
    drive(viewer, "turn (deg)", 30.0)
    settle(viewer)
