"""Opening a big mesh shows its geometry at once (issue 21): the parsed mesh with a quick
uniform-H colour map while validation and the curvature fields finish in the background.

- the preview field against libigl / the core's uniform Laplacian (a closed mesh: exactly
  ``−½ (L x) · n̂`` with area-weighted normals; the core's uniform H on a sphere);
- ``load_mesh(on_parsed=)`` hands over the parsed geometry (the file's, before any repair), and
  nothing for polygons;
- a job's partial results reach ``preview`` on the UI thread while it runs, never after;
  through a child process too;
- in the viewer (mock backend, the job in a thread): the preview shows the file's geometry,
  the state is untouched meanwhile, the validated mesh keeps the structure registered for the
  preview (one registration), its colours are the core's cotan H; a failed or cancelled job
  brings the previous mesh back.
"""

from __future__ import annotations

import threading

import igl
import meshlap_app.state.preview as preview_module
import numpy as np
import polyscope as ps
import pytest
from meshlap_app.jobs import Jobs, in_child
from meshlap_app.state.mesh import read_mesh_with_fields
from meshlap_app.state.preview import PREVIEW_LABEL, make_preview, preview_field

from meshlap_core import primitives
from meshlap_core.curvature import all_curvature_fields, mean_curvature_uniform
from meshlap_core.errors import MeshError
from meshlap_core.io import load_mesh, save_mesh
from meshlap_core.laplacian import uniform_laplacian
from meshlap_core.options import curvature_field_title
from tests.support.widgets import frames


def test_preview_field_is_the_uniform_laplacian_against_the_normals_on_a_closed_mesh():
    V, F = primitives.icosphere(3)
    V = V * np.array([1.0, 0.7, 1.3])  # an ellipsoid: H varies
    L = uniform_laplacian(F, len(V)).toarray()  # D⁻¹A − I
    N = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    expected = -0.5 * np.sum((L @ V) * N, axis=1)
    assert np.allclose(preview_field(V, F), expected, rtol=1e-10, atol=1e-12)


def test_preview_field_is_positive_on_a_sphere_and_the_cores_uniform_h():
    V, F = primitives.icosphere(4)
    H = preview_field(V, F)
    assert np.all(H > 0)  # outward normals: H > 0 (the convention)
    # the core's uniform H uses angle-weighted normals: on a sphere both point outward
    assert np.allclose(H, mean_curvature_uniform(V, F), rtol=2e-2)


def test_preview_field_is_zero_where_no_face_is():
    V, F = primitives.icosphere(1)
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])  # an unreferenced vertex
    H = preview_field(V, F)
    assert H[-1] == 0.0 and np.all(np.isfinite(H))


