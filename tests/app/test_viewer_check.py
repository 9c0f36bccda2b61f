"""The Check panel: its state headless, its widgets through the UI adapter (openGL_mock).

Its driver, :func:`tests.support.drivers.check.drive_panel_check`, is also part of the
every-widget tour of ``tests/app/test_viewer_widgets.py``.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from meshlap_app.state.check import VIEWER_TASKS, CheckState

from meshlap_core import primitives
from meshlap_core.errors import MeshError
from meshlap_core.exercises.tasks import EXERCISE_TASKS
from meshlap_core.laplacian import cotan_stiffness, mass_matrix, vertex_areas
from tests.support.students import STUDENTS


# ---------------------------------------------------------------- state (no polyscope)
def test_state_checks_the_file_the_task_and_the_vertex(tmp_path):
    st = CheckState()
    with pytest.raises(MeshError, match="type the path"):
        st.student_path(tmp_path)
    st.file = "missing.py"
    with pytest.raises(MeshError, match="does not exist"):
        st.student_path(tmp_path)
    (tmp_path / "notes.txt").write_text("x")
    st.file = "notes.txt"
    with pytest.raises(MeshError, match="not a Python file"):
        st.student_path(tmp_path)
    with pytest.raises(MeshError, match="eigenbasis"):
        st.set_task("eigenbase")  # the message lists the choices
    assert st.task == "cotan_laplacian"
    assert VIEWER_TASKS == EXERCISE_TASKS  # the panel shows every task meshlap check checks
    with pytest.raises(MeshError, match="out of range"):
        st.select(10, 10)
    assert st.rows() == [] and st.verdict() == []


def test_state_rows_put_the_student_beside_the_reference():
    V, F = primitives.icosphere(1)
    check = CheckState.compute(STUDENTS / "wrong_cotan_full.py", "cotan_laplacian", V, F)
    st = CheckState()
    st.adopt(check, (0, "f", "cotan_laplacian"))
    st.select(3, len(V))
    C = cotan_stiffness(V, F)
    rows = st.rows()
    assert [r[0] for r in rows] == [f"[3,{j}]" for j in sorted(C[3].indices)]
    for term, mine, ref in rows:
        j = int(term.split(",")[1][:-1])
        assert float(ref) == pytest.approx(C[3, j], rel=1e-5)
        assert float(mine) == pytest.approx(2 * C[3, j], rel=1e-5)  # cot instead of cot/2
    # the difference map: the row's largest |student − reference| = the row's largest |C_ij|
    assert np.allclose(check.difference, abs(C).max(axis=1).toarray().ravel())
    assert st.verdict()[0].startswith("cotan_laplacian") and "cot/2" in "\n".join(st.verdict())


def test_heat_distance_on_the_mesh_on_screen():
    """The heat-method task in the viewer: a missing shift is diagnosed, and its map is one
    constant, φ[source] = −d[0] (the student pinned φ at vertex 0 and did not shift)."""
    assert "heat_geodesic" in VIEWER_TASKS
    V, F = primitives.icosphere(2)
    check = CheckState.compute(STUDENTS / "wrong_heat_shift.py", "heat_geodesic", V, F)
    assert check.result.tasks[0].diagnosis == "not_shifted" and check.signed
    d = check.difference
    assert np.ptp(d) < 1e-9 * np.abs(check.expected).max() and abs(d[0]) > 0.1
    np.testing.assert_allclose(d[0], -check.expected[0], rtol=1e-9)  # φ pinned at vertex 0


def _generalized_pairs(V, F, k):
    """Dense ``K u = λ M u`` from the core's operators (the test's own reference)."""
    import scipy.linalg as sla

    K = -cotan_stiffness(V, F).toarray()
    lam, U = sla.eigh(K, mass_matrix(V, F, "voronoi").toarray())
    return lam[:k], U[:, :k]


def test_eigenbasis_on_the_mesh_on_screen():
    """The eigenbasis in the viewer (642 vertices: above the dense size, so the reference is the
    lab's sparse solver): the ordinary eigenproblem is diagnosed, the rows put λ_j and u_j[i]
    beside the reference's, and the map is |u_j − u_ref,j| with the basis aligned; a right file
    gets the same rows as the reference (its basis of the triple λ = 2 rotated onto ours)."""
    V, F = primitives.icosphere(3)
    lam, _ = _generalized_pairs(V, F, 6)
    wrong = CheckState.compute(STUDENTS / "wrong_spectral.py", "eigenbasis", V, F)
    assert wrong.result.tasks[0].diagnosis == "ordinary_eigenproblem" and not wrong.signed
    st = CheckState()
    st.adopt(wrong, (0, "f", "eigenbasis"))
    st.select(7, len(V))
    rows = st.rows()
    assert [r[0] for r in rows[:4]] == ["λ0", "u0[7]", "λ1", "u1[7]"]
    np.testing.assert_allclose([float(r[2]) for r in rows[::2]], lam, rtol=1e-5, atol=1e-5)
    # the student's λ are those of K u = λ u: the Euclidean problem's
    import scipy.linalg as sla

    plain = sla.eigvalsh(-cotan_stiffness(V, F).toarray())[:6]
    np.testing.assert_allclose([float(r[1]) for r in rows[::2]], plain, rtol=1e-5, atol=1e-9)
    d = wrong.difference
    assert d.shape == (len(V),) and d.min() > 0.05  # u0 is constant: 1/√area vs 1/√n
    right = CheckState.compute(STUDENTS / "right_igl.py", "eigenbasis", V, F)
    assert right.result.passed
    # u0..u3: whole eigenspaces (λ = 0, and λ = 2 three times); u4, u5 are two of the five
    # of the next λ, whose choice no alignment can undo
    mine = np.array([float(r[1]) for r in right.rows(7)[1:8:2]])
    np.testing.assert_allclose(mine, [float(r[2]) for r in right.rows(7)[1:8:2]], atol=1e-5)
    m = vertex_areas(V, F, "voronoi")
    assert abs(float(right.rows(7)[1][2])) == pytest.approx(1 / np.sqrt(m.sum()), rel=1e-5)


def test_reconstruction_on_the_mesh_on_screen():
    """Uᵀ X instead of Uᵀ M X in the viewer: diagnosed, and the map is the row's largest
    |student − reference|, computed here from the test's own dense basis."""
    V, F = primitives.icosphere(2)
    check = CheckState.compute(STUDENTS / "wrong_spectral.py", "spectral_reconstruction", V, F)
    t = check.result.tasks[0]
    assert t.diagnosis == "projection_without_mass"
    _, U = _generalized_pairs(V, F, 10)
    M = mass_matrix(V, F, "voronoi")
    ref, mine = U @ (U.T @ (M @ V)), U @ (U.T @ V)
    np.testing.assert_allclose(check.difference, np.abs(mine - ref).max(axis=1), rtol=1e-6)
    rows = check.rows(4)
    assert [r[0] for r in rows] == ["x", "y", "z"]
    np.testing.assert_allclose([float(r[2]) for r in rows], ref[4], rtol=1e-5, atol=1e-9)


# ---------------------------------------------------------------- widgets (openGL_mock)
ps = pytest.importorskip("polyscope")

from meshlap_app.scene import MESH  # noqa: E402

from tests.support import widgets  # noqa: E402
from tests.support.drivers.check import drive_panel_check  # noqa: E402
from tests.support.legend_ledger import Ledger  # noqa: E402
from tests.support.students import ONE_VERTEX_WRONG, facing_vertex  # noqa: E402
from tests.support.widgets import drive  # noqa: E402


def test_check_widgets(viewer, tmp_path):
    drive_panel_check(viewer, tmp_path)


def test_difference_map_has_its_colour_bar_only_in_this_view(viewer, monkeypatch):
    ledger = Ledger().install(monkeypatch)
    viewer.set_panel("check")
    drive(viewer, "student file", str(STUDENTS / "wrong_curvature.py"))
    drive(viewer, "task", "mean_curvature")
    drive(viewer, "check", True)
    widgets.frames(viewer, 2)
    from meshlap_app.state.check import difference_title

    title = difference_title("mean_curvature", True)
    assert title == "mean_curvature: student - reference [1/length]"
    q = ledger.quantities[MESH][title]
    assert q.enabled and q.colorbar and q.owner == "check"
    lo, hi = q.vminmax
    assert lo == -hi and hi > 0  # a signed scalar per vertex: a symmetric range around 0
    d = viewer.panels["check"].state.check.difference
    assert np.isclose(hi, np.abs(d).max())
    viewer.set_panel("curvature")
    widgets.frames(viewer, 2)
    assert title not in ledger.quantities.get(MESH, {})


def test_a_click_selects_the_vertex_in_this_view_only(viewer):
    panel = viewer.panels["check"]
    hit = SimpleNamespace(
        structure_name=MESH, structure_data={"element_type": "vertex", "index": 9}, position=None
    )
    assert not panel.pick(viewer, hit, viewer.panels["curvature"])
    assert panel.pick(viewer, hit, panel) and panel.state.vertex == 9


def test_a_saved_session_reopens_the_check(viewer, tmp_path):
    """Saved with a check shown, a session runs it again on load (file, task, vertex, map);
    a student file missing on this machine is said in red and the session still opens."""
    from meshlap_app import session

    viewer.set_panel("check")
    drive(viewer, "student file", str(STUDENTS / "wrong_cotan_full.py"))
    drive(viewer, "check", True)
    drive(viewer, "vertex", 5)
    saved = session.capture(viewer)
    assert saved.settings["check"] == {
        "file": str(STUDENTS / "wrong_cotan_full.py"),
        "task": "cotan_laplacian",
        "vertex": 5,
        "checked": True,
        "isolines": {},
    }
    path = session.save(viewer, tmp_path / "lesson.json")
    st = viewer.panels["check"].state
    st.file, st.check, st.vertex = "", None, -1
    session.load(viewer, path)
    widgets.frames(viewer, 2)
    assert st.check is not None and st.current(viewer.state.mesh.version)
    assert st.check.result.tasks[0].diagnosis == "cot_not_half" and st.vertex == 5
    assert st.rows() and session.capture(viewer).settings["check"] == saved.settings["check"]

    moved = saved.settings["check"] | {"file": str(tmp_path / "gone.py")}
    other = session.Session(
        mesh=saved.mesh, panel="check", settings=saved.settings | {"check": moved}
    )
    session.apply(viewer, other, "moved.json", resize=False)
    assert "does not exist" in viewer.state.errors["check"]
    assert not st.current(viewer.state.mesh.version)
    assert st.file == moved["file"] and st.vertex == 5


# ---------------------------------------------------------------- real pixels (EGL)

EGL_CHECK_SCRIPT = """
import json, sys, time
from pathlib import Path

import numpy as np
import polyscope as ps
from meshlap_app.camera import project_to_screen
from meshlap_app.scene import save_screenshot
from meshlap_app.state import AppState, MeshState
from meshlap_app.viewer import Viewer, init_polyscope

if __name__ == "__main__":
    mesh = MeshState(); mesh.load(None)
    init_polyscope("openGL3_egl")
    viewer = Viewer(AppState(mesh=mesh, panel="check"))
    viewer.sync_mesh()
    ps.set_user_callback(viewer.callback)
    ps.reset_camera_to_home_view()
    panel = viewer.panels["check"]
    panel.state.file = sys.argv[1]
    panel.state.set_task("barycentric_areas")
    panel.start_check(viewer)  # outside the window: inline
    for _ in range(3):
        ps.frame_tick()
    save_screenshot(Path(sys.argv[2]))
    target = int(sys.argv[3])
    params = ps.get_view_camera_parameters()
    w, h = ps.get_window_size()
    xy, front = project_to_screen(viewer.state.display.points(mesh.V[[target]]),
                                  params.get_view_mat(), params.get_fov_vertical_deg(), w, h)
    t = panel.state.check.result.tasks[0]
    print(json.dumps({"xy": xy[0].tolist(), "front": bool(front[0]), "size": [w, h],
                      "status": t.status, "vertex": t.vertex}))
"""


@pytest.mark.egl
def test_egl_difference_map_is_coloured_where_the_mistake_is(tmp_path, python_ok):
    """A wrong student file loaded in the Check panel, rendered by EGL: the difference map is
    red (coolwarm's positive end) around the wrong vertex's projection and nowhere else in the
    3D view; the rest of the mesh is at the colour of 0."""
    import json

    import matplotlib.image as mpimg

    target = facing_vertex()
    student = tmp_path / "one_wrong.py"
    student.write_text(ONE_VERTEX_WRONG.replace("{target}", str(target)))
    script = tmp_path / "egl_check.py"
    script.write_text(EGL_CHECK_SCRIPT)
    out = tmp_path / "check.png"
    res = python_ok(script, student, out, target, timeout=600)
    info = json.loads(res.stdout.strip().splitlines()[-1])
    assert info["status"] == "failed" and info["front"]
    img = mpimg.imread(out)[..., :3]
    scale = img.shape[1] / info["size"][0]  # framebuffer pixels per window pixel
    view = img[:, : int(0.55 * img.shape[1])]  # the 3D view (the panel is on the right)
    red = (view[..., 0] - view[..., 2] > 0.2) & (view[..., 0] > 0.45)
    bg = np.abs(view - view[0, 0]).sum(axis=2) > 0.05
    assert bg.mean() > 0.05 and red.sum() > 10
    ys, xs = np.nonzero(red)
    x0, y0 = (np.array(info["xy"]) * scale).tolist()
    # every red pixel is near the wrong vertex: the map is coloured there and only there
    dist = np.hypot(xs - x0, ys - y0)
    assert dist.max() < 0.08 * view.shape[0], (dist.max(), x0, y0)
    assert red.sum() < 0.02 * bg.sum()


def test_failing_call_count_agrees_with_meshlap_check(viewer, capsys):
    """The panel said "9 more failing calls" where ``meshlap check`` said 8: it counted the
    mesh on screen among the battery's calls. The panel's verdict is the battery's, as the
    command prints it, and the mesh on screen is judged on a line of its own."""
    import re

    from meshlap_core.cli import main
    from tests.support.widgets import drive, frames

    student = STUDENTS / "wrong_cotan_full.py"
    viewer.set_panel("check")
    drive(viewer, "student file", str(student))
    drive(viewer, "task", "cotan_laplacian")
    drive(viewer, "check", True)
    frames(viewer, 2)
    drawn = [text for sec, text, _ in viewer.ui.texts if sec == "check"]
    drawn += [text for sec, text, _ in viewer.ui.errors_drawn if sec == "check"]
    count = re.compile(r"and (\d+) more failing call")
    in_panel = {int(m.group(1)) for t in drawn if (m := count.search(t))}
    assert "on the mesh on screen: wrong (the map shows where)" in drawn
    capsys.readouterr()
    assert main(["check", str(student), "--task", "cotan_laplacian"]) == 3  # a task failed
    printed = {int(m.group(1)) for m in count.finditer(capsys.readouterr().out)}
    assert len(printed) == 1 and in_panel == printed, (in_panel, printed)
