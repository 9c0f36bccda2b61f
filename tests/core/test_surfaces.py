"""Parametric surfaces: exact forms and curvature, numeric derivatives, meshing, convergence.

Tier 1: closed-form values (helicoid, sphere, torus, cylinder, saddles, catenoid) worked out by
hand from p(u, v). Tier 2: invariants (Euler's theorem, extremes of κₙ, k1 + k2 = 2H,
watertight welded meshes). Tier 3: independent references (exact vs numeric derivatives,
primitives.torus_mesh, the core's discrete estimators converging to the analytic values).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import meshlap_core
from meshlap_core import primitives, surfaces
from meshlap_core.curvature import convergence, refinement, vertex_normals
from meshlap_core.curvature.convergence import convergence_study
from meshlap_core.errors import MeshError
from meshlap_core.io import load_mesh
from meshlap_core.surfaces import (
    ParametricSurface,
    get_surface,
    mesh_surface,
    normal_curvature,
    normal_curvature_curve,
    point_geometry,
    surface_curvature_fields,
    surface_derivatives,
)
from meshlap_core.topology import boundary_loops, edge_face_counts, euler_characteristic

NUMERIC = ("complex-step", "central")


def _random_uv(s: ParametricSurface, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Random parameters well inside the domain (away from poles)."""
    rng = np.random.default_rng(seed)
    u0, u1, v0, v1 = s.domain
    return (
        rng.uniform(u0 + 0.05 * (u1 - u0), u1 - 0.05 * (u1 - u0), n),
        rng.uniform(v0 + 0.05 * (v1 - v0), v1 - 0.05 * (v1 - v0), n),
    )


# ------------------------------------------------------------------------------------------
# tier 1: exact values
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["exact", *NUMERIC])
@pytest.mark.parametrize("u, v", [(0.0, 0.0), (0.5, 1.0), (1.0, 4.0), (0.25, 2 * np.pi)])
def test_helicoid_exact_values(u: float, v: float, method: str) -> None:
    g = point_geometry("helicoid", u, v, method=method)
    w = 1 + u * u
    assert g.E == pytest.approx(1, abs=1e-10)
    assert g.F == pytest.approx(0, abs=1e-10)
    assert g.G == pytest.approx(w, abs=1e-10)
    assert g.e == pytest.approx(0, abs=1e-9)
    assert g.g == pytest.approx(0, abs=1e-9)
    # f = -p_uv . n = -(-sin v, cos v, 0) . (sin v, -cos v, u)/√w = 1/√w
    assert g.f == pytest.approx(1 / np.sqrt(w), abs=1e-9)
    assert g.K == pytest.approx(-1 / w**2, abs=1e-9)
    assert g.H == pytest.approx(0, abs=1e-9)
    assert g.k1 == pytest.approx(1 / w, abs=1e-9)
    assert g.k2 == pytest.approx(-1 / w, abs=1e-9)
    assert g.classification == "hyperbolic"
    # n = (p_u x p_v)/|.| = (sin v, -cos v, u)/sqrt(1+u²)
    np.testing.assert_allclose(g.n, np.array([np.sin(v), -np.cos(v), u]) / np.sqrt(w), atol=1e-12)


def test_helicoid_origin_normal_curvature_is_sin_2theta() -> None:
    # at the origin E = G = 1, F = e = g = 0, f = 1: κₙ = 2 f cs / 1 = sin 2θ
    theta, kn = normal_curvature_curve("helicoid", 0.0, 0.0)
    assert theta.shape == kn.shape == (361,)
    assert theta[0] == 0 and theta[-1] == pytest.approx(2 * np.pi)
    np.testing.assert_allclose(kn, np.sin(2 * theta), atol=1e-12)
    g = point_geometry("helicoid", 0.0, 0.0)
    # I is the identity at the origin: the tangent-plane and the parameter angles agree
    assert g.theta_max == g.theta_uv_max == pytest.approx(np.pi / 4)  # sin 2θ = +1
    assert g.theta_min == g.theta_uv_min == pytest.approx(3 * np.pi / 4)  # sin 2θ = -1


@pytest.mark.parametrize("r", [0.5, 1.0, 2.0])
def test_sphere_is_umbilic_with_K_one_over_r2(r: float) -> None:
    s = get_surface("sphere", r=r)
    for u, v in [(0.3, 0.1), (np.pi / 2, 3.0), (2.9, 6.0)]:
        g = point_geometry(s, u, v)
        assert g.K == pytest.approx(1 / r**2, rel=1e-12)
        # n points outwards, the surface bends away from it: κ = +1/r (the project's sign)
        assert g.k1 == pytest.approx(1 / r, rel=1e-12)
        assert g.k2 == pytest.approx(1 / r, rel=1e-12)
        assert g.H == pytest.approx(1 / r, rel=1e-12)
        np.testing.assert_allclose(g.n, g.p / r, atol=1e-12)
        assert g.classification == "umbilic"
        _, kn = normal_curvature_curve(s, u, v, 50)
        np.testing.assert_allclose(kn, 1 / r, rtol=1e-12)


