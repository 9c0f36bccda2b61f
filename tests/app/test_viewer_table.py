"""The vertex inspector's tables: the UI adapter's table API and what the one-ring panel lists.

On polyscope's openGL_mock backend the adapter records every table it draws (headers, every
row's cells as shown, flagged and highlighted rows); the tests tie each cell to the number
:func:`meshlap_core.inspector.inspect_vertex` computes (itself tied to the global operators in
``test_inspector.py``), and the sums of the columns to the vertex's own quantities (``Σ w_ij
(x_j − x_i) = A_i Δx``, ``Σ shares = A_i``). With EGL (real fonts), the tables must fit the
panel's text width at 1280×720, UI scale 1 and 2.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from meshlap_app.text_numbers import is_number

from meshlap_core.inspector import inspect_vertex
from meshlap_core.io import save_mesh

ps = pytest.importorskip("polyscope")

from meshlap_app import scene  # noqa: E402
from meshlap_app.panels.onering import NEGATIVE_RGBA  # noqa: E402
from meshlap_app.state.onering import HoverThrottle  # noqa: E402
from meshlap_app.text_numbers import sig  # noqa: E402

from tests.support.meshes import perturbed_grid  # noqa: E402
from tests.support.scripted_ui import ScriptedUI, TableRecord  # noqa: E402
from tests.support.widgets import FakeClock, drive  # noqa: E402

VERTEX = 54  # the README's inspector vertex: two negative weights (rows 65 and 43)


def num(cell: str) -> float:
    return float(cell.rstrip("°"))


# ---------------------------------------------------------------- the adapter
def test_is_number():
    for cell in ("0", "-0.5007", "38.07°", "1e-05", "-", " 12 "):
        assert is_number(cell), cell
    for cell in ("yes", "A/2", "at i", "sum", "", "°"):
        assert not is_number(cell), cell


def test_table_records_what_it_draws_and_stays_balanced(mock):
    ui = ScriptedUI()
    ui.begin_section("test")
    errors: list[Exception] = []

    def callback():
        with ui.table("t", ["j", "w", "note"], ["index", "weight", ""]) as shown:
            assert shown
            ui.row(["3", "-0.5", "obtuse"], NEGATIVE_RGBA)
            ui.row(["4", "1.25"], highlight=True)  # fewer cells: the rest stay empty
        try:
            with ui.table("broken", ["a"]):
                ui.row(["1"])
                raise ValueError("a handler failed")  # EndTable and the colours still pop
        except ValueError as exc:
            errors.append(exc)
        for bad in (lambda: ui.row(["1"]), lambda: None):
            try:
                bad()
            except RuntimeError as exc:
                errors.append(exc)
        try:
            with ui.table("narrow", ["a"]):
                ui.row(["1", "2"])
        except RuntimeError as exc:
            errors.append(exc)

    ps.set_user_callback(callback)
    for _ in range(3):  # imgui would abort on an unbalanced Begin/End or style stack
        ps.frame_tick()
    ps.clear_user_callback()
    rec = ui.tables[("test", "t")]
    assert isinstance(rec, TableRecord)
    assert rec.headers == ["j", "w", "note"] and rec.tips == ["index", "weight", ""]
    assert rec.rows == [["3", "-0.5", "obtuse"], ["4", "1.25"]]  # the last frame's only
    assert rec.flagged() == [["3", "-0.5", "obtuse"]] and rec.colors[0] == NEGATIVE_RGBA
    assert rec.highlighted == [1] and rec.column("w") == ["-0.5", "1.25"]
    assert ui.tables[("test", "broken")].rows == [["1"]]
    kinds = [type(e).__name__ for e in errors]
    assert kinds == ["ValueError", "RuntimeError", "RuntimeError"] * 3
    assert "outside a ui.table()" in str(errors[1]) and "2 cells for 1 columns" in str(errors[2])
    assert not ui.seen  # a table is not an interactive widget: nothing for the tour to drive


# ---------------------------------------------------------------- the inspector's tables
@pytest.fixture
def grid_viewer(viewer, tmp_path):
    path = tmp_path / "grid.obj"
    save_mesh(path, *perturbed_grid())
    assert viewer.open(path)
    viewer.set_panel("onering")
    drive(viewer, "vertex", VERTEX)
    return viewer


def tables(viewer) -> tuple[TableRecord, TableRecord, TableRecord | None]:
    """The weights, contributions and faces tables (the last one only once its header, closed
    by default, was opened)."""
    t = viewer.ui.tables
    return t[("onering", "weights")], t[("onering", "contributions")], t.get(("onering", "faces"))


def test_weights_table_lists_inspect_vertex(grid_viewer):
    v = grid_viewer
    drive(v, "incident faces", True)  # (closed by default) the faces table is drawn too
    ins = inspect_vertex(*perturbed_grid(), VERTEX)
    weights, _, _ = tables(v)
    assert weights.headers == ["j", "|x_j - x_i|", "alpha", "beta", "w_ij", "1/|N|"]
    assert len(weights.tips) == len(weights.headers) and all(weights.tips)
    assert [int(r[0]) for r in weights.rows] == [t.index for t in ins.neighbors]  # ring order
    scale = max(abs(t.weight_cotan) for t in ins.neighbors)
    for row, t in zip(weights.rows, ins.neighbors, strict=True):
        assert num(row[1]) == pytest.approx(t.edge_length, rel=5e-4)
        assert num(row[2]) == pytest.approx(math.degrees(t.alpha), abs=0.0051)
        assert num(row[3]) == pytest.approx(math.degrees(t.beta), abs=0.0051)
        assert row[2].endswith("°") and row[3].endswith("°")
        assert row[4] == sig(t.weight_cotan, scale)  # the panel's 4 significant digits
        assert num(row[4]) == pytest.approx(t.weight_cotan, rel=5e-4)
        assert num(row[5]) == pytest.approx(1 / 6, rel=5e-4) == t.weight_uniform
    # negative weights: exactly the inspector's, drawn in the 3D view's magenta
    flagged = weights.flagged()
    assert sorted(r[0] for r in flagged) == ["43", "65"]
    assert {r[0] for r in flagged} == {str(t.index) for t in ins.neighbors if t.negative}
    assert all(num(r[4]) < 0 for r in flagged)
    assert all(c == (*scene.NEGATIVE_COLOR, 1.0) for c in weights.colors if c is not None)
    assert weights.highlighted == []  # nothing hovered


def test_contributions_sum_to_area_times_laplacian(grid_viewer):
    ins = inspect_vertex(*perturbed_grid(), VERTEX)
    _, contrib, _ = tables(grid_viewer)
    assert contrib.headers == ["j", "x", "y", "z"]
    *rows, total = contrib.rows
    size = max(float(np.abs(t.contribution).max()) for t in ins.neighbors)
    for row, t in zip(rows, ins.neighbors, strict=True):
        assert int(row[0]) == t.index
        np.testing.assert_allclose([num(c) for c in row[1:]], t.contribution, rtol=5e-4)
        assert row[1:] == [sig(float(c), size) for c in t.contribution]
    assert total[0] == "sum"
    # the sum row is A_i Δ_cotan x: the Lx formula's numerator
    np.testing.assert_allclose(
        [num(c) for c in total[1:]], ins.area * ins.laplacian_cotan, rtol=5e-4, atol=1e-12
    )
    assert sorted(r[0] for r in contrib.flagged()) == ["43", "65"]


def test_faces_table_lists_inspect_vertex(grid_viewer):
    drive(grid_viewer, "incident faces", True)
    ins = inspect_vertex(*perturbed_grid(), VERTEX)
    _, _, faces = tables(grid_viewer)
    assert faces.headers == ["face", "theta_f", "area", "obtuse", "A_f/3", "Voronoi", "rule"]
    assert [int(r[0]) for r in faces.rows] == [f.face for f in ins.faces]
    for row, f in zip(faces.rows, ins.faces, strict=True):
        assert num(row[1]) == pytest.approx(math.degrees(f.angle), abs=0.0051)
        assert num(row[2]) == pytest.approx(f.area, rel=5e-4)
        assert row[3] == ("at i" if f.obtuse_at_vertex else "yes" if f.obtuse else "no")
        assert num(row[4]) == pytest.approx(f.share_barycentric, rel=5e-4)
        assert num(row[5]) == pytest.approx(f.share_voronoi, rel=5e-4)
        assert row[6] == ("A/2" if f.obtuse_at_vertex else "A/4" if f.obtuse else "cot")
    # the shares add up to the vertex's areas (the A_i line of the formulas)
    assert sum(num(r[4]) for r in faces.rows) == pytest.approx(ins.area_barycentric, rel=2e-3)
    assert sum(num(r[5]) for r in faces.rows) == pytest.approx(ins.area_voronoi, rel=2e-3)
    angles = sum(num(r[1]) for r in faces.rows)
    assert angles == pytest.approx(math.degrees(ins.angle_sum), abs=0.03)
    assert any(r[3] == "at i" for r in faces.rows)  # this vertex has an obtuse corner


def test_clockwise_and_boundary_rows(grid_viewer):
    v = grid_viewer
    ids = [r[0] for r in tables(v)[0].rows]
    drive(v, "clockwise (reverse)", True)
    assert [r[0] for r in tables(v)[0].rows] == ids[::-1]
    assert [r[0] for r in tables(v)[1].rows[:-1]] == ids[::-1]
    drive(v, "clockwise (reverse)", False)
    drive(v, "vertex", 0)  # a corner of the grid: its two boundary edges have one face each
    ins = inspect_vertex(*perturbed_grid(), 0)
    betas = [r[3] for r in tables(v)[0].rows]
    assert betas == [
        "-" if t.beta is None else f"{math.degrees(t.beta):.2f}°" for t in ins.neighbors
    ]
    assert betas.count("-") == 2


def test_hovered_neighbour_row_is_lit(grid_viewer, monkeypatch):
    v = grid_viewer
    panel = v.panels["onering"]
    panel.clock, panel.throttle = (clock := FakeClock()), HoverThrottle()
    target = 65
    hit = type(
        "Hit",
        (),
        {
            "is_hit": True,
            "structure_name": scene.MESH,
            "structure_data": {"element_type": "vertex", "index": target},
            "position": np.zeros(3),
        },
    )()
    monkeypatch.setattr(ps, "pick", lambda screen_coords: hit)
    drive(v, "hover", (100.0, 80.0))
    clock.t = 0.1
    drive(v, "hover", (100.0, 80.0), (100.0, 80.0))  # picked, then drawn lit
    weights, contrib, _ = tables(v)
    row = [r[0] for r in weights.rows].index(str(target))
    assert weights.highlighted == [row] and contrib.highlighted == [row]
    assert panel.hovered.startswith(f"vertex {target}")
    drive(v, "hover", (300.0, 80.0), (300.0, 80.0))  # moving: the label and the light go
    assert tables(v)[0].highlighted == []
    hit.structure_data = {"element_type": "vertex", "index": VERTEX}  # the vertex itself
    clock.t = 1.0
    drive(v, "hover", (300.0, 80.0), (300.0, 80.0))
    assert panel.hovered.startswith(f"vertex {VERTEX}") and tables(v)[0].highlighted == []


# ---------------------------------------------------------------- real fonts (EGL)
WIDTH_SCRIPT = """
import json, sys
from pathlib import Path
import polyscope as ps
from meshlap_app import scene
from meshlap_app.state import AppState, CurvatureState, MeshState
from meshlap_app.viewer import Viewer, init_polyscope
from tests.support.scripted_ui import ScriptedUI

