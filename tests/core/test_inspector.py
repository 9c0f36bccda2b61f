"""The vertex inspector against hand computations and the global operators."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from meshlap_core import curvature as curv
from meshlap_core import primitives
from meshlap_core.errors import MeshError
from meshlap_core.inspector import format_inspection, inspect_vertex
from meshlap_core.io import save_mesh
from meshlap_core.laplacian import cotan_stiffness, vertex_areas


def _meshes():
    rng = np.random.default_rng(3)
    V, F = primitives.icosphere(2)
    yield "icosphere", V, F
    Vp = V + rng.normal(scale=0.04, size=V.shape)  # many obtuse triangles
    yield "perturbed icosphere", Vp, F
    V, F = primitives.grid(5, 4)
    V = V + rng.normal(scale=0.06, size=V.shape)  # open, curved, obtuse
    yield "open grid", V, F
    V, F = primitives.torus_mesh(12, 8)
    yield "torus", V, F


MESHES = list(_meshes())


def test_one_right_triangle_by_hand():
    """Right angle at 0: w_01 = ½ cot 45° = ½, w_12 = ½ cot 90° = 0; Voronoi areas ¼, ⅛, ⅛."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2]])
    r = inspect_vertex(V, F, 0, "voronoi", "pi")
    assert [t.index for t in r.neighbors] == [1, 2]
    assert [t.weight_cotan for t in r.neighbors] == pytest.approx([0.5, 0.5])
    assert [math.degrees(t.alpha) for t in r.neighbors] == pytest.approx([45, 45])
    assert all(t.beta is None for t in r.neighbors)  # boundary edges: one face each
    assert r.area_voronoi == pytest.approx(0.25) and r.area_barycentric == pytest.approx(1 / 6)
    assert r.angle_sum == pytest.approx(math.pi / 2)
    assert r.angle_deficit == pytest.approx(math.pi / 2)  # π − π/2 (boundary rule pi)
    assert r.K == pytest.approx((math.pi / 2) / 0.25)
    # Σ w (x_j − x_i) = ½(1,0,0) + ½(0,1,0); divided by A = ¼
    np.testing.assert_allclose(r.laplacian_cotan, [2, 2, 0])
    r1 = inspect_vertex(V, F, 1, "voronoi")
    assert r1.area_voronoi == pytest.approx(1 / 8)
    assert {t.index: t.weight_cotan for t in r1.neighbors}[2] == pytest.approx(0.0, abs=1e-15)


def test_an_obtuse_angle_gives_a_negative_weight_and_the_obtuse_area_rule():
    V = np.array([[0.0, 0, 0], [2, 0, 0], [1, 0.3, 0], [1, -0.3, 0]])
    F = np.array([[0, 1, 2], [1, 0, 3]])
    r = inspect_vertex(V, F, 0, "voronoi")
    w = {t.index: t for t in r.neighbors}
    assert w[1].negative and w[1].weight_cotan < 0  # both angles opposite edge 01 are obtuse
    assert w[1].beta is not None
    assert all(f.obtuse and not f.obtuse_at_vertex for f in r.faces)
    assert [f.share_voronoi for f in r.faces] == pytest.approx([f.area / 4 for f in r.faces])
    assert "NEGATIVE" in format_inspection(r)