def test_on_parsed_hands_over_the_geometry_as_parsed(tmp_path):
    V, F = primitives.icosphere(2)
    path = tmp_path / "ball.obj"
    save_mesh(path, V, F)
    seen = []
    mesh = load_mesh(path, on_parsed=lambda V, F: seen.append((V.copy(), F.copy())))
    assert len(seen) == 1
    assert np.array_equal(seen[0][1], mesh.F) and np.allclose(seen[0][0], mesh.V)
    assert seen[0][0].dtype == np.float64 and seen[0][1].dtype == np.int64
    # an unreferenced vertex: the parsed geometry has it, the repaired mesh does not
    text = path.read_text() + "v 9 9 9\n"
    (tmp_path / "extra.obj").write_text(text)
    seen.clear()
    mesh = load_mesh(tmp_path / "extra.obj", on_parsed=lambda V, F: seen.append((V, F)))
    assert len(seen[0][0]) == len(V) + 1 and len(mesh.V) == len(V)
    # polygons: no preview (the triangulation is the validator's)
    (tmp_path / "quad.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    seen.clear()
    load_mesh(tmp_path / "quad.obj", on_parsed=lambda V, F: seen.append((V, F)))
    assert seen == []


def test_partial_results_are_previewed_on_the_ui_thread_while_the_job_runs():
    jobs = Jobs()
    go, shown, done = threading.Event(), [], []

    def work(reporter):
        reporter.partial("first")
        reporter.partial("second")  # replaces one not yet shown
        go.wait(10)
        return "final"

    job = jobs.start("o", "t", work, done.append, preview=lambda v: shown.append(v))
    for _ in range(1000):
        if job.reporter.last_partial == "second":
            break
        threading.Event().wait(0.005)
    assert shown == []  # nothing before poll
    jobs.poll()
    assert shown == ["second"] and done == []
    jobs.poll()
    assert shown == ["second"]  # shown once
    go.set()
    assert jobs.wait("o", timeout=10)
    assert done == ["final"] and shown == ["second"]


def test_a_partial_result_of_a_job_that_already_ended_is_not_previewed():
    jobs = Jobs()
    shown, done = [], []

    def work(reporter):
        reporter.partial("late")
        return "final"

    jobs.start("o", "t", work, done.append, preview=shown.append)
    assert jobs.wait("o", timeout=10)
    assert done == ["final"] and shown == []


def _partial_work(n: int, progress=None) -> int:
    progress.partial(np.arange(n))
    return n


def test_in_child_sends_partial_results_to_the_parent():
    jobs = Jobs()
    jobs.processes = True
    done = []
    job = jobs.start("c", "child", in_child(_partial_work, 5), done.append)
    assert jobs.wait("c", timeout=120)
    assert done == [5]
    assert np.array_equal(job.reporter.last_partial, np.arange(5))


class RemoteReporter:
    """What a child process's reporter offers ``read_mesh_with_fields`` (``remote``)."""

    remote = True
    cancel = None

    def __init__(self):
        self.fraction = None
        self.last_partial = None

    def __call__(self, fraction, message=""):
        pass

    def phase_only(self, message):
        pass

    def partial(self, value):
        self.last_partial = value


def test_a_child_sends_the_mesh_back_without_the_geometry_previewed(tmp_path, monkeypatch):
    monkeypatch.setattr(preview_module, "PREVIEW_FACES", 0)
    V, F = primitives.icosphere(3)
    path = tmp_path / "ball.obj"
    save_mesh(path, V, F)
    reporter = RemoteReporter()
    loaded, _ = read_mesh_with_fields(path, "voronoi", "pi", reporter)
    assert loaded.mesh.V is None and loaded.mesh.F is None  # not sent twice
    p = reporter.last_partial
    mesh = load_mesh(path)
    assert np.array_equal(p.V, mesh.V) and np.array_equal(p.F, mesh.F)
    assert np.allclose(p.field, preview_field(mesh.V, mesh.F))
    loaded.with_geometry(p)
    assert loaded.mesh.V is p.V and loaded.mesh.F is p.F
    with pytest.raises(MeshError):
        read_mesh_with_fields(path, "voronoi", "pi", RemoteReporter())[0].with_geometry(None)


def test_a_repaired_mesh_is_sent_whole(tmp_path, monkeypatch):
    monkeypatch.setattr(preview_module, "PREVIEW_FACES", 0)
    V, F = primitives.icosphere(2)
    save_mesh(tmp_path / "ball.obj", V, F)
    path = tmp_path / "extra.obj"
    path.write_text((tmp_path / "ball.obj").read_text() + "v 9 9 9\n")
    reporter = RemoteReporter()
    loaded, _ = read_mesh_with_fields(path, "voronoi", "pi", reporter)
    assert not loaded.previewed and len(loaded.mesh.V) == len(V)
    assert len(reporter.last_partial.V) == len(V) + 1


# ---------------------------------------------------------------------- in the viewer


@pytest.fixture
def held(monkeypatch):
    """Validation in ``load_mesh`` waits for the returned event; ``held.fail`` makes it
    refuse the mesh instead."""
    import meshlap_core.io.load as load_module

    event = threading.Event()
    event.fail = False
    real = load_module.validate_mesh

    def slow(*args, **kwargs):
        assert event.wait(60)
        if event.fail:
            raise MeshError("refused by the test")
        return real(*args, **kwargs)

    monkeypatch.setattr(load_module, "validate_mesh", slow)
    monkeypatch.setattr(preview_module, "PREVIEW_FACES", 0)
    return event


@pytest.fixture
def ellipsoid(tmp_path):
    V, F = primitives.icosphere(3)
    V = V * np.array([1.0, 0.6, 1.4])
    path = tmp_path / "ellipsoid.obj"
    save_mesh(path, V, F)
    return path


def uploaded(sm, label: str) -> np.ndarray:
    """The values of the scalar quantity ``label`` of ``sm`` as polyscope holds them."""
    buf = sm.get_quantity_buffer(label, "values")
    return np.array([buf.get_value(i) for i in range(buf.size())])


def open_until_preview(viewer, path):
    viewer.background = True
    viewer.open(path)
    job = viewer.state.jobs.running("mesh_info")
    for _ in range(4000):
        if job.reporter.last_partial is not None:
            break
        threading.Event().wait(0.005)
    frames(viewer, 2)
    assert viewer.preview is not None


def test_the_preview_shows_the_files_geometry_then_the_validated_mesh_keeps_it(
    viewer, held, ellipsoid, monkeypatch
):
    old = (viewer.state.mesh.name, viewer.state.mesh.version, len(viewer.state.mesh.V))
    registered = []
    real = ps.register_surface_mesh

    def count(name, *args, **kwargs):
        registered.append(name)
        return real(name, *args, **kwargs)

    monkeypatch.setattr(ps, "register_surface_mesh", count)
    open_until_preview(viewer, ellipsoid)
    V, F = igl.read_triangle_mesh(str(ellipsoid))  # the file, read by libigl
    p = viewer.preview
    assert np.allclose(p.V, V, rtol=0, atol=1e-12) and np.array_equal(p.F, F)
    sm = ps.get_surface_mesh("mesh")
    assert sm.n_vertices() == len(V) and sm.n_faces() == len(F)
    shown = uploaded(sm, PREVIEW_LABEL)
    assert np.allclose(shown, preview_field(V, F), rtol=1e-5, atol=1e-6)
    state = viewer.state
    assert (state.mesh.name, state.mesh.version, len(state.mesh.V)) == old  # untouched
    assert registered == ["mesh"]
    held.set()
    assert state.jobs.wait(timeout=120)
    frames(viewer, 2)
    assert state.mesh.name == "ellipsoid.obj" and viewer.preview is None
    mesh = state.mesh
    assert mesh.V is p.V and mesh.F is p.F  # validation left it as parsed: one copy
    assert registered == ["mesh"]  # the structure of the preview was kept
    sm = ps.get_surface_mesh("mesh")
    assert sm.n_vertices() == len(mesh.V)
    with pytest.raises(ValueError):
        sm.get_quantity_buffer(PREVIEW_LABEL, "values")  # its colours went
    core = all_curvature_fields(mesh.V, mesh.F, state.curv.area, state.curv.boundary)
    label = curvature_field_title("cotan")
    final = uploaded(sm, label)
    assert np.allclose(final, core["cotan"], rtol=1e-5, atol=1e-6)  # float32 upload


def test_a_refused_mesh_after_its_preview_brings_the_previous_mesh_back(viewer, held, ellipsoid):
    old = (viewer.state.mesh.name, viewer.state.mesh.version, len(viewer.state.mesh.V))
    open_until_preview(viewer, ellipsoid)
    assert ps.get_surface_mesh("mesh").n_vertices() != old[2]
    held.fail = True
    held.set()
    assert viewer.state.jobs.wait(timeout=120)
    frames(viewer, 2)
    state = viewer.state
    assert (state.mesh.name, state.mesh.version, len(state.mesh.V)) == old
    assert "refused by the test" in state.mesh.error
    assert viewer.preview is None
    assert ps.get_surface_mesh("mesh").n_vertices() == old[2]


def test_cancel_after_the_preview_brings_the_previous_mesh_back(viewer, held, ellipsoid):
    old = (viewer.state.mesh.name, viewer.state.mesh.version, len(viewer.state.mesh.V))
    open_until_preview(viewer, ellipsoid)
    assert viewer.state.jobs.cancel("mesh_info")
    frames(viewer, 2)
    held.set()
    frames(viewer, 2)
    state = viewer.state
    assert (state.mesh.name, state.mesh.version, len(state.mesh.V)) == old
    assert viewer.preview is None
    sm = ps.get_surface_mesh("mesh")
    assert sm.n_vertices() == old[2]
    core = all_curvature_fields(state.mesh.V, state.mesh.F, state.curv.area, state.curv.boundary)
    label = curvature_field_title("cotan")
    assert np.allclose(uploaded(sm, label), core["cotan"], atol=1e-6)


def test_make_preview_range_is_symmetric():
    V, F = primitives.icosphere(2)
    lo, hi = make_preview("x", V, F).vminmax
    assert lo == -hi and hi > 0


def test_the_preview_box_fits_the_display_as_its_vertices_do():
    """The window fits its display to the preview's two corners (computed in the child):
    the same centre, scale and display points as a fit to every vertex."""
    from meshlap_app.state.display import Display

    V, F = primitives.icosphere(2)
    V = V * np.array([3.0, 0.5, 1.5]) + np.array([10.0, -2.0, 0.25])
    p = make_preview("x", V, F)
    assert np.array_equal(p.box, [[v.min() for v in V.T], [v.max() for v in V.T]])
    for up in ("y", "z", "-x"):
        a, b = Display(), Display()
        a.fit(V, up)
        b.fit(p.corners(), up)
        assert np.array_equal(a.centre, b.centre) and a.scale == b.scale
        assert np.array_equal(a.points(V), b.points(V))


@pytest.mark.parametrize("up", ["x", "y", "z", "-x", "-y", "-z"])
def test_display_points_are_the_rotation_applied_as_a_matrix(up):
    """The display's signed-permutation fast path gives exactly ``((V − c) s) Rᵀ``; the up axis
    ends up along +y (the y-up case: the points only centred and scaled)."""
    from meshlap_app.state.display import Display

    V = np.random.default_rng(1).normal(size=(500, 3)) * [1.0, 5.0, 3.0] + 7.0
    d = Display()
    d.fit(V, up)
    P = d.points(V)
    assert np.array_equal(P, ((V - d.centre) * d.scale) @ d.rotation.T)
    assert P.flags.c_contiguous and P.shape == V.shape
    axis, sign = "xyz".index(up[-1]), (-1.0 if up.startswith("-") else 1.0)
    assert np.array_equal(P[:, 1], sign * (V[:, axis] - d.centre[axis]) * d.scale)
    assert np.array_equal(d.points(V[3]), P[3])  # one point


def test_after_a_cancelled_preview_the_next_mesh_opened_goes_to_the_recent_list(
    viewer, held, ellipsoid, sphere
):
    """The restore after a cancelled preview forgets every panel's change tracking: the Mesh
    section still knows the first mesh it showed, and lists the next one opened."""
    open_until_preview(viewer, ellipsoid)
    assert viewer.state.jobs.cancel("mesh_info")
    frames(viewer, 2)
    held.set()
    frames(viewer, 2)
    section = viewer.panels["mesh_info"]
    assert section.recent == []  # nothing was opened: the first mesh is not "recent"
    viewer.background = False
    assert viewer.open(sphere)
    frames(viewer, 2)
    assert viewer.state.mesh.name == "sphere.obj"
    assert section.recent == [sphere]


def test_the_mesh_section_names_the_file_loading_not_the_previous_mesh(
    viewer, held, ellipsoid, monkeypatch
):
    """Issue 33: while a file loads, the Mesh section said the previous mesh's name and
    figures (and the Curvature section its histogram) beside the new file's preview. Now:
    the file's name and "loading...", its sizes as parsed once previewed, no histogram of
    another mesh; the mesh's own figures once it has loaded."""
    texts: list[tuple[str, str]] = []
    ui = viewer.ui
    for name in ("text", "note"):
        plain = getattr(ui, name)

        def recorded(text, plain=plain):
            texts.append((ui.section, text))
            plain(text)

        monkeypatch.setattr(ui, name, recorded)

    def drawn(section: str) -> str:
        return " | ".join(t for s, t in texts if s == section)

    old = viewer.state.mesh.name
    frames(viewer, 2)  # (ImPlot draws a plot from its second frame)
    assert old in drawn("mesh_info") and "loading" not in drawn("mesh_info")
    assert ("curvature", "##vertices") in ui.plots  # the histogram of the mesh shown
    texts.clear()
    viewer.background = True
    with monkeypatch.context() as m:  # the preview not shown yet: the old mesh is on screen
        m.setattr(viewer, "show_preview", lambda preview: None)
        viewer.open(ellipsoid)
        ui.plots.clear()
        frames(viewer, 2)
    assert viewer.preview is None
    assert "ellipsoid.obj: loading..." in drawn("mesh_info")
    assert f"{old} stays on screen until ellipsoid.obj is read" in drawn("mesh_info")
    assert ("curvature", "##vertices") in ui.plots  # (the mesh on screen: its histogram)
    open_until_preview(viewer, ellipsoid)  # (a new job: the first is replaced)
    texts.clear()
    ui.plots.clear()
    frames(viewer, 2)
    p = viewer.preview
    mesh_text = drawn("mesh_info")
    assert "ellipsoid.obj: loading..." in mesh_text and old not in mesh_text
    assert f"{len(p.V):,} vertices, {len(p.F):,} faces as read" in mesh_text
    assert "chi =" not in mesh_text  # no topology of the previous mesh
    assert ("curvature", "##vertices") not in ui.plots
    assert "histogram once ellipsoid.obj has loaded" in drawn("curvature")
    held.set()
    assert viewer.state.jobs.wait(timeout=120)
    texts.clear()
    ui.plots.clear()
    frames(viewer, 2)
    n, m = len(viewer.state.mesh.V), len(viewer.state.mesh.F)
    assert f"ellipsoid.obj: {n} vertices, {m} faces" in drawn("mesh_info")
    assert "loading" not in drawn("mesh_info") and ("curvature", "##vertices") in ui.plots
