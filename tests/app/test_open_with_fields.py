"""The window's first mesh (and ``meshlap view --screenshot``'s) opened with its curvature
fields (:func:`meshlap_app.opening.load_now`): the fields are computed at load, before any
polyscope structure, and the panel finds them current; a failure keeps the error and the
last good mesh."""

from __future__ import annotations

import numpy as np
from meshlap_app.heap import release_freed
from meshlap_app.opening import load_now
from meshlap_app.state.app import AppState

from meshlap_core.curvature import all_curvature_fields
from meshlap_core.io import save_mesh
from meshlap_core.primitives import bumpy_sphere


def test_fields_come_with_the_mesh_and_are_current(tmp_path):
    path = tmp_path / "bumpy.obj"
    save_mesh(path, *bumpy_sphere(2))
    state = AppState(folder=tmp_path)
    assert load_now(state, path)
    mesh, curv = state.mesh, state.curv
    assert mesh.name == "bumpy.obj" and curv.current(mesh)
    want = all_curvature_fields(mesh.V, mesh.F, curv.area, curv.boundary)
    assert set(curv.fields) == set(want)
    for name, values in want.items():
        np.testing.assert_allclose(curv.fields[name], values, rtol=1e-12, atol=1e-12)


def test_a_failed_load_keeps_the_last_mesh_and_says_why(tmp_path):
    state = AppState(folder=tmp_path)
    assert load_now(state, None)  # the bundled default
    version, name = state.mesh.version, state.mesh.name
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    assert not load_now(state, bad)
    assert "bad.obj" in state.mesh.error
    assert (state.mesh.version, state.mesh.name) == (version, name)
    assert state.curv.current(state.mesh)
    assert not load_now(state, tmp_path / "missing.obj")
    assert "missing.obj" in state.mesh.error


def test_release_freed_says_whether_it_could():
    assert release_freed() in (True, False)
