"""The viewer's long operations as jobs, driven through the scripted UI on polyscope's mock
backend (``viewer.background = True``, as in the window): opening a mesh, the eigenbasis and
the smoothing stepper's build each show a progress line and a Cancel button in their panel; a
job of a panel not on screen shows at the top; Cancel (or a failure) keeps what was shown; the
panels stay usable meanwhile; results arrive only in a frame."""

from __future__ import annotations

import threading

import meshlap_app.state.mesh as mesh_module
import polyscope as ps
import pytest
from meshlap_app.jobs import call_hooked

from tests.support.widgets import drive, frames


@pytest.fixture
def gate(monkeypatch):
    """``load_mesh`` in the viewer waits for the returned event (a slow file)."""
    event = threading.Event()
    real = mesh_module.load_mesh

    def slow(path, **kwargs):
        progress = kwargs.get("progress")
        for _ in range(2000):
            if event.wait(0.005):
                break
            if progress is not None:  # as the core's hooks do: a report, which may cancel
                progress(None, "reading the file")
        return real(path)

    monkeypatch.setattr(mesh_module, "load_mesh", slow)
    return event


def progress_texts(viewer, section: str) -> list[str]:
    return [text for sec, _, text in viewer.ui.progress_lines if sec == section]


def reported(viewer, owner: str) -> None:
    """Wait until ``owner``'s job reported once (its worker runs on its own)."""
    job = viewer.state.jobs.running(owner)
    for _ in range(2000):
        if job.reporter.reports:
            return
        threading.Event().wait(0.005)
    raise AssertionError(f"the {owner} job never reported")


def wait_jobs(viewer) -> None:
    assert viewer.state.jobs.wait(timeout=120)
    frames(viewer)


def test_open_is_a_job_with_progress_and_cancel(viewer, gate, sphere, tmp_path):
    viewer.background = True
    torus = tmp_path / "torus.obj"
    torus.write_text((sphere.parent / "sphere.obj").read_text())  # same shape, new name
    before = (viewer.state.mesh.name, viewer.state.mesh.version)
    drive(viewer, "path", str(torus))  # Enter: the job starts, the old mesh stays
    assert viewer.state.jobs.running("mesh_info") is not None
    reported(viewer, "mesh_info")
    frames(viewer, 2)
    assert (viewer.state.mesh.name, viewer.state.mesh.version) == before
    lines = progress_texts(viewer, "mesh_info")
    assert lines and lines[-1].startswith("opening torus.obj")
    drive(viewer, "Cancel##mesh_info", True)  # the Cancel button under the progress line
    assert viewer.state.jobs.running("mesh_info") is None
    gate.set()
    frames(viewer, 3)
    assert (viewer.state.mesh.name, viewer.state.mesh.version) == before
    assert not viewer.state.mesh.error
    # open it again and let it finish: the mesh (and its curvature fields) arrive in a frame
    drive(viewer, "path", str(torus))
    wait_jobs(viewer)
    assert viewer.state.mesh.name == "torus.obj" and viewer.state.curv.current(viewer.state.mesh)
    assert ps.get_surface_mesh("mesh").n_vertices() == len(viewer.state.mesh.V)


def test_a_failed_open_keeps_the_mesh_and_says_why(viewer, tmp_path):
    viewer.background = True
    bad = tmp_path / "broken.off"
    bad.write_text("OFF\n10 5 0\n0 0 0\n")
    n, version = len(viewer.state.mesh.V), viewer.state.mesh.version
    drive(viewer, "path", str(bad))
    wait_jobs(viewer)
    assert "broken.off" in viewer.state.mesh.error
    assert (len(viewer.state.mesh.V), viewer.state.mesh.version) == (n, version)


