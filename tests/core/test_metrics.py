"""Tests of meshlap_core.metrics: hand-computed cases, invariants, independent references."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from meshlap_core import metrics as M
from meshlap_core.errors import MeshError
from meshlap_core.primitives import bumpy_sphere, cube, grid, icosphere, torus_mesh

# ----------------------------------------------------------------------------- hand-computed


def test_unit_cube_volume_is_one():
    V, F = cube()
    assert M.signed_volume(V, F) == pytest.approx(1.0, abs=1e-14)
    vol, reason = M.enclosed_volume(V, F)
    assert vol == pytest.approx(1.0, abs=1e-14) and reason is None


def test_subdivided_scaled_cube_volume():
    V, F = cube(subdivisions=2, size=2.0)
    assert M.signed_volume(V, F) == pytest.approx(8.0, rel=1e-13)


def test_reversed_faces_give_negative_volume():
    V, F = cube()
    assert M.signed_volume(V, F[:, ::-1]) == pytest.approx(-1.0, abs=1e-14)


def test_rmse_hand_computed():
    V_ref = np.zeros((2, 3))
    V = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 0.0]])  # errors 5 and 0
    assert M.rmse(V, V_ref) == pytest.approx(np.sqrt(25.0 / 2))
    assert M.max_error(V, V_ref) == pytest.approx(5.0)
    np.testing.assert_allclose(M.vertex_errors(V, V_ref), [5.0, 0.0])


def test_cube_dihedral_angles():
    V, F = cube()
    theta = M.dihedral_angles(V, F)
    assert len(theta) == 18  # 12 cube edges + 6 face diagonals, all interior
    n_right = np.isclose(theta, np.pi / 2, atol=1e-12).sum()
    n_flat = np.isclose(theta, np.pi, atol=1e-12).sum()
    assert (n_right, n_flat) == (12, 6)


@pytest.mark.parametrize("t", [0.3, -0.5, 1.2])
def test_hinge_dihedral_hand_computed(t):
    # two triangles sharing the edge 0-1 on the x axis; face 0 has normal +z. Folding the second
    # wing towards +z (t > 0) makes a valley seen from the normal side: a reflex edge, pi + t.
    V = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -np.cos(t), np.sin(t)]], float)
    F = np.array([[0, 1, 2], [1, 0, 3]])
    theta = M.dihedral_angles(V, F)
    assert theta.shape == (1,)
    assert theta[0] == pytest.approx(np.pi + t, abs=1e-12)


def test_normal_deviation_hand_computed():
    F = np.array([[0, 1, 2]])
    V_ref = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    t = 0.4
    V = np.array([[0, 0, 0], [1, 0, 0], [0, np.cos(t), np.sin(t)]], float)
    assert M.normal_deviation_deg(V, V_ref, F) == pytest.approx(np.degrees(t), abs=1e-10)


def test_dihedral_histogram_of_cube():
    V, F = cube()
    counts, edges = M.dihedral_histogram(M.dihedral_angles(V, F), bins=9)  # 40 degree bins
    assert edges[0] == 0.0 and edges[-1] == 360.0 and len(counts) == 9
    assert counts[2] == 12  # [80, 120) holds the 90 degree edges
    assert counts[4] == 6  # [160, 200) holds the flat diagonals
    assert counts.sum() == 18


# ----------------------------------------------------------------------------- invariants


def test_rmse_and_errors_of_mesh_against_itself_are_zero():
    V, F = bumpy_sphere(3)
    assert M.rmse(V, V) == 0.0
    assert M.max_error(V, V) == 0.0
    assert M.dihedral_mae_deg(V, V, F) == 0.0
    assert M.normal_deviation_deg(V, V, F) == 0.0
    pct, reason = M.volume_change_pct(V, V, F)
    assert pct == 0.0 and reason is None


def test_rmse_of_a_translation_is_its_length():
    V, _ = icosphere(2)
    t = np.array([0.3, -0.4, 1.2])
    assert M.rmse(V + t, V) == pytest.approx(np.linalg.norm(t))


def test_volume_is_translation_invariant_on_closed_meshes():
    V, F = torus_mesh()
    v0 = M.signed_volume(V, F)
    assert M.signed_volume(V + np.array([5.0, -3.0, 2.0]), F) == pytest.approx(v0, rel=1e-12)


def test_volume_scales_with_the_cube_of_the_size():
    V, F = bumpy_sphere(3)
    assert M.signed_volume(2.5 * V, F) == pytest.approx(2.5**3 * M.signed_volume(V, F), rel=1e-12)
    pct, _ = M.volume_change_pct(2.0 * V, V, F)
    assert pct == pytest.approx(700.0)


def test_open_mesh_volume_is_undefined_with_a_reason():
    V, F = grid(5, 5)
    assert not M.is_closed(F)
    vol, reason = M.enclosed_volume(V, F)
    assert vol is None and "open" in reason and "16 boundary edges" in reason
    pct, reason = M.volume_change_pct(V, V, F)
    assert pct is None and "undefined" in reason
    out = M.Reference(V, F).compare(V)
    assert out["volume_change_pct"] is None and "open" in out["volume_note"]


def test_flat_grid_dihedrals_are_pi_even_with_a_flipped_face():
    V, F = grid(6, 6)
    F = F.copy()
    F[3] = F[3, ::-1]  # inconsistent orientation: the normal is flipped before measuring
    theta = M.dihedral_angles(V, F)
    np.testing.assert_allclose(theta, np.pi, atol=1e-12)


def test_convex_icosphere_edges_are_convex():
    V, F = icosphere(3)
    theta = M.dihedral_angles(V, F)
    assert len(theta) == 3 * len(F) // 2
    assert np.all(theta < np.pi) and np.all(theta > np.pi / 2)


def test_dihedral_mae_is_symmetric_and_positive():
    V, F = bumpy_sphere(3)
    W = V * 1.0
    W[::7] *= 1.05
    a, b = M.dihedral_mae_deg(W, V, F), M.dihedral_mae_deg(V, W, F)
    assert a == pytest.approx(b) and a > 0


def test_reference_compare_matches_the_standalone_functions():
    V, F = bumpy_sphere(3)
    rng = np.random.default_rng(1)
    W = V + 0.01 * rng.standard_normal(V.shape)
    out = M.Reference(V, F).compare(W)
    assert out["rmse"] == pytest.approx(M.rmse(W, V))
    assert out["max_error"] == pytest.approx(M.max_error(W, V))
    assert out["volume_change_pct"] == pytest.approx(M.volume_change_pct(W, V, F)[0])
    assert out["dihedral_mae_deg"] == pytest.approx(M.dihedral_mae_deg(W, V, F))
    assert out["normal_dev_deg"] == pytest.approx(M.normal_deviation_deg(W, V, F))


def test_inputs_are_not_modified():
    V, F = bumpy_sphere(2)
    V0, F0 = V.copy(), F.copy()
    M.Reference(V, F).compare(V * 1.1)
    M.dihedral_angles(V, F)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)


def test_mismatched_vertex_counts_raise():
    V, _ = icosphere(1)
    with pytest.raises(MeshError, match="reference"):
        M.rmse(V[:-1], V)


# ----------------------------------------------------------------------------- references


def test_icosphere_volume_matches_convex_hull_and_approaches_the_ball():
    V, F = icosphere(4)
    vol = M.signed_volume(V, F)
    assert vol == pytest.approx(ConvexHull(V).volume, rel=1e-12)  # scipy qhull: independent
    assert vol == pytest.approx(4 * np.pi / 3, rel=5e-3)  # inscribed polyhedron, O(h^2) low
    assert vol < 4 * np.pi / 3
    errs = [4 * np.pi / 3 - M.signed_volume(*icosphere(s)) for s in (2, 3, 4)]
    assert errs[0] > 3 * errs[1] > 9 * errs[2]  # second-order convergence


def test_edge_faces_agree_with_topology_counts():
    from meshlap_core.topology import edge_face_counts

    _, F = grid(5, 7)
    E, count = edge_face_counts(F)
    adj = M.edge_faces(F)
    assert len(adj.edges) == int((count == 2).sum())
    assert np.all(adj.consistent)
    got = {tuple(sorted(e)) for e in adj.edges.tolist()}
    want = {tuple(e) for e in E[count == 2].tolist()}
    assert got == want


@pytest.mark.parametrize("flip", [False, True])
def test_volume_change_is_signed_by_the_enclosed_volume(flip):
    """Shrinking an icosphere by 10 % loses 27.1 % of its enclosed volume, whichever way its
    faces point (an inside-out sphere has a negative signed volume)."""
    V, F = icosphere(3)
    if flip:
        F = F[:, ::-1].copy()
    assert (M.signed_volume(V, F) < 0) == flip
    pct, reason = M.volume_change_pct(0.9 * V, V, F)
    assert reason is None and pct == pytest.approx(100 * (0.9**3 - 1))
    pct, _ = M.volume_change_pct(1.1 * V, V, F)
    assert pct == pytest.approx(100 * (1.1**3 - 1))
    ref = M.Reference(V, F)
    assert ref.compare(0.9 * V)["volume_change_pct"] == pytest.approx(100 * (0.9**3 - 1))


def test_smoothing_an_inside_out_sphere_reports_shrinkage():
    from meshlap_core.smoothing import Smoother

    V, F = icosphere(2)
    out = {}
    for flip in (False, True):
        G = F[:, ::-1].copy() if flip else F
        s = Smoother(V, G, "explicit", "uniform", 0.5, warn=False)
        for _ in range(5):
            s.step()
        out[flip] = s.history[-1]["volume_change_pct"]
    assert out[True] < 0 and out[True] == pytest.approx(out[False], rel=1e-12)


def test_volume_blocks_of_any_size_give_the_same_volume(monkeypatch):
    """The volume is summed over blocks of faces (cache-sized): any block size, including
    one that splits the faces unevenly, gives the convex hull's volume."""
    V, F = icosphere(3)
    want = ConvexHull(V).volume
    for size in (1, 7, 8192):
        monkeypatch.setattr(M, "VOLUME_CHUNK", size)
        assert M.signed_volume(V, F) == pytest.approx(want, rel=1e-12)
