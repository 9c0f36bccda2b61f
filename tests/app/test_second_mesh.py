"""A second mesh opened after the first one's eigenbasis and side-by-side copies: the
reconstruction comes back shown and follows k, and no copy keeps the first mesh's field."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")


from tests.support.widgets import compute_basis, drive, frames  # noqa: E402


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


def test_a_second_mesh_after_side_by_side_and_an_eigenbasis_shows_no_error(mock, viewer):
    """The tour's order (side by side on the torus, a vertex, its eigenbasis, then bumpy
    opened): the side-by-side copy of the torus (1152 vertices) took bumpy's field, an error
    ("'values' should be a length n_vertices array") shown on every panel."""
    from meshlap_app.scene import MESH_B

    assets = Path(__file__).resolve().parents[2] / "assets"
    assert viewer.open(assets / "torus.obj")
    ps.frame_tick()
    viewer.set_panel("curvature")
    viewer.ui.script("side by side", True)
    ps.frame_tick()
    assert ps.get_surface_mesh(MESH_B).n_vertices() == 1152
    viewer.set_panel("spectral")
    viewer.ui.script("compute eigenbasis", True)
    for _ in range(4):
        ps.frame_tick()
    assert viewer.open(assets / "bumpy.obj")
    for view in ("spectral", "curvature", "smoothing"):
        viewer.set_panel(view)
        for _ in range(3):
            ps.frame_tick()
        assert not viewer.state.errors, (view, viewer.state.errors)
    assert ps.get_surface_mesh(MESH_B).n_vertices() == len(viewer.state.mesh.V) == 2562