def test_torus_sign_of_K_inside_and_outside() -> None:
    R, r = 3.0, 1.0
    s = get_surface("torus", R=R, r=r)
    outside = point_geometry(s, 0.7, 0.0)
    inside = point_geometry(s, 0.7, np.pi)
    top = point_geometry(s, 0.7, np.pi / 2)
    assert outside.K == pytest.approx(1 / (r * (R + r)), rel=1e-12)
    assert inside.K == pytest.approx(-1 / (r * (R - r)), rel=1e-12)
    assert outside.classification == "elliptic"
    assert inside.classification == "hyperbolic"
    assert top.K == pytest.approx(0, abs=1e-12)
    assert top.classification == "parabolic"
    u, v = _random_uv(s, 200)
    cf = surface_curvature_fields(s, u, v)
    np.testing.assert_allclose(cf.K, np.cos(v) / (r * (R + r * np.cos(v))), atol=1e-12)
    # the normal points outwards, away from the tube's core circle
    core = np.stack([R * np.cos(u), R * np.sin(u), np.zeros_like(u)], axis=1)
    assert np.all(np.sum(cf.n * (s(u, v) - core), axis=1) > 0)


@pytest.mark.parametrize("r", [0.5, 2.0])
def test_cylinder_is_parabolic(r: float) -> None:
    g = point_geometry(get_surface("cylinder", r=r), 1.1, 0.4)
    assert g.K == pytest.approx(0, abs=1e-12)
    # outward n: the circle around the axis bends away from it, κ = +1/r; flat along the axis
    assert g.k1 == pytest.approx(1 / r, rel=1e-12)
    assert g.k2 == pytest.approx(0, abs=1e-12)
    assert g.classification == "parabolic"
    np.testing.assert_allclose(np.abs(g.dir2), [0, 0, 1], atol=1e-12)  # flat along the axis
    assert abs(g.dir1[2]) < 1e-12  # curved around it


