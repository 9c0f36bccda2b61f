"""Maps of a surface to the plane and their distortion (meshlap_core.flatten).

Three tiers: hand-computed tiny cases (a four-face fan, a stretched right triangle, a square
loop), invariants (Tutte one-to-one on every shipped disk, boundaries on the circle or square,
linear precision, the eigen-equation, ARAP's monotone energy, a developable strip flattened
without distortion), and references (libigl's harmonic, Tutte, LSCM and flip count; a dense
Schur complement).
"""

import doctest
import threading

import igl
import numpy as np
import pytest
import scipy.sparse as sp

from meshlap_core.errors import Cancelled, MeshError
from meshlap_core.flatten import (
    ARAP,
    Flattener,
    arap,
    boundary_positions,
    distortion_table,
    flatten,
    flattener,
    make_disk,
    measure_distortion,
    unit_square_uv,
)
from meshlap_core.flatten.boundary import circle_positions, square_positions
from meshlap_core.flatten.conformal import area_matrix, conformal_energy, image_area
from meshlap_core.flatten.fixed_boundary import cotan_laplacian, graph_laplacian
from meshlap_core.flatten.jacobian import (
    closest_rotations,
    face_frames,
    jacobians,
    singular_values,
)
from meshlap_core.flatten.schur import BoundaryReduction, _by_factor, _by_solves
from meshlap_core.io import load_mesh
from meshlap_core.laplacian import cotan_stiffness
from meshlap_core.primitives import grid, icosphere, torus_mesh
from meshlap_core.topology import boundary_loops

ASSETS = __import__("pathlib").Path(__file__).resolve().parents[2] / "assets"
SHARED_DISKS = [
    "camelhead.obj",
    "lilium.obj",
    "lilium_s.obj",
    "plane.obj",
    "plane_ns.obj",
    "terrain.obj",
    "cow.obj",
    "cow_small.obj",
]
"""The meshes of ../shared/meshes with one boundary loop and genus 0."""


# ------------------------------------------------------------------------------ meshes


def compact(V, F):
    """Drop the vertices in no face."""
    used, inv = np.unique(F, return_inverse=True)
    return V[used], inv.reshape(-1, 3)


def cylinder_strip(nu=12, nv=6, angle=2.0, height=1.5):
    """A piece of the unit cylinder, ``θ ∈ [0, angle]``, ``z ∈ [0, height]``, quads split: its
    triangles are planar rectangles' halves, so it unrolls isometrically (developable)."""
    th, z = np.meshgrid(np.linspace(0, angle, nu), np.linspace(0, height, nv), indexing="ij")
    V = np.stack([np.cos(th.ravel()), np.sin(th.ravel()), z.ravel()], axis=1)
    _, F = grid(nu, nv)
    return V, F


def bumpy_patch(n=12):
    """A height field over the unit square: a curved disk."""
    V, F = grid(n, n)
    V = V.copy()
    V[:, 2] = 0.25 * np.sin(3 * V[:, 0]) * np.cos(2 * V[:, 1])
    return V, F


def cap():
    """The part of an icosphere above z = 0.2: a spherical cap (a curved disk)."""
    V, F = icosphere(3)
    return compact(V, F[V[F].mean(axis=1)[:, 2] > 0.2])


def annulus():
    """A flat grid with its middle faces removed: two boundary loops."""
    V, F = grid(12, 12)
    centre = V[F].mean(axis=1)[:, :2]
    return compact(V, F[np.abs(centre - 0.5).max(axis=1) > 0.2])


def jittered_grid(n=10, seed=3):
    """A planar grid with its interior vertices moved at random (still a valid disk)."""
    V, F = grid(n, n)
    V = V.copy()
    inner = (V[:, 0] > 0) & (V[:, 0] < 1) & (V[:, 1] > 0) & (V[:, 1] < 1)
    V[inner, :2] += np.random.default_rng(seed).uniform(-0.2, 0.2, (inner.sum(), 2)) / n
    return V, F


GENERATED = {
    "bumpy patch": bumpy_patch,
    "cap": cap,
    "cylinder strip": cylinder_strip,
    "jittered grid": jittered_grid,
    "cut torus": lambda: tuple(getattr(make_disk(*torus_mesh(24, 12)), a) for a in ("V", "F")),
    "slit sphere": lambda: tuple(getattr(make_disk(*icosphere(2)), a) for a in ("V", "F")),
}


def shipped_or_generated(name, shared_mesh):
    """``(V, F)`` of a generated disk, an asset or a shared mesh (skipped when absent)."""
    if name in GENERATED:
        return GENERATED[name]()
    path = ASSETS / name if (ASSETS / name).is_file() else shared_mesh(name)
    mesh = load_mesh(path)
    return mesh.V, mesh.F


def fan(p=(0.3, 0.2)):
    """Four triangles around a vertex at ``p`` inside the unit square (corners 0–3)."""
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [p[0], p[1], 0]], dtype=float)
    F = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    return V, F


def similarity_residual(A, B):
    """``min_{a,b} |A − (a·B + b)| / |A|`` over complex ``a, b`` (A, B as (n,2) points)."""
    za, zb = A[:, 0] + 1j * A[:, 1], B[:, 0] + 1j * B[:, 1]
    M = np.stack([zb, np.ones_like(zb)], axis=1)
    coef, *_ = np.linalg.lstsq(M, za, rcond=None)
    return float(np.abs(za - M @ coef).max() / np.abs(za - za.mean()).max())