def test_eigenbasis_job_progress_cancel_and_status_line_elsewhere(viewer, monkeypatch):
    from meshlap_app.state import spectral as spectral_state

    viewer.background = True
    release = threading.Event()
    real = spectral_state.SpectralBasis.compute

    def slow(V, F, k, **kwargs):
        progress = kwargs.get("progress")
        while not release.wait(0.005):
            if progress is not None:
                progress(0.25, "Lanczos")
        return call_hooked(real, V, F, k, reporter=progress)

    monkeypatch.setattr(spectral_state.SpectralBasis, "compute", staticmethod(slow))
    st = viewer.panels["spectral"].state
    drive(viewer, "modes to compute", 10, panel="spectral")
    drive(viewer, "compute eigenbasis", True)
    reported(viewer, "spectral")
    frames(viewer, 2)
    assert st.busy and st.basis is None
    assert progress_texts(viewer, "spectral")[-1].startswith("eigenbasis (10 modes): Lanczos")
    assert "(25 %)" in progress_texts(viewer, "spectral")[-1]
    # another view: the job goes on, its line shows at the top with its Cancel button
    drive(viewer, "view", "curvature")
    frames(viewer)
    assert progress_texts(viewer, "jobs")[-1].startswith("eigenbasis")
    drive(viewer, "Cancel##spectral", True)
    assert not st.busy and st.basis is None
    release.set()
    frames(viewer, 2)
    assert st.basis is None  # cancelled: nothing adopted
    drive(viewer, "compute eigenbasis", True, panel="spectral")
    wait_jobs(viewer)
    assert st.basis is not None and st.basis.k_max == 10


def test_smoothing_builds_its_stepper_as_a_job_and_stays_usable(viewer, monkeypatch):
    from meshlap_app.state.smoothing import SmoothingState

    viewer.background = True
    release = threading.Event()
    real = SmoothingState.build

    def slow(V, F, options, progress=None):
        release.wait(30)
        return real(V, F, options, progress)

    monkeypatch.setattr(SmoothingState, "build", staticmethod(slow))
    st = viewer.panels["smoothing"].state
    viewer.set_panel("smoothing")
    frames(viewer)
    assert st.smoother is None and viewer.state.jobs.running("smoothing") is not None
    drive(viewer, "lambda", 0.25)  # the panel answers meanwhile
    assert st.lam == 0.25
    assert progress_texts(viewer, "smoothing")[-1].startswith("building the implicit")
    viewer.set_panel("curvature")
    viewer.set_panel("smoothing")  # a panel switch does not start a second build
    assert viewer.state.jobs.cancelled == 0
    release.set()
    wait_jobs(viewer)
    assert st.smoother is not None and st.smoother.lam == 0.25
    built = st.smoother
    viewer.set_panel("curvature")
    viewer.set_panel("smoothing")  # cached: switching back rebuilds nothing
    frames(viewer)
    assert st.smoother is built and viewer.state.jobs.running("smoothing") is None
    # a new method: built as a job, the old stepper stays until the new one is there
    drive(viewer, "method", "explicit")
    assert st.smoother is built and st.method == "implicit"
    wait_jobs(viewer)
    assert st.method == "explicit" and st.smoother is not built


def test_a_new_area_recomputes_the_fields_as_a_job_and_cancel_goes_back(viewer, monkeypatch):
    from meshlap_app.state.curvature import CurvatureState

    viewer.background = True
    curv = viewer.state.curv
    release = threading.Event()
    real = CurvatureState.compute

    def slow(V, F, area, boundary, progress=None):
        release.wait(30)
        return real(V, F, area, boundary)

    monkeypatch.setattr(CurvatureState, "compute", staticmethod(slow))
    shown = dict(curv.fields)
    drive(viewer, "area", "barycentric", panel="curvature")  # the default is voronoi
    frames(viewer)
    assert viewer.state.jobs.running("curvature") is not None
    assert curv.fields == shown  # the map on screen stays meanwhile
    assert progress_texts(viewer, "curvature")[-1].startswith("curvature fields (barycentric")
    drive(viewer, "Cancel##curvature", True)
    frames(viewer)
    assert curv.area == "voronoi" and curv.fields == shown  # back to what is shown
    release.set()
    drive(viewer, "area", "barycentric")
    wait_jobs(viewer)
    frames(viewer)
    assert curv.current(viewer.state.mesh) and curv.computed_for()[1] == "barycentric"