@pytest.mark.parametrize("name,V,F", MESHES, ids=[m[0] for m in MESHES])
@pytest.mark.parametrize("area", ["barycentric", "voronoi"])
def test_every_term_equals_the_global_operators(name, V, F, area):
    C = cotan_stiffness(V, F).tocsr()
    A = {a: vertex_areas(V, F, a) for a in ("barycentric", "voronoi")}
    N = curv.vertex_normals(V, F)
    H_u = curv.mean_curvature_uniform(V, F)
    H_c = curv.mean_curvature_cotan(V, F, area)
    K = curv.gaussian_curvature(V, F, area, "pi")
    k1, k2 = curv.principal_curvatures(V, F, area, "pi")
    for i in range(0, len(V), max(1, len(V) // 25)):
        r = inspect_vertex(V, F, i, area, "pi")
        row = C.getrow(i).toarray().ravel()
        for t in r.neighbors:
            assert t.weight_cotan == pytest.approx(row[t.index], rel=1e-10, abs=1e-12)
        assert sorted(t.index for t in r.neighbors) == sorted(set(F[(F == i).any(1)].ravel()) - {i})
        assert r.area_barycentric == pytest.approx(A["barycentric"][i], rel=1e-12)
        assert r.area_voronoi == pytest.approx(A["voronoi"][i], rel=1e-10)
        np.testing.assert_allclose(r.normal, N[i], atol=1e-12)
        assert r.H_uniform == pytest.approx(H_u[i], rel=1e-9, abs=1e-12)
        assert r.H_cotan == pytest.approx(H_c[i], rel=1e-8, abs=1e-10)
        assert r.K == pytest.approx(K[i], rel=1e-9, abs=1e-10)
        assert (r.k1, r.k2) == pytest.approx((k1[i], k2[i]), rel=1e-7, abs=1e-7)


def test_the_ring_is_in_counter_clockwise_order():
    V, F = primitives.icosphere(1)
    faces = {tuple(np.roll(f, k)) for f in F.tolist() for k in range(3)}
    for i in range(len(V)):
        ring = [t.index for t in inspect_vertex(V, F, i).neighbors]
        for a, b in zip(ring, ring[1:] + ring[:1], strict=True):
            assert (i, a, b) in faces


def test_boundary_rules_at_a_boundary_vertex():
    V, F = primitives.grid(3, 3)
    corner = 0
    deficits = {
        b: inspect_vertex(V, F, corner, boundary=b).angle_deficit for b in ("pi", "2pi", "zero")
    }
    assert deficits == pytest.approx({"pi": math.pi / 2, "2pi": 3 * math.pi / 2, "zero": 0.0})


def test_a_vertex_shared_by_two_tetrahedra_lists_two_fans():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]])
    tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    F = np.vstack([tet, np.array([[0, 5, 4], [0, 4, 6], [0, 6, 5], [4, 5, 6]])])
    r = inspect_vertex(V, F, 0)
    assert not r.manifold and len(r.fans) == 2
    assert [sorted(int(j) for j in f.neighbors) for f in r.fans] == [[1, 2, 3], [4, 5, 6]]
    assert all(f.closed for f in r.fans)
    assert sorted(t.index for t in r.neighbors) == [1, 2, 3, 4, 5, 6]


@pytest.mark.parametrize("bad", [-1, 10**9, 2.5, True])
def test_bad_vertex_is_a_mesh_error(bad):
    V, F = primitives.icosphere(0)
    with pytest.raises(MeshError, match="vertex"):
        inspect_vertex(V, F, bad)


def test_cli_json_and_errors(tmp_path):
    V, F = primitives.grid(4, 4)
    path = tmp_path / "g.obj"
    save_mesh(path, V, F)
    run = [sys.executable, "-m", "meshlap_core.cli", "inspect", str(path)]
    res = subprocess.run([*run, "--vertex", "5", "--json"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    keys = {
        "vertex",
        "boundary",
        "area_barycentric",
        "area_voronoi",
        "normal",
        "laplacian_uniform",
        "laplacian_cotan",
        "H_uniform",
        "H_cotan",
        "angle_sum",
        "angle_deficit",
        "K",
        "k1",
        "k2",
        "neighbors",
        "faces",
    }
    assert keys <= set(out)
    assert {
        "index",
        "edge_length",
        "alpha_deg",
        "beta_deg",
        "weight_cotan",
        "weight_uniform",
        "negative",
    } <= set(out["neighbors"][0])
    assert {"face", "angle_deg", "area", "obtuse"} <= set(out["faces"][0])
    assert sum(f["angle_deg"] for f in out["faces"]) == pytest.approx(360)
    res = subprocess.run([*run, "--vertex", "99"], capture_output=True, text=True)
    assert res.returncode == 2 and res.stderr.count("\n") == 1 and "--vertex" in res.stderr
    res = subprocess.run([*run, "--vertex", "1"], capture_output=True, text=True)
    assert res.returncode == 0 and "H_cotan = −½" in res.stdout


def test_right_angles_give_zero_weights_not_negative_ones():
    """Opposite angles of 90° give cot = round-off (±1e-17): listed as 0, never as negative."""
    V, F = primitives.grid(4, 4)
    for i in range(len(V)):
        r = inspect_vertex(V, F, i)
        scale = max(abs(t.weight_cotan) for t in r.neighbors)
        zero = [t for t in r.neighbors if abs(t.weight_cotan) < 1e-12 * scale]
        assert not any(t.negative for t in r.neighbors)
        if not r.boundary:
            assert zero  # the squares' diagonals: both opposite angles are right angles