def test_saddles_at_the_origin() -> None:
    # z = u² - v², n = +z: e = -p_uu . n = -2, g = +2 (bends towards n along u, away along v)
    g = point_geometry("saddle", 0.0, 0.0)
    assert (g.e, g.f, g.g) == pytest.approx((-2, 0, 2), abs=1e-12)
    assert (g.k1, g.k2, g.K, g.H) == pytest.approx((2, -2, -4, 0), abs=1e-12)
    np.testing.assert_allclose(np.abs(g.dir1), [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(np.abs(g.dir2), [1, 0, 0], atol=1e-12)
    m = point_geometry("monkey_saddle", 0.0, 0.0)
    assert (m.e, m.f, m.g) == pytest.approx((0, 0, 0), abs=1e-12)
    assert m.classification == "planar"
    assert point_geometry("monkey_saddle", 0.5, 0.2).classification == "hyperbolic"


def test_catenoid_numeric_derivatives_give_the_minimal_surface() -> None:
    c = 1.5
    s = get_surface("catenoid", c=c)
    assert s.derivatives is None  # exercises the numeric path
    u, v = _random_uv(s, 100)
    cf = surface_curvature_fields(s, u, v)
    np.testing.assert_allclose(cf.H, 0, atol=1e-9)
    np.testing.assert_allclose(cf.K, -1 / (c**2 * np.cosh(v / c) ** 4), atol=1e-9)


# ------------------------------------------------------------------------------------------
# tier 2: invariants
# ------------------------------------------------------------------------------------------

POINTS = [
    ("helicoid", 0.6, 2.0),
    ("torus", 0.3, 2.5),
    ("torus", 1.0, 0.4),
    ("catenoid", 1.0, 0.5),
    ("saddle", 0.3, -0.4),
    ("monkey_saddle", 0.4, 0.7),
    ("cylinder", 2.0, 1.0),
]


@pytest.mark.parametrize("name, u, v", POINTS)
def test_euler_theorem(name: str, u: float, v: float) -> None:
    """κₙ(θ) = κ₁cos²φ + κ₂sin²φ, φ the metric angle from the first principal direction."""
    g = point_geometry(name, u, v)
    theta = np.linspace(0, 2 * np.pi, 97)
    kn = normal_curvature(name, u, v, theta)
    t = np.cos(theta)[:, None] * g.p_u + np.sin(theta)[:, None] * g.p_v
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    cos_phi = t @ g.dir1
    sin_phi = t @ g.dir2
    np.testing.assert_allclose(cos_phi**2 + sin_phi**2, 1, atol=1e-10)  # dir1 ⟂ dir2
    np.testing.assert_allclose(kn, g.k1 * cos_phi**2 + g.k2 * sin_phi**2, atol=1e-10)


@pytest.mark.parametrize("name, u, v", POINTS)
def test_extremes_of_normal_curvature_are_the_principal_curvatures(
    name: str, u: float, v: float
) -> None:
    g = point_geometry(name, u, v)
    theta, kn = normal_curvature_curve(name, u, v, 2001)
    for sign, k, t_ext in ((-1, g.k1, g.theta_uv_max), (1, g.k2, g.theta_uv_min)):
        t0 = theta[np.argmin(sign * kn)]
        res = minimize_scalar(
            lambda t, sg=sign: sg * normal_curvature(name, u, v, t),
            bounds=(t0 - 0.01, t0 + 0.01),
            method="bounded",
            options={"xatol": 1e-10},
        )
        assert sign * res.fun == pytest.approx(k, abs=1e-9)
        assert normal_curvature(name, u, v, t_ext) == pytest.approx(k, abs=1e-12)
        assert 0 <= t_ext < np.pi
        # the located extreme is at t_ext or t_ext + π
        assert min(abs((res.x - t_ext + np.pi / 2) % np.pi - np.pi / 2), 1) < 1e-4
    assert g.k1 >= g.k2
    assert g.k1 + g.k2 == pytest.approx(2 * g.H, abs=1e-12)
    assert g.k1 * g.k2 == pytest.approx(g.K, abs=1e-12)
    for d in (g.dir1, g.dir2):
        assert np.linalg.norm(d) == pytest.approx(1)
        assert abs(d @ g.n) < 1e-12
    assert g.dir1 @ g.dir2 == pytest.approx(0, abs=1e-12)


def test_point_classification_rules() -> None:
    assert surfaces.classify(0.0, 0.0) == "planar"
    assert surfaces.classify(2.0, 2.0) == "umbilic"
    assert surfaces.classify(0.0, -1.0) == "parabolic"
    assert surfaces.classify(2.0, 1.0) == "elliptic"
    assert surfaces.classify(-1.0, -2.0) == "elliptic"
    assert surfaces.classify(1.0, -1.0) == "hyperbolic"


# ------------------------------------------------------------------------------------------
# tier 3: numeric vs exact derivatives
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", [n for n in surfaces.SURFACES if get_surface(n).derivatives])
@pytest.mark.parametrize("method", NUMERIC)
def test_numeric_derivatives_match_exact(name: str, method: str) -> None:
    s = get_surface(name)
    u, v = _random_uv(s, 300, seed=1)
    exact = surface_derivatives(s, u, v, "exact")
    num = surface_derivatives(s, u, v, method)
    for k in ("p", "p_u", "p_v", "p_uu", "p_uv", "p_vv"):
        np.testing.assert_allclose(getattr(num, k), getattr(exact, k), atol=1e-8, err_msg=k)


def test_adding_a_surface_needs_only_p() -> None:
    # elliptic paraboloid z = (a u² + b v²)/2, n = +z at the origin: it bends towards n,
    # so κ = -a along u and -b along v; a > b gives k1 = -b (along v), k2 = -a
    a, b = 3.0, 0.5
    s = ParametricSurface(
        "paraboloid",
        lambda u, v: np.stack(np.broadcast_arrays(u, v, (a * u * u + b * v * v) / 2), axis=-1),
        (-1, 1, -1, 1),
    )
    g = point_geometry(s, 0.0, 0.0)
    assert (g.k1, g.k2, g.K, g.H) == pytest.approx((-b, -a, a * b, -(a + b) / 2), abs=1e-9)
    assert g.classification == "elliptic"
    np.testing.assert_allclose(np.abs(g.dir1), [0, 1, 0], atol=1e-9)


def test_non_analytic_p_falls_back_to_central_differences() -> None:
    # np.real drops the complex step, so "auto" must not use it
    s = ParametricSurface(
        "flat-z",
        lambda u, v: np.stack(
            np.broadcast_arrays(np.real(u), np.real(v), np.real(u * u + v * v) / 2), axis=-1
        ),
        (-1, 1, -1, 1),
    )
    g = point_geometry(s, 0.0, 0.0)
    assert (g.k1, g.k2) == pytest.approx((-1, -1), abs=1e-8)  # bends towards n = +z
    assert g.classification == "umbilic"
    with pytest.raises(MeshError, match="complex"):
        surface_derivatives(s, 0.0, 0.0, "complex-step")


# ------------------------------------------------------------------------------------------
# bad input
# ------------------------------------------------------------------------------------------


def test_unknown_surface_lists_known_ones() -> None:
    with pytest.raises(MeshError, match="known surfaces: helicoid, sphere, torus"):
        get_surface("klein_bottle")
    with pytest.raises(MeshError, match="no parameter q"):
        get_surface("torus", q=1.0)
    assert get_surface("monkey-saddle").name == "monkey_saddle"


def test_out_of_domain_names_the_argument() -> None:
    with pytest.raises(MeshError, match=r"^u: 2 is outside"):
        point_geometry("helicoid", 2.0, 0.0)
    with pytest.raises(MeshError, match=r"^v: -1 is outside"):
        point_geometry("helicoid", 0.5, -1.0)
    with pytest.raises(MeshError, match=r"^v: nan"):
        point_geometry("helicoid", 0.5, float("nan"))


def test_pole_is_reported_as_singular() -> None:
    with pytest.raises(MeshError, match="singular"):
        point_geometry("sphere", 0.0, 1.0)


def test_bad_p_shape_and_domain() -> None:
    s = ParametricSurface("bad", lambda u, v: np.stack([u, v], axis=-1), (0, 1, 0, 1))
    with pytest.raises(MeshError, match="expected"):
        point_geometry(s, 0.5, 0.5)
    with pytest.raises(MeshError, match="u0 < u1"):
        ParametricSurface("bad", lambda u, v: u, (1, 0, 0, 1))
    with pytest.raises(MeshError, match="r < R"):
        get_surface("torus", R=1, r=2)


# ------------------------------------------------------------------------------------------
# meshing
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name, chi", [("sphere", 2), ("torus", 0)])
def test_closed_surfaces_mesh_watertight(name: str, chi: int) -> None:
    m = mesh_surface(name, (12, 10))
    _, count = edge_face_counts(m.F)
    assert np.all(count == 2)  # every edge shared by exactly two faces
    assert euler_characteristic(m.F) == chi
    assert not m.boundary.any()
    # welded: no two vertices at the same place, no degenerate face
    d = np.linalg.norm(m.V[:, None] - m.V[None], axis=2) + np.eye(len(m.V))
    assert d.min() > 1e-6
    a = np.linalg.norm(
        np.cross(m.V[m.F[:, 1]] - m.V[m.F[:, 0]], m.V[m.F[:, 2]] - m.V[m.F[:, 0]]), axis=1
    )
    assert a.min() > 1e-6
    assert len(boundary_loops(m.F)) == 0


def test_sphere_poles_collapse_to_single_vertices() -> None:
    nu, nv = 6, 9
    m = mesh_surface("sphere", (nu, nv))
    assert m.pole.sum() == 2
    assert len(m.V) == (nu - 1) * nv + 2
    assert len(m.F) == 2 * nu * nv - 2 * nv  # one triangle per cell in the two polar rows
    for p in np.flatnonzero(m.pole):
        assert np.sum(np.any(m.F == p, axis=1)) == nv
    np.testing.assert_allclose(np.sort(m.V[m.pole, 2]), [-1, 1], atol=1e-15)


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
def test_mesh_keeps_uv_and_follows_the_normal(name: str) -> None:
    s = get_surface(name)
    m = mesh_surface(s, 10)
    np.testing.assert_allclose(m.V, s(m.uv[:, 0], m.uv[:, 1]), atol=1e-14)
    ok = ~m.pole
    n_exact = surface_curvature_fields(s, m.uv[ok, 0], m.uv[ok, 1]).n
    n_mesh = vertex_normals(m.V, m.F)[ok]
    assert np.min(np.sum(n_exact * n_mesh, axis=1)) > 0.8  # same orientation everywhere


@pytest.mark.parametrize(
    "name, loops", [("helicoid", 1), ("saddle", 1), ("cylinder", 2), ("catenoid", 2)]
)
def test_open_surfaces_have_their_boundary(name: str, loops: int) -> None:
    m = mesh_surface(name, 8)
    assert len(boundary_loops(m.F)) == loops
    _, count = edge_face_counts(m.F)
    assert count.max() == 2


def test_torus_mesh_equals_primitives_torus() -> None:
    V, F = primitives.torus_mesh(32, 16)
    m = mesh_surface("torus", (32, 16))
    np.testing.assert_allclose(m.V, V, atol=1e-14)
    np.testing.assert_array_equal(m.F, F)


def test_bad_resolution() -> None:
    with pytest.raises(MeshError, match="res"):
        mesh_surface("helicoid", 0)
    with pytest.raises(MeshError, match="at least 3"):
        mesh_surface("torus", (2, 8))


# ------------------------------------------------------------------------------------------
# convergence of the discrete estimators
# ------------------------------------------------------------------------------------------


def test_exact_reference_values_used_by_the_study() -> None:
    m = mesh_surface(get_surface("sphere", r=2.0), 6)
    H, K = refinement.exact_curvature_at(get_surface("sphere", r=2.0), m.uv, m.pole)
    np.testing.assert_allclose(H, 0.5, rtol=1e-9)  # the core's sign: H > 0 with outward n
    np.testing.assert_allclose(K, 0.25, rtol=1e-9)  # including the two pole vertices


@pytest.mark.parametrize("name", ["sphere", "torus"])
def test_voronoi_cotan_H_and_deficit_K_converge(name: str) -> None:
    st = convergence_study(name, (8, 16, 32))
    for est in ("H cotan voronoi", "K deficit voronoi"):
        mx = st.errors[est]["max"]
        assert mx[1] < 0.4 * mx[0] and mx[2] < 0.4 * mx[1], (est, mx)
        assert all(o > 1.5 for o in st.errors[est]["order_max"])
    # the uniform Laplacian is not consistent: its error does not shrink
    assert st.errors["H uniform"]["max"][2] > 0.5 * st.ref_scale["H"]
    assert st.errors["H uniform"]["max"][2] >= st.errors["H uniform"]["max"][0]


def test_barycentric_area_stalls_on_icospheres() -> None:
    st = convergence_study("sphere", (2, 3, 4), mesher="icosphere")
    for q in ("H cotan", "K deficit"):
        bary = st.errors[f"{q} barycentric"]["max"]
        vor = st.errors[f"{q} voronoi"]["max"]
        assert min(bary) > 0.1  # stalls near 15 % (unit sphere: absolute = relative)
        assert bary[2] > 0.9 * bary[1]
        assert vor[2] < 0.3 * vor[1] and vor[1] < 0.3 * vor[0]  # ~4x per subdivision
        assert max(vor) < 0.03
        # the barycentric mean error still converges: the stall is at a few vertices
        mean = st.errors[f"{q} barycentric"]["mean"]
        assert mean[2] < 0.4 * mean[1]


def test_barycentric_area_fails_only_at_the_uv_sphere_poles() -> None:
    st = convergence_study("sphere", (8, 16, 32))
    bary = st.errors["K deficit barycentric"]
    assert min(bary["max"][1:]) > 0.2 and all(bary["worst_is_pole"][1:])
    cut = convergence_study("sphere", (8, 16, 32), exclude_poles=True)
    mx = cut.errors["K deficit barycentric"]["max"]
    assert mx[2] < 0.35 * mx[1]


def test_barycentric_K_converges_on_the_torus_grid() -> None:
    st = convergence_study("torus", (8, 16, 32))
    for est in ("K deficit barycentric", "H cotan barycentric"):
        mx = st.errors[est]["max"]
        assert mx[2] < 0.35 * mx[1], (est, mx)


def test_study_table_and_dict() -> None:
    st = convergence_study("torus", (6, 12))
    text = st.table()
    for est in convergence.ESTIMATORS:
        assert est in text
    d = st.to_dict()
    assert json.loads(json.dumps(d))["resolutions"] == [6, 12]
    assert len(d["errors"]["H uniform"]["order_max"]) == 1
    with pytest.raises(MeshError, match="only meshes the sphere"):
        convergence_study("torus", (1,), mesher="icosphere")


# ------------------------------------------------------------------------------------------
# outputs: figure, dict, CLI
# ------------------------------------------------------------------------------------------


def test_plot_is_written_atomically(tmp_path) -> None:
    out = tmp_path / "kn.png"
    g = surfaces.plot_normal_curvature("helicoid", 0.0, 0.0, out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["kn.png"]
    assert g.K == pytest.approx(-1)
    with pytest.raises(MeshError, match="PNG"):
        surfaces.plot_normal_curvature("helicoid", 0.0, 0.0, tmp_path / "kn.jpg")


def test_point_geometry_to_dict_is_json() -> None:
    d = point_geometry("torus", 0.2, 0.3).to_dict()
    back = json.loads(json.dumps(d))
    for k in (
        "E",
        "F",
        "G",
        "e",
        "f",
        "g",
        "K",
        "H",
        "k1",
        "k2",
        "classification",
        "dir1",
        "dir2",
        "dir1_uv",
        "dir2_uv",
        "theta_max",
        "theta_min",
        "theta_uv_max",
        "theta_uv_min",
        "signs",
        "n",
    ):
        assert k in back
    assert len(back["dir1"]) == 3 and len(back["dir1_uv"]) == 2


def test_core_import_stays_light() -> None:
    import subprocess
    import sys

    code = (
        "import sys, meshlap_core.surfaces; "
        "print(any(m.split('.')[0] in ('matplotlib', 'polyscope') for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def _cli(capsys, *argv: str) -> tuple[int, str, str]:
    from meshlap_core.cli import main

    code = main(["surface", *argv])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_cli_point_json(capsys) -> None:
    code, out, _ = _cli(capsys, "helicoid", "--u", "0.5", "--v", "1", "--json")
    assert code == 0
    d = json.loads(out)
    assert d["G"] == pytest.approx(1.25)
    assert d["f"] == pytest.approx(1 / np.sqrt(1.25))
    assert d["k1"] == pytest.approx(0.8) and d["k2"] == pytest.approx(-0.8)
    assert d["classification"] == "hyperbolic"
    assert len(d["dir1"]) == 3 and len(d["dir1_uv"]) == 2


def test_cli_errors(capsys) -> None:
    code, _, err = _cli(capsys, "sphere", "--u", "4")
    assert code == 2 and "--u" in err and "outside" in err
    code, _, err = _cli(capsys, "moebius")
    assert code == 2 and "known surfaces" in err


def test_cli_plot_mesh_and_convergence(tmp_path, capsys) -> None:
    png, obj = tmp_path / "kn.png", tmp_path / "torus.obj"
    code, out, _ = _cli(
        capsys, "torus", "--plot", str(png), "--mesh", str(obj), "--res", "12,8", "--json"
    )
    assert code == 0
    d = json.loads(out)
    assert d["mesh"]["n_vertices"] == 96 and d["mesh"]["n_faces"] == 192
    assert png.read_bytes()[:4] == b"\x89PNG"
    back = load_mesh(obj)
    m = mesh_surface("torus", (12, 8))
    np.testing.assert_allclose(back.V, m.V, atol=1e-12)
    np.testing.assert_array_equal(back.F, m.F)
    code, out, err = _cli(
        capsys, "sphere", "--convergence", "--res", "1,2", "--mesher", "icosphere", "--json"
    )
    assert code == 0
    d = json.loads(out)
    assert d["n_vertices"] == [42, 162]
    assert set(d["errors"]) == set(convergence.ESTIMATORS)
    assert "vertices" in err  # progress on stderr, not stdout


# ------------------------------------------------------------------------------------------
# singular points (issue 14, item 5)
# ------------------------------------------------------------------------------------------


def _expected_singular(name: str, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Where each catalogue surface (default parameters) degenerates, worked out by hand:
    only the sphere's and the ellipsoid's two poles (|p_u × p_v| = r² sin u, resp.
    sin u · |(bc sin u cos v, ac sin u sin v, ab cos u)|)."""
    if name in ("sphere", "ellipsoid"):
        return (u == 0.0) | (u == np.pi)
    return np.zeros(np.broadcast(u, v).shape, dtype=bool)


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
def test_singular_points_of_every_catalogue_surface(name: str) -> None:
    s = get_surface(name)
    u0, u1, v0, v1 = s.domain
    # a grid that includes every edge and corner of the domain (the poles among them)
    U, V = np.meshgrid(np.linspace(u0, u1, 13), np.linspace(v0, v1, 11), indexing="ij")
    np.testing.assert_array_equal(surfaces.is_singular(s, U, V), _expected_singular(name, U, V))
    cf = surface_curvature_fields(s, U, V)
    np.testing.assert_array_equal(cf.singular, _expected_singular(name, U, V))
    assert np.isnan(cf.K[cf.singular]).all() and np.isfinite(cf.K[~cf.singular]).all()


@pytest.mark.parametrize("r", [1e-6, 1.0, 1e6])
@pytest.mark.parametrize("u", [0.0, np.pi])
def test_both_sphere_poles_are_singular_at_every_scale(r: float, u: float) -> None:
    s = get_surface("sphere", r=r)
    assert bool(surfaces.is_singular(s, u, 0.0))
    with pytest.raises(MeshError, match=r"singular.*pole"):
        point_geometry(s, u, 0.0)
    with pytest.raises(MeshError, match="singular"):
        normal_curvature(s, u, 0.0, 0.3)
    # 1e-6 away from the pole the sphere is regular and umbilic, K = 1/r²
    inside = 1e-6 if u == 0 else np.pi - 1e-6
    g = point_geometry(s, inside, 0.0)
    assert g.K == pytest.approx(1 / r**2, rel=1e-6)
    assert g.classification == "umbilic"


def test_south_pole_cli_is_refused_like_the_north_pole(capsys) -> None:
    for u in ("0", "3.141592653589793"):
        code, out, err = _cli(capsys, "sphere", "--u", u, "--v", "0")
        assert code == 2 and out == ""
        assert err.count("\n") == 1 and err.startswith("meshlap: error: --u/--v: ")
        assert "singular" in err


def test_singular_test_is_against_the_surface_scale() -> None:
    # the mean of |p_u x p_v| over the domain is the area over the parameter area: 2r²/π
    for r in (1e-6, 1.0, 1e6):
        assert surfaces.surface_scale(get_surface("sphere", r=r)) == pytest.approx(
            2 * r * r / np.pi, rel=1e-3
        )
    assert surfaces.surface_scale("cylinder") == pytest.approx(1.0)  # |p_u x p_v| = r = 1


@pytest.mark.parametrize("scale", [1e-8, 1.0, 1e8])
def test_an_undeclared_apex_is_found_by_the_scale_test(scale: float) -> None:
    # a cone (u cos v, u sin v, u) declares no pole: |p_u x p_v| = √2 u vanishes at u = 0
    cone = ParametricSurface(
        "cone",
        lambda u, v: scale * np.stack(np.broadcast_arrays(u * np.cos(v), u * np.sin(v), u), -1),
        (0.0, 1.0, 0.0, 2 * np.pi),
    )
    v = np.linspace(0, 2 * np.pi, 7)
    assert surfaces.is_singular(cone, 0.0, v).all()
    assert not surfaces.is_singular(cone, 1e-6, v).any()
    assert not surfaces.is_singular(cone, 0.5, v).any()
    with pytest.raises(MeshError, match="area scale"):
        point_geometry(cone, 0.0, 1.0)
    # K = 0 (developable); n = (−cos v, −sin v, 1)/√2 points into the cone, so the circle
    # around the axis bends towards n: κ₂ = -1/(√2 u · scale), κ₁ = 0 along the rulings
    g = point_geometry(cone, 0.5, 1.0)
    assert g.K == pytest.approx(0, abs=1e-6 / scale**2)
    assert g.k2 == pytest.approx(-1 / (np.sqrt(2) * 0.5 * scale), rel=1e-6)
    assert g.k1 == pytest.approx(0, abs=1e-6 / scale)


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
def test_regular_points_stay_regular(name: str) -> None:
    s = get_surface(name)
    u, v = _random_uv(s, 500, seed=3)
    assert not surfaces.is_singular(s, u, v).any()
    u0, u1, v0, v1 = s.domain
    # within 1e-6 of the domain width of every edge, poles included
    eps_u, eps_v = 1e-6 * (u1 - u0), 1e-6 * (v1 - v0)
    near = np.array([u0 + eps_u, u1 - eps_u])
    assert not surfaces.is_singular(s, near[:, None], v[None, :20]).any()
    assert not surfaces.is_singular(s, u[:20, None], np.array([v0 + eps_v, v1 - eps_v])).any()


def test_flat_helicoid_is_a_disc_with_a_pole() -> None:
    s = get_surface("helicoid", c=0.0)
    assert s.poles == ("u0",) and s.closed_v
    assert surfaces.is_singular(s, 0.0, np.linspace(0, 6, 5)).all()
    g = point_geometry(s)  # the default point moves off the pole
    assert (g.u, g.K, g.H) == pytest.approx((0.5, 0.0, 0.0), abs=1e-12)
    assert g.classification == "planar"
    m = mesh_surface(s, 8)
    assert m.pole.sum() == 1 and not m.boundary[m.pole].any()  # the centre: an interior fan
    assert euler_characteristic(m.F) == 1 and len(boundary_loops(m.F)) == 1
    _, count = edge_face_counts(m.F)
    assert count.max() == 2


@pytest.mark.parametrize(
    "name, param", [("helicoid", "c"), ("saddle", "a"), ("monkey_saddle", "a")]
)
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_shape_parameters_must_be_finite(name: str, param: str, value: float) -> None:
    with pytest.raises(MeshError, match=rf"^{param}: must be a finite number"):
        get_surface(name, **{param: value})


# ------------------------------------------------------------------------------------------
# bounded work (issue 14, items 6 and 7)
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("res", [4096, (1, 16777216), (2048, 2049), (10**9, 10**9)])
def test_mesh_memory_is_refused_before_any_allocation(res) -> None:
    import tracemalloc

    tracemalloc.start()
    try:
        with pytest.raises(MeshError, match=r"^res: .* GiB of memory .* GiB limit"):
            mesh_surface("helicoid", res)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2**20  # nothing of the mesh's size (≥ 2 GiB) was allocated


def test_memory_estimate_and_limit() -> None:
    assert surfaces.estimate_mesh_bytes(4096, 4096) == surfaces.MESH_BYTES_PER_CELL * 4096**2
    assert surfaces.MAX_CELLS * surfaces.MESH_BYTES_PER_CELL <= surfaces.MAX_MESH_BYTES
    assert surfaces.MAX_MESH_BYTES == 2 * 1024**3
    # the largest square grid under the limit is accepted (checked, not built)
    side = int(np.sqrt(surfaces.MAX_CELLS))
    assert surfaces.check_mesh_res("helicoid", (side, side)) == (side, side)
    with pytest.raises(MeshError, match="at least 3 cells"):
        surfaces.check_mesh_res("torus", (2, 8))
    with pytest.raises(MeshError, match=r"^--res: "):
        surfaces.check_mesh_res("torus", 10**6, name="--res")


@pytest.mark.parametrize("res", ["4096", "1,16777216", "3000,3000"])
def test_cli_refuses_a_mesh_above_the_memory_limit(tmp_path, capsys, res: str) -> None:
    out = tmp_path / "h.obj"
    code, stdout, err = _cli(capsys, "helicoid", "--mesh", str(out), "--res", res)
    assert code == 2 and stdout == ""
    assert err.count("\n") == 1 and err.startswith("meshlap: error: --res: ")
    assert "GiB" in err and "limit" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "name, levels, exclude_poles, match",
    [
        ("helicoid", (8, 1), False, "level 1: the mesh has no interior vertex"),
        ("saddle", (16, 8, 1), False, "level 1"),
        ("torus", (8, 2), False, "closed in u"),
        ("helicoid", (8, 2000), False, "GiB"),
        ("helicoid", (8, 1000, 1000, 1100), False, "levels together"),
        ("sphere", (8, 0), False, "at least 1 cell"),
    ],
)
def test_every_convergence_level_is_checked_before_any_meshing(
    name: str, levels: tuple[int, ...], exclude_poles: bool, match: str
) -> None:
    lines: list[str] = []
    with pytest.raises(MeshError, match=match):
        convergence_study(name, levels, exclude_poles=exclude_poles, progress=lines.append)
    assert lines == []  # no level was meshed


@pytest.mark.parametrize("name", list(surfaces.SURFACES))
@pytest.mark.parametrize("exclude_poles", [False, True])
def test_small_levels_fail_only_before_meshing(name: str, exclude_poles: bool) -> None:
    """The up-front check (from a mesh of at most 3 x 3 cells) agrees with the study itself:
    a level either passes it and is studied, or fails before anything is meshed."""
    for n in range(1, 6):
        lines: list[str] = []
        try:
            st = convergence_study(name, (n,), exclude_poles=exclude_poles, progress=lines.append)
        except MeshError:
            assert lines == []
            assert n < 3  # three cells per direction always leave an interior vertex
        else:
            assert len(lines) == 1 and st.n_compared[0] >= 1


def test_cli_convergence_refuses_a_bad_level_with_one_line(capsys) -> None:
    code, out, err = _cli(capsys, "helicoid", "--convergence", "--res", "8,1")
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "--res" in err and "level 1" in err


def test_one_name_per_thing() -> None:
    # get_surface is the one name of the catalogue look-up (the public API's too); the exact
    # fields at (u, v) are surface_curvature_fields (no aliases left)
    assert get_surface("torus", R=2.0).params == {"R": 2.0, "r": 1.0}
    assert meshlap_core.get_surface is get_surface
    assert not hasattr(surfaces, "surface") and not hasattr(surfaces, "curvature_fields")
    # the parametric torus and the triangle mesh of primitives: the same points
    s = surfaces.torus(R=2.0, r=0.5)
    V, _ = primitives.torus_mesh(8, 6, R=2.0, r=0.5)
    np.testing.assert_allclose(mesh_surface(s, (8, 6)).V, V, atol=1e-14)


def test_eig_sym2_matches_lapack() -> None:
    # the principal curvatures' closed-form eigen-decomposition against numpy's eigh, including
    # near-umbilic, diagonal and tiny/huge matrices (eigenvectors compared up to sign)
    from meshlap_core.curvature.principal import eig_sym2

    rng = np.random.default_rng(7)
    a, b, c = rng.normal(size=(3, 4000)) * 10.0 ** rng.uniform(-6, 6, (1, 4000))
    b[:500] *= 1e-13  # nearly diagonal
    c[500:1000] = a[500:1000] * (1 + 1e-9)  # nearly umbilic with an off-diagonal part
    b[1000:1100] = 0.0
    a[1100:1200] = c[1100:1200] + 1e-7 * b[1100:1200]  # d ≈ 0: the two formulas meet
    k1, k2, cs, sn = eig_sym2(a, b, c)
    y1 = np.stack([cs, sn], -1)
    lam, Y = np.linalg.eigh(np.stack([np.stack([a, b], -1), np.stack([b, c], -1)], -2))
    scale = np.maximum(np.abs(a), np.maximum(np.abs(b), np.abs(c)))
    assert np.all(k1 >= k2)
    np.testing.assert_allclose(k1 / scale, lam[:, 1] / scale, rtol=0, atol=1e-14)
    np.testing.assert_allclose(k2 / scale, lam[:, 0] / scale, rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(y1, axis=1), 1.0, atol=1e-15)
    # A y1 = k1 y1 (residual relative to the matrix's size), and y1 = ±eigh's vector where the
    # gap is large enough for the vector to be well defined
    res = (
        np.stack([a * y1[:, 0] + b * y1[:, 1], b * y1[:, 0] + c * y1[:, 1]], -1) - k1[:, None] * y1
    )
    assert np.max(np.linalg.norm(res, axis=1) / scale) < 1e-14
    gap = (k1 - k2) / scale
    well = gap > 1e-6
    cos = np.abs(np.einsum("ij,ij->i", y1, Y[:, :, 1]))
    np.testing.assert_allclose(cos[well], 1.0, atol=1e-12)
    # the zero matrix: eigenvalues 0, the u direction
    z = np.zeros(1)
    k1, k2, cs, sn = eig_sym2(z, z, z)
    y1 = np.stack([cs, sn], -1)
    assert k1[0] == k2[0] == 0.0 and y1.tolist() == [[1.0, 0.0]]


@pytest.mark.parametrize("name", [*surfaces.SURFACES, "flat_helicoid"])
def test_mesh_boundary_is_the_edges_used_once(name: str) -> None:
    # the boundary mask of mesh_surface (read off the grid when there is no pole) against the
    # definition: the vertices of edges used by exactly one face
    from meshlap_core.topology import boundary_vertex_mask

    s = get_surface("helicoid", c=0.0) if name == "flat_helicoid" else get_surface(name)
    for res in [(1, 1), (1, 4), (3, 3), (4, 7), (7, 3), (12, 5)]:
        if (s.closed_u and res[0] < 3) or (s.closed_v and res[1] < 3):
            continue
        m = mesh_surface(s, res)
        np.testing.assert_array_equal(m.boundary, boundary_vertex_mask(m.F, len(m.V)))