mesh = MeshState(); assert mesh.load(Path(sys.argv[1]))
init_polyscope("openGL3_egl")
ps.set_window_size(1280, 720)
viewer = Viewer(AppState(mesh=mesh, panel="onering"), ui=ScriptedUI())
ps.set_build_default_gui_panels(False)
scale = float(sys.argv[2])
if scale != 1.0:
    viewer.set_ui_scale(scale)
viewer.sync_mesh()
viewer.panels["onering"].select(viewer, int(sys.argv[3]))
ps.set_user_callback(viewer.callback)
viewer.ui.script("incident faces", *[True] * 3)
for _ in range(3):
    ps.frame_tick()
out = {f"{k[0]}/{k[1]}": [r.width, r.avail] for k, r in viewer.ui.tables.items()}
out["wrap"] = viewer.ui.wrap_width * viewer.ui.scale
print(json.dumps(out))
"""


@pytest.mark.egl
@pytest.mark.parametrize("scale", [1.0, 2.0])
def test_tables_fit_the_panel_with_real_fonts(tmp_path, scale, python_ok):
    mesh = tmp_path / "grid.obj"
    save_mesh(mesh, *perturbed_grid())
    res = python_ok("-c", WIDTH_SCRIPT, mesh, scale, VERTEX, timeout=300)
    sizes = json.loads(res.stdout.strip().splitlines()[-1])
    wrap = sizes.pop("wrap")
    assert set(sizes) == {"onering/weights", "onering/contributions", "onering/faces"}
    for name, (width, avail) in sizes.items():
        # drawn with real glyphs, and no wider than the panel's text (nor the room it had)
        assert 100 * scale < width <= min(wrap, avail), (name, width, wrap, avail)
