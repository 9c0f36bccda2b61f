"""The vertex inspector in the viewer: its geometry (headless) and its widgets (openGL_mock).

The geometry drawn in 3D is tied to the inspection it draws: the area cell's fan has the area
``A_i`` that ``inspect_vertex`` lists (itself checked against ``M_ii`` in
``tests/core/test_inspector.py``), the ring edges carry the listed weights, the arcs span the
corner angles. The widgets (area kind, boundary rule, hover) are driven through the UI adapter
with good and bad values; their driver, :func:`tests.support.drivers.onering.drive_inspector`,
is also part of the every-widget tour of ``tests/app/test_viewer_widgets.py``.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from meshlap_app.state import CurvatureState, MeshState
from meshlap_app.state.onering import (
    HoverThrottle,
    OneRingState,
    angle_arcs,
    area_cell,
    arrow_scales,
    cell_path,
    fan_area,
    weight_segments,
)

from meshlap_core import primitives
from meshlap_core.errors import MeshError
from meshlap_core.inspector import inspect_vertex
from meshlap_core.io import save_mesh
from tests.support.meshes import perturbed_grid

MESHES = {
    "grid": perturbed_grid,
    "sphere": lambda: primitives.icosphere(2),
    "bumpy": lambda: primitives.bumpy_sphere(),
}


# ---------------------------------------------------------------- geometry (headless)
@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize("kind", ["barycentric", "voronoi"])
def test_area_cell_has_the_listed_area(name, kind):
    V, F = MESHES[name]()
    for i in range(0, len(V), max(1, len(V) // 60)):
        ins = inspect_vertex(V, F, i, kind)
        nodes, tris, outline = area_cell(ins, V, F)
        assert fan_area(nodes, tris) == pytest.approx(ins.area, rel=1e-9)
        np.testing.assert_array_equal(nodes[0], V[i])
        # the outline is closed inside, and open (two spokes to x_i) on the boundary
        spokes = int(np.sum(outline[:, 0] == 0))
        assert spokes == (2 if ins.boundary else 0)


def test_voronoi_cell_rules_of_meyer_et_al():
    p, q = np.zeros(3), np.array([1.0, 0.0, 0.0])
    acute = cell_path(p, q, np.array([0.5, 0.8, 0.0]), "voronoi")
    assert len(acute) == 3  # through the circumcentre, equidistant from the corners
    cc = acute[1]
    assert np.linalg.norm(cc - p) == pytest.approx(np.linalg.norm(cc - q))
    obtuse_at_p = cell_path(p, q, np.array([-0.5, 0.3, 0.0]), "voronoi")
    np.testing.assert_allclose(obtuse_at_p[1], 0.5 * (q + np.array([-0.5, 0.3, 0.0])))
    obtuse_at_q = cell_path(p, q, np.array([1.2, 0.3, 0.0]), "voronoi")
    assert len(obtuse_at_q) == 2  # straight across: a quarter of the face
    bary = cell_path(p, q, np.array([0.5, 0.8, 0.0]), "barycentric")
    np.testing.assert_allclose(bary[1], (p + q + np.array([0.5, 0.8, 0.0])) / 3)


def test_weight_segments_carry_the_listed_weights():
    V, F = perturbed_grid()
    ins = inspect_vertex(V, F, 54)
    nodes, edges, w = weight_segments(ins, V)
    assert (w < 0).sum() == 2 and w.min() == pytest.approx(-0.5007, abs=1e-4)
    np.testing.assert_array_equal(w, [t.weight_cotan for t in ins.neighbors])
    for (a, b), t in zip(edges, ins.neighbors, strict=True):
        assert np.linalg.norm(nodes[b] - nodes[a]) == pytest.approx(t.edge_length)
        np.testing.assert_array_equal(nodes[a], V[54])


def test_angle_arcs_span_the_corner_angles():
    V, F = perturbed_grid()
    ins = inspect_vertex(V, F, 54)
    radius = 0.01
    nodes, edges, theta = angle_arcs(ins, V, F, radius, steps=64)
    np.testing.assert_allclose(np.linalg.norm(nodes - V[54], axis=1), radius, rtol=1e-12)
    seg = np.linalg.norm(nodes[edges[:, 1]] - nodes[edges[:, 0]], axis=1)
    # arc length = radius · θ summed over faces: the interior angle sum (chords, so just below)
    assert seg.sum() == pytest.approx(radius * ins.angle_sum, rel=1e-3)
    assert sorted(set(np.round(theta, 12))) == sorted(round(f.angle, 12) for f in ins.faces)


def test_arrow_scales():
    V, F = primitives.icosphere(2)
    ins = inspect_vertex(V, F, 0)
    s_n, s_lap = arrow_scales(ins, 0.2)
    assert s_n == 0.2
    assert np.linalg.norm(s_lap * ins.laplacian_cotan) == pytest.approx(0.2)
    Vg, Fg = primitives.grid(5, 5)
    flat = inspect_vertex(Vg, Fg, 12)  # interior of a flat grid: Δx = 0
    assert arrow_scales(flat, 0.2)[1] == 0.0


def test_hover_throttle_picks_once_the_cursor_rests():
    t = HoverThrottle(interval=0.1)
    assert not t.due(0.0, (10.0, 10.0))  # just arrived
    assert not t.due(0.05, (10.0, 10.0))
    assert t.due(0.1, (10.0, 10.0)) and t.current((10.0, 10.0))  # rested 0.1 s: pick
    assert not t.due(0.5, (10.0, 10.0))  # idle: picked there already
    for k in range(10):  # moving: no picking
        assert not t.due(0.5 + 0.05 * k, (11.0 + k, 10.0))
        assert not t.current((11.0 + k, 10.0))
    assert not t.due(0.99, (20.0, 10.0))
    assert t.due(1.06, (20.0, 10.0))
    assert not t.due(1.2, (20.0, 10.0))


def test_state_follows_area_and_boundary_rule(tmp_path):
    path = tmp_path / "grid.obj"
    save_mesh(path, *perturbed_grid())
    mesh, curv, ring = MeshState(), CurvatureState(), OneRingState()
    assert mesh.load(path)
    assert ring.select(mesh, curv, 0)  # a corner of the grid: boundary
    assert ring.inspection.boundary and ring.inspection.area_kind == "voronoi"  # the default
    ring.set_rules(mesh, curv, "barycentric", "pi")
    assert ring.inspection.area_kind == "barycentric" and curv.area == "barycentric"
    ring.set_rules(mesh, curv, "voronoi", "zero")
    assert (curv.area, curv.boundary) == ("voronoi", "zero")
    assert ring.inspection.area_kind == "voronoi" and ring.inspection.K == 0.0
    assert ring.K == pytest.approx(ring.inspection.K, abs=1e-12)  # the field agrees
    for area, rule in (("nonsense", "pi"), ("voronoi", "4pi"), ("", "")):
        with pytest.raises(MeshError):
            ring.set_rules(mesh, curv, area, rule)
        assert (curv.area, curv.boundary) == ("voronoi", "zero")  # nothing changed
    ring.select(mesh, curv, 54)
    ids = [t.index for t in ring.rows()]
    ring.toggle_reverse(mesh, curv)
    assert [t.index for t in ring.rows()] == ids[::-1]
    assert ids == [int(j) for j in ring.neighbors][::-1]


def test_isolated_vertex_has_no_inspection():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]])
    mesh = MeshState(V=V, F=np.array([[0, 1, 2]]), version=1)  # vertex 3 in no face
    curv, ring = CurvatureState(), OneRingState()
    assert ring.select(mesh, curv, 3)
    assert ring.inspection is None and "no face" in ring.inspection_error
    assert ring.rows() == []
    assert ring.select(mesh, curv, 0) and ring.inspection is not None


# ---------------------------------------------------------------- widgets (openGL_mock)
ps = pytest.importorskip("polyscope")

from meshlap_app import scene  # noqa: E402

from tests.support.drivers.onering import drive_inspector, inspector_names  # noqa: E402
from tests.support.widgets import FakeClock, drive  # noqa: E402


def test_inspector_widgets(viewer):
    drive_inspector(viewer)


def test_hover_shows_index_and_field_value(viewer, monkeypatch):
    viewer.set_panel("onering")
    drive(viewer, "vertex", 3)
    panel = viewer.panels["onering"]
    panel.clock, panel.throttle = (clock := FakeClock()), HoverThrottle()
    hit = SimpleNamespace(
        is_hit=True,
        structure_name=scene.MESH,
        structure_data={"element_type": "vertex", "index": 11},
        position=np.zeros(3),
    )
    calls = []

    def fake_pick(screen_coords):
        calls.append(tuple(screen_coords))
        return hit

    monkeypatch.setattr(ps, "pick", fake_pick)
    drive(viewer, "hover", (100.0, 80.0))
    clock.t = 0.1
    drive(viewer, "hover", (100.0, 80.0))
    assert "labels" not in viewer.state.errors, viewer.state.errors
    value = viewer.state.curv.fields[viewer.state.curv.field_name][11]
    assert panel.hovered == f"vertex 11: {viewer.state.curv.field_name} = {value:.4g}"
    drive(viewer, "hover", *[(100.0, 80.0)] * 5)  # idle frames: the answer stays, no picking
    assert len(calls) == 1 and panel.hovered.startswith("vertex 11")
    hit.structure_data = {"element_type": "face", "index": 0}
    drive(viewer, "hover", (101.0, 80.0))  # a face: its nearest corner, once rested
    assert len(calls) == 1
    clock.t = 1.0
    drive(viewer, "hover", (101.0, 80.0))
    assert len(calls) == 2 and panel.hovered.startswith("vertex ")
    assert int(panel.hovered.split()[1].rstrip(":")) in viewer.state.mesh.F[0]


def test_inspector_structures_follow_the_panel(viewer):
    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)
    nodes = ps.get_curve_network(scene.INSPECT_WEIGHTS).n_nodes()
    assert nodes == 1 + viewer.panels["onering"].state.valence
    drive(viewer, "vertex", 0)  # a selection change updates the drawings
    assert (
        ps.get_curve_network(scene.INSPECT_WEIGHTS).n_nodes()
        == 1 + viewer.panels["onering"].state.valence
    )
    viewer.set_panel("curvature")
    assert not inspector_names()  # removed when leaving the panel
    viewer.set_panel("onering")
    assert scene.INSPECT_WEIGHTS in inspector_names()  # back with the panel
    assert scene.INSPECT_NEGATIVE not in inspector_names()  # the icosphere: no w < 0


def test_negative_weights_drawn_and_listed(viewer, tmp_path):
    path = tmp_path / "grid.obj"
    save_mesh(path, *perturbed_grid())
    assert viewer.open(path)
    viewer.set_panel("onering")
    shown: list[tuple[str, object]] = []
    ui = viewer.ui
    real_colored, real_text = ui.colored, ui.text
    ui.colored = lambda text, rgba: (shown.append((text, rgba)), real_colored(text, rgba))
    ui.text = lambda text: (shown.append((text, None)), real_text(text))
    try:
        drive(viewer, "vertex", 54)
    finally:
        del ui.colored, ui.text
    neg = ps.get_curve_network(scene.INSPECT_NEGATIVE)
    assert neg.n_edges() == 2
    flagged = ui.tables[("onering", "weights")].flagged()  # the magenta rows of the table
    assert sorted(r[0] for r in flagged) == ["43", "65"] and all(
        r[4].startswith("-") for r in flagged
    )
    assert any(t.startswith("K = deficit / A_i") for t, _ in shown)
    assert any(t.startswith("L_cotan x = (1/A_i)") for t, _ in shown)
    assert any("magenta edges: negative w_ij (2)" in t for t, _ in shown)
    assert math.isfinite(viewer.panels["onering"].state.inspection.H_cotan)


def test_non_manifold_vertex_lists_its_fans(viewer, tmp_path):
    path = tmp_path / "bowtie.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n")
    assert viewer.open(path)
    viewer.set_panel("onering")
    shown: list[str] = []
    real_error = viewer.ui.error
    viewer.ui.error = lambda text: (shown.append(text), real_error(text))
    try:
        drive(viewer, "vertex", 0)
    finally:
        del viewer.ui.error
    assert (
        viewer.panels["onering"].state.inspection is not None
        and not viewer.panels["onering"].state.inspection.manifold
    )
    assert any("non-manifold vertex: 2 fans" in t for t in shown)