# ------------------------------------------------------------------------------ by hand


def test_fan_tutte_centre_is_the_neighbours_mean_and_harmonic_keeps_it_affine():
    """Boundary on the square: the corners go to (±1, ±1). Tutte puts the inner vertex at the
    mean of its four neighbours, (0, 0), wherever it is; the harmonic map reproduces affine
    maps (cotangent weights have linear precision), so it lands at 2p − 1."""
    V, F = fan((0.3, 0.2))
    flat = Flattener(V, F)
    np.testing.assert_allclose(flat.disk.outer, [0, 1, 2, 3])
    tutte = flat.map("tutte", "square").uv
    harmonic = flat.map("harmonic", "square").uv
    np.testing.assert_allclose(tutte[:4], [[-1, -1], [1, -1], [1, 1], [-1, 1]], atol=1e-15)
    np.testing.assert_allclose(tutte[4], [0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(harmonic[4], [-0.4, -0.6], atol=1e-14)


def test_singular_values_of_a_stretched_right_triangle():
    """(0,0),(1,0),(0,1) to (0,0),(2,0),(0,1): J = diag(2, 1). The layout has twice the
    area, so the normalizing scale is 1/√2: σ = (√2, 1/√2), angle distortion 2, area 0."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    F = np.array([[0, 1, 2]])
    d = measure_distortion(V, F, [[0, 0], [2, 0], [0, 1]])
    assert d.scale == pytest.approx(1 / np.sqrt(2))
    assert d.sigma1[0] == pytest.approx(np.sqrt(2))
    assert d.sigma2[0] == pytest.approx(1 / np.sqrt(2))
    assert d.angle[0] == pytest.approx(2.0)
    assert d.area[0] == pytest.approx(0.0, abs=1e-15)
    assert d.signed_area[0] == pytest.approx(1.0)
    e = d.ellipse(0)
    np.testing.assert_allclose(np.abs(e.uv_axes[:, 0]), [1, 0], atol=1e-15)
    np.testing.assert_allclose(np.abs(e.surface_axes[:, 0]), [1, 0, 0], atol=1e-15)
    circle, ellipse = e.polylines(0.1, 8)
    assert circle.shape == (8, 3) and ellipse.shape == (8, 2)
    # the circle of radius 0.1 maps to semi-axes 0.2 and 0.1 in the layout (J itself)
    np.testing.assert_allclose(np.ptp(ellipse, axis=0), [0.4, 0.2], atol=1e-12)


def test_flipped_and_collapsed_faces_by_hand():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    F = np.array([[0, 1, 2]])
    flipped = measure_distortion(V, F, [[0, 0], [0, 1], [1, 0]])
    assert flipped.flipped[0] and not flipped.collapsed[0]
    assert flipped.summary()["flipped"] == 1
    line = measure_distortion(V, F, [[0, 0], [1, 0], [2, 0]])
    assert line.collapsed[0] and not line.flipped[0]
    assert line.angle[0] == np.inf and line.summary()["collapsed"] == 1


def test_circle_and_square_positions_by_hand():
    """A unit square loop of four equal edges: the circle's quarter points, the square's
    corners; eight vertices: corners and side midpoints."""
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    loop = np.arange(4)
    np.testing.assert_allclose(
        circle_positions(V, loop), [[1, 0], [0, 1], [-1, 0], [0, -1]], atol=1e-15
    )
    np.testing.assert_allclose(square_positions(V, loop), [[-1, -1], [1, -1], [1, 1], [-1, 1]])
    V8 = np.array([[0, 0], [0.5, 0], [1, 0], [1, 0.5], [1, 1], [0.5, 1], [0, 1], [0, 0.5]])
    V8 = np.column_stack([V8, np.zeros(8)])
    want = [[-1, -1], [0, -1], [1, -1], [1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0]]
    np.testing.assert_allclose(square_positions(V8, np.arange(8)), want, atol=1e-15)


def test_area_matrix_gives_the_signed_shoelace_area():
    """A counter-clockwise square of side 2: ½ xᵀQx = 4, the reversed loop −4."""
    loop = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    uv = np.array([[0, 0], [2, 0], [2, 2], [0, 2.0]])
    x = np.concatenate([uv[:, 0], uv[:, 1]])
    assert 0.5 * x @ area_matrix(loop, 4) @ x == pytest.approx(4.0)
    assert 0.5 * x @ area_matrix(loop[:, ::-1], 4) @ x == pytest.approx(-4.0)
    assert image_area(uv, loop) == pytest.approx(4.0)


# ------------------------------------------------------------------------------ invariants


def test_conformal_energy_is_dirichlet_minus_area():
    """½ xᵀL_Cx = ½ Σ A_f ‖J_f‖² − 𝒜: zero for the identity of a planar mesh, and the
    formula for a random map (the Dirichlet energy from the Jacobians, 𝒜 the layout area)."""
    V, F = jittered_grid()
    K = cotan_laplacian(V, F)
    halfedges = make_disk(V, F).table.boundary_halfedges()
    L = conformal_energy(K, halfedges)
    x = np.concatenate([V[:, 0], V[:, 1]])
    assert abs(0.5 * x @ L @ x) < 1e-13
    uv = np.random.default_rng(0).normal(size=(len(V), 2))
    fr = face_frames(V, F)
    dirichlet = 0.5 * fr.area @ np.sum(jacobians(fr, F, uv) ** 2, axis=(1, 2))
    d1, d2 = uv[F[:, 1]] - uv[F[:, 0]], uv[F[:, 2]] - uv[F[:, 0]]
    signed = 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]).sum()
    x = np.concatenate([uv[:, 0], uv[:, 1]])
    assert 0.5 * x @ L @ x == pytest.approx(dirichlet - signed, rel=1e-12)


def test_closed_form_singular_values_and_rotations_match_the_svd():
    J = np.random.default_rng(1).normal(size=(200, 2, 2))
    s1, s2 = singular_values(J)
    S = np.linalg.svd(J, compute_uv=False)
    np.testing.assert_allclose(np.stack([s1, s2], axis=1), S, rtol=1e-12, atol=1e-14)
    R = closest_rotations(J)
    np.testing.assert_allclose(np.linalg.det(R), 1.0)
    # no rotation is nearer to J than R (a dense sweep of angles)
    t = np.linspace(0, 2 * np.pi, 721)[:, None]
    best = np.min(
        (J[:, 0, 0] - np.cos(t)) ** 2 + (J[:, 0, 1] + np.sin(t)) ** 2
        + (J[:, 1, 0] - np.sin(t)) ** 2 + (J[:, 1, 1] - np.cos(t)) ** 2, axis=0
    )  # fmt: skip
    assert np.all(np.sum((J - R) ** 2, axis=(1, 2)) <= best + 1e-12)


TUTTE_DISKS = ["grid.obj", *SHARED_DISKS, *GENERATED]


@pytest.mark.parametrize("name", TUTTE_DISKS)
def test_tutte_is_one_to_one_on_every_shipped_disk(name, shared_mesh):
    """Tutte's theorem: uniform positive weights and a convex boundary (the circle) give a
    map with no flipped and no collapsed face; on the square (convex, not strictly) still no
    flip, and a collapsed face has its three corners on one side."""
    V, F = shipped_or_generated(name, shared_mesh)
    flat = Flattener(V, F)
    circle = flat.map("tutte", "circle").distortion()
    assert circle.flipped.sum() == 0 and circle.collapsed.sum() == 0
    square = flat.map("tutte", "square")
    d = square.distortion()
    assert d.flipped.sum() == 0
    corners = square.uv[flat.disk.F[d.collapsed]]
    on_side = np.isclose(np.abs(corners), 1.0, atol=1e-12)
    assert np.all(on_side[..., 0].all(axis=1) | on_side[..., 1].all(axis=1))


@pytest.mark.parametrize("method", ["tutte", "harmonic", "arap"])
@pytest.mark.parametrize("shape", ["circle", "square"])
def test_fixed_boundaries_lie_on_the_circle_or_the_square(method, shape):
    V, F = cap()
    flat = Flattener(V, F)
    uvmap = flat.map(method, shape, iters=3 if method == "arap" else None)
    b = uvmap.uv[flat.disk.outer]
    if method == "arap":  # (ARAP's circle and square have the surface's area)
        b = b / np.sqrt(flat.area / (np.pi if shape == "circle" else 4.0))
    if shape == "circle":
        np.testing.assert_allclose(np.linalg.norm(b, axis=1), 1.0, rtol=1e-12)
    else:
        np.testing.assert_allclose(np.abs(b).max(axis=1), 1.0, rtol=1e-12)
        assert np.count_nonzero(np.isclose(np.abs(b), 1.0).all(axis=1)) == 4  # the corners


def test_harmonic_map_has_linear_precision_and_tutte_does_not():
    """On a jittered planar grid with the square boundary (an affine image of the unit
    square's), the harmonic map is that affine map everywhere; Tutte's is not."""
    V, F = jittered_grid()
    flat = Flattener(V, F)
    affine = 2.0 * V[:, :2] - 1.0
    np.testing.assert_allclose(flat.map("harmonic", "square").uv, affine, atol=1e-12)
    assert np.abs(flat.map("tutte", "square").uv - affine).max() > 1e-3


def test_spectral_map_is_harmonic_inside_and_an_eigenvector_on_the_boundary():
    V, F = bumpy_patch()
    flat = Flattener(V, F)
    uv = flat.map("scp").uv
    K = flat.stiffness("cotan")
    red = BoundaryReduction(K, flat.disk.boundary)
    assert np.abs((K @ uv)[red.interior]).max() < 1e-10 * np.abs(K @ uv).max()
    b = len(red.boundary)
    local = np.full(len(V), -1)
    local[red.boundary] = np.arange(b)
    S = sp.block_diag([red.S, red.S]).toarray() - area_matrix(local[flat.halfedges], b).toarray()
    x = np.concatenate([uv[red.boundary, 0], uv[red.boundary, 1]])
    lam = x @ S @ x / (x @ x)
    assert np.linalg.norm(S @ x - lam * x) < 1e-9 * np.linalg.norm(S) * np.linalg.norm(x)
    # the translations' eigenvalue is 0; the map's is the next one (doubled)
    ev = np.linalg.eigvalsh(S)
    assert ev[0] == pytest.approx(0, abs=1e-10) and ev[1] == pytest.approx(0, abs=1e-10)
    assert lam == pytest.approx(ev[2], rel=1e-8) and ev[3] == pytest.approx(ev[2], rel=1e-8)


def test_the_two_ways_to_the_schur_complement_agree():
    pytest.importorskip("sksparse")
    V, F = cap()
    disk = make_disk(V, F)
    K = cotan_laplacian(disk.V, disk.F)
    bnd = np.unique(disk.boundary)
    interior = np.setdiff1d(np.arange(len(disk.V)), bnd)
    K_IB = sp.csr_matrix(K[interior][:, bnd])
    S1, ext1 = _by_factor(K, interior, bnd)
    S2, ext2 = _by_solves(K, interior, bnd, K_IB, None, None)
    Kd = K.toarray()
    S_ref = Kd[np.ix_(bnd, bnd)] - Kd[np.ix_(bnd, interior)] @ np.linalg.solve(
        Kd[np.ix_(interior, interior)], Kd[np.ix_(interior, bnd)]
    )
    np.testing.assert_allclose(S1, S_ref, atol=1e-10 * np.abs(S_ref).max())
    np.testing.assert_allclose(S2, S_ref, atol=1e-10 * np.abs(S_ref).max())
    r = np.random.default_rng(2).normal(size=(len(interior), 2))
    want = np.linalg.solve(Kd[np.ix_(interior, interior)], r)
    np.testing.assert_allclose(ext1(r), want, atol=1e-10 * np.abs(want).max())
    np.testing.assert_allclose(ext2(r), want, atol=1e-10 * np.abs(want).max())


def test_arap_energy_never_increases_and_each_step_is_optimal():
    """E(u_{k+1}, R(u_{k+1})) ≤ E(u_k, R(u_k)); the global step's map is a minimum for the
    rotations it used (the gradient vanishes at the free vertices), and the local step's
    rotations beat turned ones."""
    V, F = cap()
    flat = Flattener(V, F)
    solver = flat.arap()
    solver.run(15)
    E = np.array(solver.energies)
    assert np.all(np.diff(E) <= 1e-12 * E[0]) and E[-1] < E[0]
    # the global step: the ARAP energy with the rotations fixed, as a function of u
    R = solver.rotations
    fr = solver.frames

    def energy(uv):
        return float(fr.area @ np.sum((jacobians(fr, flat.disk.F, uv) - R) ** 2, axis=(1, 2)))

    uv = solver._global()
    base = energy(uv)
    rng = np.random.default_rng(4)
    for _ in range(5):
        du = rng.normal(size=uv.shape) * 1e-4
        du[solver.pinned] = 0.0
        assert energy(uv + du) >= base - 1e-14 * base
        assert energy(uv - du) >= base - 1e-14 * base
    # the local step
    J = jacobians(fr, flat.disk.F, solver.uv)
    misfit = fr.area @ np.sum((J - solver.rotations) ** 2, axis=(1, 2))
    assert misfit == pytest.approx(solver.energy, rel=1e-12)
    c, s = np.cos(0.01), np.sin(0.01)
    turned = solver.rotations @ np.array([[c, -s], [s, c]])
    assert fr.area @ np.sum((J - turned) ** 2, axis=(1, 2)) > solver.energy


@pytest.mark.parametrize("method", ["lscm", "arap", "scp"])
def test_a_developable_strip_flattens_without_distortion(method):
    """A piece of a cylinder is isometric to a plane rectangle: the conformal maps and ARAP
    find it, with angle and area distortion below 1e-6."""
    V, F = cylinder_strip()
    s = Flattener(V, F).map(method, iters=5 if method == "arap" else None).summary()
    assert s["angle_max"] - 1.0 < 1e-6
    assert s["area_max"] < 1e-6
    assert s["flipped"] == 0


def test_arap_from_a_scaled_start_recovers_the_isometry():
    V, F = grid(6, 6)
    solver = ARAP(V, F, 3.0 * V[:, :2])
    solver.run(2)
    assert solver.energy < 1e-12  # (round-off of ‖J‖² + 2 − 2r)
    assert similarity_residual(solver.uv, V[:, :2]) < 1e-10
    assert image_area(solver.uv, make_disk(V, F).table.boundary_halfedges()) == pytest.approx(1)


def test_lscm_of_a_planar_mesh_is_a_rigid_motion():
    """Zero conformal energy: the layout itself, the pins at their true distance."""
    V, F = jittered_grid()
    uv = Flattener(V, F).map("lscm").uv
    D3 = np.linalg.norm(V[:, None, :2] - V[None, :, :2], axis=2)
    D2 = np.linalg.norm(uv[:, None] - uv[None, :], axis=2)
    np.testing.assert_allclose(D2, D3, atol=1e-12)


# ------------------------------------------------------------------------------ disks


def test_a_disk_flattens_as_it_is():
    V, F = bumpy_patch()
    disk = make_disk(V, F)
    assert disk.how == "disk" and disk.messages == ()
    np.testing.assert_array_equal(disk.source, np.arange(len(V)))
    np.testing.assert_array_equal(disk.F, F)
    assert len(disk.cut_edges) == 0 and disk.holes == ()


def test_holes_stay_free_and_the_longest_loop_is_the_outer_one():
    V, F = annulus()
    disk = make_disk(V, F)
    assert disk.how == "holes" and len(disk.holes) == 1
    assert "longest" in disk.messages[0] and "hole" in disk.messages[0]
    outer = disk.V[disk.outer]
    assert np.ptp(outer[:, 0]) == pytest.approx(1.0)  # the square's rim, not the hole's
    uvmap = flatten(V, F, "tutte")
    np.testing.assert_allclose(np.linalg.norm(uvmap.uv[disk.outer], axis=1), 1.0)
    assert np.all(np.linalg.norm(uvmap.uv[disk.holes[0]], axis=1) < 0.99)  # free


@pytest.mark.parametrize(
    "make, how",
    [(lambda: torus_mesh(16, 8), "genus-cut"), (lambda: icosphere(2), "slit")],
)
def test_closed_meshes_are_cut_to_a_disk(make, how):
    """One boundary loop, Euler characteristic 1, faces unchanged in the input's numbering,
    every cut edge an edge of the input and on the disk's boundary twice."""
    V, F = make()
    disk = make_disk(V, F)
    assert disk.how == how and disk.messages
    assert len(boundary_loops(disk.F)) == 1 and disk.holes == ()
    n_edges = len(
        np.unique(
            np.sort(
                np.concatenate([disk.F[:, [0, 1]], disk.F[:, [1, 2]], disk.F[:, [2, 0]]]), axis=1
            ),
            axis=0,
        )
    )
    assert disk.n_vertices - n_edges + len(disk.F) == 1
    np.testing.assert_array_equal(disk.input_faces(), F)
    np.testing.assert_allclose(disk.V, V[disk.source])
    input_edges = {
        tuple(e)
        for e in np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    }
    assert all(tuple(e) in input_edges for e in disk.cut_edges)
    outer_input = disk.source[disk.outer]
    pairs = {tuple(sorted(p)) for p in zip(outer_input, np.roll(outer_input, -1), strict=True)}
    assert {tuple(e) for e in disk.cut_edges} <= pairs


def test_a_tetrahedron_is_slit_along_two_edges():
    """Every pair of its vertices is an edge, and a lone cut edge doubles no vertex: the slit
    goes one edge further (found by the hostile corpus: an IndexError before)."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    disk = make_disk(V, F)
    assert disk.how == "slit" and len(disk.cut_edges) == 2 and len(disk.outer) == 4
    assert flatten(V, F, "tutte").summary()["flipped"] == 0


def test_non_manifold_vertices_are_split_into_their_fans():
    """Two triangles meeting at a vertex are two pieces once it is split: refused, naming F;
    a vertex where a closed fan meets an open one is split and the mesh flattens."""
    bowtie_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0.0]])
    bowtie_F = np.array([[0, 1, 2], [0, 3, 4]])
    with pytest.raises(MeshError, match="non-manifold vertices split the mesh into 2 pieces"):
        make_disk(bowtie_V, bowtie_F)
    # a closed tetrahedron touching a flat grid at one vertex: one piece until split
    V, F = grid(4, 4)
    apex = len(V)
    tet_V = np.array([[0.5, -0.5, 0], [0, -0.5, 0.5], [0.3, -0.9, 0.2]])
    V2 = np.vstack([V, tet_V])
    tet_F = np.array(
        [
            [0, apex, apex + 1],
            [0, apex + 1, apex + 2],
            [0, apex + 2, apex],
            [apex, apex + 2, apex + 1],
        ]
    )
    with pytest.raises(MeshError, match="pieces"):
        make_disk(V2, np.vstack([F, tet_F]))


def test_needle_faces_make_a_clear_error_and_tutte_still_works(tmp_path):
    """Cotangent weights of needle faces break LSCM's system (found by the hostile corpus: a
    LinAlgError before); the uniform weights of Tutte's map do not mind them."""
    from tests.support import hostile

    case = next(h for h in hostile.LOADABLE if h.name == "needles.obj")
    mesh = load_mesh(case.build(tmp_path))
    flat = Flattener(mesh.V, mesh.F)
    with pytest.raises(MeshError, match="not numerically positive definite") as info:
        flat.map("lscm")
    assert info.value.source == "F"
    assert flat.map("tutte").summary()["flipped"] == 0


def test_without_the_automatic_cut_a_non_disk_is_refused():
    """``cut=False``: a torus or a sphere is refused (naming F); a seam that opens the sphere
    makes it a disk all the same, and holes are no obstacle."""
    for V, F in (torus_mesh(12, 6), icosphere(1)):
        with pytest.raises(MeshError, match=r"not a disk .* cutting is off") as info:
            flatten(V, F, cut=False)
        assert info.value.source == "F"
    V, F = icosphere(1)
    path = [int(F[0, 0]), int(F[0, 1]), int(F[0, 2])]  # two edges of one face
    assert make_disk(V, F, seam=path, cut=False).how == "seam"
    assert len(make_disk(*annulus(), cut=False).holes) == 1


def test_a_seam_is_cut_and_a_splitting_seam_is_refused():
    V, F = grid(6, 6)  # vertex 6i + j at (i, j)/5; the diagonals join k and k + 7
    disk = make_disk(V, F, seam=[0, 7, 14])  # from a corner into the interior
    assert disk.how.startswith("seam") and len(disk.cut_edges) == 2
    assert disk.n_vertices == len(V) + 2  # vertices 0 and 7 doubled; 14 (the slit's tip) not
    assert len(disk.holes) == 0
    inner = make_disk(V, F, seam=[8, 15, 22])  # an inner slit: a second boundary loop
    assert len(inner.holes) == 1 and len(inner.holes[0]) == 4
    with pytest.raises(MeshError, match="seam: the seam cuts the mesh into 2 pieces"):
        make_disk(V, F, seam=[0, 7, 14, 21, 28, 35])  # corner to corner


def test_vertices_in_no_face_are_left_out(tmp_path):
    V, F = bumpy_patch(5)
    V2 = np.vstack([V, [[9.0, 9.0, 9.0]]])
    flat = Flattener(V2, F)
    assert flat.disk.n_vertices == len(V) and flat.disk.n_input == len(V) + 1
    uvmap = flat.map("harmonic")
    np.testing.assert_allclose(uvmap.uv, flatten(V, F, "harmonic").uv)
    flat.save_obj(tmp_path / "out.obj", uvmap)
    assert load_mesh(tmp_path / "out.obj").n_vertices == len(V)  # (the loader drops it)


def test_maps_share_the_operators_and_give_a_table():
    V, F = cap()
    flat = Flattener(V, F)
    maps = [flat.map(m) for m in ("tutte", "harmonic", "lscm", "scp")]
    maps.append(flat.map("arap", iters=4))
    assert flat.map("tutte", "square").method == "tutte"
    table = distortion_table(maps)
    assert [r["method"] for r in table] == ["tutte", "harmonic", "lscm", "scp", "arap"]
    assert all(r["angle_mean"] >= 1.0 and r["seconds"] >= 0 for r in table)
    assert table[-1]["iterations"] == 4 and len(maps[-1].energies) == 5
    assert table[1]["angle_mean"] < table[0]["angle_mean"]  # cotangent weights: more conformal
    assert table[2]["angle_mean"] < table[1]["angle_mean"]  # a free boundary: more still
    corner = maps[0].corner_uv()
    np.testing.assert_array_equal(corner[3:6], maps[0].uv[flat.disk.F[1]])
    uv01 = unit_square_uv(maps[2].uv)
    assert uv01.min() >= 0 and uv01.max() <= 1 and np.isclose(np.ptp(uv01, axis=0).max(), 1)


def test_a_clicked_face_gives_its_ellipse():
    V, F = cap()
    d = flatten(V, F, "tutte").distortion()
    f = int(np.argmax(d.angle))
    e = d.ellipse(f)
    assert (e.sigma1, e.sigma2) == pytest.approx((d.sigma1[f], d.sigma2[f]))
    np.testing.assert_allclose(
        e.jacobian @ (e.frame.T @ e.surface_axes), e.uv_axes * [e.sigma1, e.sigma2], atol=1e-12
    )
    np.testing.assert_allclose(e.frame.T @ e.frame, np.eye(2), atol=1e-14)


def test_cancel_stops_the_long_maps():
    V, F = cap()
    flat = Flattener(V, F)
    stop = threading.Event()
    stop.set()
    with pytest.raises(Cancelled):
        Flattener(V, F, cancel=stop)
    with pytest.raises(Cancelled):
        flat.map("scp", cancel=stop)
    with pytest.raises(Cancelled):
        flat.arap(cancel=stop)
    solver = flat.arap()
    calls = []

    def progress(fraction, message):
        calls.append(message)
        if len(calls) == 3:
            stop.set()

    stop.clear()
    with pytest.raises(Cancelled):
        solver.run(10, progress=progress, cancel=stop)
    assert solver.iterations == 3 and len(solver.energies) == 4


# ------------------------------------------------------------------------------ libigl


REFERENCE_DISKS = [
    "grid.obj",
    "camelhead.obj",
    "lilium_s.obj",
    "terrain.obj",
    "cap",
    "cut torus",
    "slit sphere",
]


@pytest.mark.parametrize("name", REFERENCE_DISKS)
def test_harmonic_and_tutte_equal_libigl(name, shared_mesh):
    """The same outer loop and circle: igl.harmonic (cotangent weights) and libigl's
    min_quad_with_fixed on its uniform Laplacian D − A (Tutte), to 1e-8."""
    V, F = shipped_or_generated(name, shared_mesh)
    flat = Flattener(V, F)
    Vd, Fd, loop = flat.disk.V, flat.disk.F, flat.disk.outer
    bc = boundary_positions(Vd, loop, "circle")
    ref = igl.harmonic(Vd, Fd, loop, bc, 1)
    np.testing.assert_allclose(flat.map("harmonic").uv, ref, atol=1e-8)
    A = igl.adjacency_matrix(Fd).astype(float)
    Q = sp.csc_matrix(sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A)
    n = len(Vd)
    tutte = igl.min_quad_with_fixed(
        Q, np.zeros((n, 2)), loop, bc, sp.csc_matrix((0, n)), np.zeros((0, 2)), True
    )
    np.testing.assert_allclose(flat.map("tutte").uv, tutte, atol=1e-8)
    np.testing.assert_allclose(
        cotan_laplacian(Vd, Fd).toarray(), -cotan_stiffness(Vd, Fd).toarray(), atol=1e-10
    )
    np.testing.assert_allclose(graph_laplacian(flat.disk.table).toarray(), Q.toarray())


@pytest.mark.parametrize("name", REFERENCE_DISKS)
def test_lscm_equals_libigl_up_to_a_similarity(name, shared_mesh):
    """With our pins at our positions, igl.lscm gives our map; with the same two vertices
    pinned elsewhere, the same map up to a similarity (1e-6). (Other pinned vertices give
    another map: the bias the spectral map removes.)"""
    V, F = shipped_or_generated(name, shared_mesh)
    uvmap = Flattener(V, F).map("lscm")
    Vd, Fd = uvmap.disk.V, uvmap.disk.F
    pins = np.array(uvmap.pins)
    d = np.linalg.norm(Vd[pins[0]] - Vd[pins[1]])
    same, _ = igl.lscm(Vd, Fd, pins, np.array([[0, 0], [d, 0.0]]))
    np.testing.assert_allclose(uvmap.uv, same, atol=1e-8 * d)
    moved, _ = igl.lscm(Vd, Fd, pins, np.array([[0.3, -2.0], [1.0, 5.0]]))
    assert similarity_residual(uvmap.uv, moved) < 1e-6


def test_flip_count_equals_libigls():
    """A vertex dragged over its neighbours folds faces: the same ones libigl finds."""
    V, F = bumpy_patch()
    uv = Flattener(V, F).map("lscm").uv.copy()
    uv[F[5, 0]] = uv[F[5, 1]] + 3 * (uv[F[5, 2]] - uv[F[5, 1]])  # fold a vertex over
    d = measure_distortion(V, F, uv)
    flipped = np.flatnonzero(d.flipped)
    assert len(flipped) > 0
    np.testing.assert_array_equal(np.sort(igl.flipped_triangles(uv, F)), flipped)


SCP_DISKS = [
    "grid.obj",
    "bumpy patch",
    "cap",
    "cylinder strip",
    "jittered grid",
]


@pytest.mark.parametrize("name", SCP_DISKS)
def test_spectral_map_matches_lscms_angle_distortion(name, shared_mesh):
    """Within 1 % on the bundled disk and the generated disks (a convex outline: both near
    their common conformal optimum; on cut meshes LSCM's pins cost more, see below)."""
    V, F = shipped_or_generated(name, shared_mesh)
    flat = Flattener(V, F)
    lscm = flat.map("lscm").summary()["angle_mean"]
    scp = flat.map("scp").summary()["angle_mean"]
    assert abs(scp - lscm) <= 0.01 * lscm


@pytest.mark.parametrize("name", [*SHARED_DISKS, "cut torus", "slit sphere"])
def test_spectral_map_is_never_worse_than_lscm_on_other_disks(name, shared_mesh):
    """On the real disks and the cut ones the two differ where LSCM's pins pull (1–2 % on
    terrain, the cut torus and the slit sphere, 45 % on cow_small, a sphere opened by a tiny
    hole), always in the spectral map's favour."""
    V, F = shipped_or_generated(name, shared_mesh)
    flat = Flattener(V, F)
    lscm = flat.map("lscm").summary()["angle_mean"]
    assert flat.map("scp").summary()["angle_mean"] <= 1.01 * lscm


def test_spectral_map_equals_a_dense_reference(spd_backend):
    """The Fiedler pair of the dense boundary pencil (np.linalg on the Schur complement),
    extended harmonically: our map up to a similarity, on both solver back ends (the Schur
    complement from a partial factorization, or from solves)."""
    V, F = cap()
    flat = Flattener(V, F)
    Kd = flat.stiffness("cotan").toarray()
    bnd = np.unique(flat.disk.boundary)
    inner = np.setdiff1d(np.arange(len(Kd)), bnd)
    S = Kd[np.ix_(bnd, bnd)] - Kd[np.ix_(bnd, inner)] @ np.linalg.solve(
        Kd[np.ix_(inner, inner)], Kd[np.ix_(inner, bnd)]
    )
    b = len(bnd)
    local = np.full(len(Kd), -1)
    local[bnd] = np.arange(b)
    P = np.block([[S, 0 * S], [0 * S, S]]) - area_matrix(local[flat.halfedges], b).toarray()
    _, vec = np.linalg.eigh(P)
    x = vec[:, 2]
    uv = np.zeros((len(Kd), 2))
    uv[bnd] = np.stack([x[:b], x[b:]], axis=1)
    uv[inner] = -np.linalg.solve(Kd[np.ix_(inner, inner)], Kd[np.ix_(inner, bnd)] @ uv[bnd])
    assert similarity_residual(flat.map("scp").uv, uv) < 1e-8


# ------------------------------------------------------------------------------ bad input

V0, F0 = grid(4, 4)


@pytest.mark.parametrize(
    "call, source, words",
    [
        (lambda: flatten(V0[:, :2], F0), "V", "shape"),
        (lambda: flatten(V0.astype(str), F0), "V", "numbers"),
        (lambda: flatten(V0 > 0, F0), "V", "boolean"),
        (lambda: flatten(V0 + 1j, F0), "V", "complex"),
        (lambda: flatten(np.where(np.arange(16)[:, None] == 3, np.nan, V0), F0), "V", "nan"),
        (lambda: flatten(V0, F0 + 0.5), "F", "integers"),
        (lambda: flatten(V0, F0[:, :2]), "F", "shape"),
        (lambda: flatten(V0, F0 + 100), "F", "vertices"),
        (lambda: flatten(V0, -F0 - 1), "F", "index -"),
        (lambda: flatten(V0, F0[:0]), "F", "no faces"),
        (lambda: flatten(V0, F0, "conformal"), "method", "unknown method"),
        (lambda: flatten(V0, F0, "tutte", "oval"), "boundary", "circle or square"),
        (lambda: flatten(V0, F0, "tutte", "free"), "boundary", "circle or square"),
        (lambda: flatten(V0, F0, "lscm", "circle"), "boundary", "free"),
        (lambda: flatten(V0, F0, "scp", "square"), "boundary", "free"),
        (lambda: flatten(V0, F0, "harmonic", iters=3), "iters", "arap only"),
        (lambda: flatten(V0, F0, "arap", iters=-1), "iters", "between"),
        (lambda: flatten(V0, F0, "arap", iters=10**9), "iters", "between"),
        (lambda: flatten(V0, F0, "arap", iters=2.5), "iters", "integer"),
        (lambda: flatten(V0, F0, "arap", iters=True), "iters", "integer"),
        (lambda: flatten(V0, F0, seam=[0]), "seam", "two vertices"),
        (lambda: flatten(V0, F0, seam=[[0, 1]]), "seam", "1-d"),
        (lambda: flatten(V0, F0, seam=[0, 99]), "seam", "out of range"),
        (lambda: flatten(V0, F0, seam=[0, 5.5]), "seam", "integers"),
        (lambda: flatten(V0, F0, seam=["a", "b"]), "seam", "numbers"),
        (lambda: flatten(V0, F0, seam=[0, 10]), "seam", "not joined by an edge"),
        (lambda: measure_distortion(V0, F0, np.zeros((16, 3))), "uv", "shape"),
        (lambda: measure_distortion(V0, F0, np.full((16, 2), np.inf)), "uv", "nan or infinite"),
        (lambda: flatten(V0, F0).distortion().ellipse(99), "face", "out of range"),
        (lambda: flatten(V0, F0).distortion().ellipse(1.5), "face", "integer"),
        (lambda: flatten(V0, F0).distortion().ellipse([1, 2]), "face", "integer"),
        (lambda: ARAP(V0, F0, np.zeros((3, 2))), "init", "shape"),
        (lambda: ARAP(V0, F0, V0[:, :2], pinned=[99]), "pinned", "vertex indices"),
        (lambda: boundary_positions(V0, np.arange(2), "circle"), "boundary", "at least three"),
    ],
)
def test_bad_arguments_are_mesh_errors_naming_the_argument(call, source, words):
    with pytest.raises(MeshError) as info:
        call()
    assert info.value.source == source
    assert words in str(info.value).lower()


def two_grids():
    V, F = grid(3, 3)
    return np.vstack([V, V + np.array([5.0, 0, 0])]), np.vstack([F, F + len(V)])


@pytest.mark.parametrize(
    "make, words",
    [
        (two_grids, "2 connected components"),
        (lambda: (V0, np.vstack([F0, F0[:1]])), "non-manifold"),
        (lambda: (V0, np.vstack([F0[:1, ::-1], F0[1:]])), "inconsistently oriented"),
        (lambda: (np.vstack([V0, V0[:1]]), np.vstack([F0, [[0, 1, 16]]])), "zero area"),
    ],
)
def test_meshes_that_cannot_be_flattened_are_refused(make, words):
    V, F = make()
    with pytest.raises(MeshError, match=words) as info:
        Flattener(V, F)
    assert info.value.source == "F"


def test_the_modules_examples_run():
    for module in (arap, flattener):
        assert doctest.testmod(module, raise_on_error=False).failed == 0


def test_every_map_on_both_solver_back_ends(spd_backend):
    """CHOLMOD (scikit-sparse) and the bundled fallback: harmonic as libigl's, the Schur
    complement by the way the back end allows, ARAP lowering its energy."""
    V, F = cap()
    flat = Flattener(V, F)
    Vd, Fd, loop = flat.disk.V, flat.disk.F, flat.disk.outer
    bc = boundary_positions(Vd, loop, "circle")
    np.testing.assert_allclose(
        flat.map("harmonic").uv, igl.harmonic(Vd, Fd, loop, bc, 1), atol=1e-8
    )
    red = BoundaryReduction(flat.stiffness("cotan"), flat.disk.boundary)
    assert red.method == ("partial factorization" if spd_backend == "cholmod" else "solves")
    assert flat.map("arap", iters=3).energies[-1] < flat.map("arap", iters=0).energies[0]
