"""The Diffusion and Curvature lab panels on meshes at 1e74 and 1e-55, read back from what
polyscope stores (``openGL_mock``): polyscope keeps positions and scalars as float32 (largest
3.4e38, smallest normal 1.2e-38), so what these panels uploaded raw came out ``inf`` (no mesh
drawn, a colour bar reading −nan) or 0 (a flat colour). Positions go through the scene's
scaling (:class:`meshlap_app.state.display.Display`) and fields through
:func:`meshlap_app.scene.scalar_for_upload` (a power of ten the label names), as in the
other panels.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_core import primitives, save_mesh  # noqa: E402
from tests.support.widgets import drive, frames, settle  # noqa: E402

SCALES = [1e74, 1e-55]


@pytest.fixture(params=SCALES, ids=["1e74", "1e-55"])
def far_viewer(request, polyscope_mock, tmp_path, monkeypatch):
    """A viewer (ScriptedUI on ``openGL_mock``) on a 162-vertex icosphere scaled by the
    parameter; returns ``(viewer, scale)``."""
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    from tests.support.scripted_ui import ScriptedUI

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    V, F = primitives.icosphere(2)
    path = tmp_path / "far.obj"
    save_mesh(path, V * request.param, F)
    polyscope_mock.remove_all_structures()
    mesh = MeshState()
    assert mesh.load(path), mesh.error
    v = Viewer(AppState(mesh=mesh, folder=tmp_path), ui=ScriptedUI())
    v.sync_mesh()
    polyscope_mock.set_user_callback(v.callback)
    yield v, request.param
    polyscope_mock.clear_user_callback()


def _read(structure, quantity: str) -> np.ndarray:
    """The float32 values polyscope stores for a scalar quantity."""
    buf = structure.get_quantity_buffer(quantity, "values")
    return np.array([buf.get_value(i) for i in range(buf.size())], dtype=np.float64)


def _positions(structure) -> np.ndarray:
    buf = structure.get_buffer("vertexPositions")
    return np.array([buf.get_value(i).as_tuple() for i in range(buf.size())])


def _factor(label: str) -> float:
    """The power of ten a label says its values were scaled by (``" (x 1e-110)"``)."""
    m = re.search(r"\(x 1e(-?\d+)\)$", label)
    return 10.0 ** int(m.group(1)) if m else 1.0


@pytest.mark.parametrize("show", ["distance", "heat"])
def test_the_diffusion_field_keeps_its_colours_at_any_scale(far_viewer, show):
    viewer, _ = far_viewer
    panel = viewer.panels["diffusion"]
    viewer.set_panel("diffusion")
    frames(viewer)
    drive(viewer, "show", show)
    assert panel.select(viewer, 7)
    settle(viewer)
    frames(viewer, 2)
    field = panel.state.distance if show == "distance" else panel.state.heat["euler"]
    assert field is not None and np.all(np.isfinite(field)), viewer.state.errors
    label = panel._title  # the colour bar's title, with the factor it names
    stored = _read(ps.get_surface_mesh("mesh"), label)
    # what the GPU holds: finite, not one flat colour, and the world values once the label's
    # factor is applied (the colour bar reads them)
    assert np.all(np.isfinite(stored)) and np.ptp(stored) > 0
    np.testing.assert_allclose(stored * _factor(label), field, rtol=1e-6)
    # the mesh itself is drawn (finite positions spanning about 1)
    P = _positions(ps.get_surface_mesh("mesh"))
    assert np.all(np.isfinite(P)) and 0.1 < np.ptp(P, axis=0).max() < 10


def test_the_curvature_lab_shows_a_far_mesh_and_its_field(far_viewer):
    from meshlap_app.panels.curvature_lab import LAB

    viewer, scale = far_viewer
    viewer.set_panel("curvature_lab")
    frames(viewer, 2)
    drive(viewer, "source", "mesh")
    drive(viewer, "estimator", "rusinkiewicz")
    panel = viewer.panels["curvature_lab"]
    lab = panel.state
    for _ in range(200):  # the estimate is a job (inline headless; a few frames at most)
        if lab.result is not None and lab.result.V is not None and len(lab.result.V) == 162:
            break
        frames(viewer)
    frames(viewer, 3)
    r = lab.result
    assert r is not None and len(r.V) == 162, viewer.state.errors
    sm = ps.get_surface_mesh(LAB)
    P = _positions(sm)
    assert np.all(np.isfinite(P)) and 0.1 < np.ptp(P, axis=0).max() < 10
    stored = _read(sm, panel._field)
    values = np.asarray(r.values, dtype=np.float64)
    assert np.all(np.isfinite(stored)) and np.ptp(stored) > 0
    np.testing.assert_allclose(stored * _factor(panel._field), values, rtol=1e-5)
    # k1 of a sphere of radius `scale` is about 1/scale: what the label's factor says
    assert np.median(values) == pytest.approx(1.0 / scale, rel=0.05)
    # a click on the uploaded (display) positions picks the right vertex
    from types import SimpleNamespace

    hit = SimpleNamespace(
        structure_name=LAB,
        structure_data={"element_type": "face", "index": 0},
        position=P[r.F[0, 1]],
    )
    assert panel.pick(viewer, hit, panel) and lab.vertex == int(r.F[0, 1])
