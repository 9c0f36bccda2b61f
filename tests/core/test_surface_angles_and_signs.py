"""Parametric surfaces: a direction's angle in the tangent plane against its angle in the (u, v)
plane, and the two signs of the second fundamental form (meshlap's outward one, do Carmo's).

Tier 1: the helicoid at its origin and at (u, v) = (0.8, 0.3) and the sphere, worked out by hand
from p(u, v) = (u cos v, u sin v, v): p_u = (cos v, sin v, 0), p_v = (−u sin v, u cos v, 1),
p_uv = (−sin v, cos v, 0), n = (sin v, −cos v, u)/√(1+u²), so E = 1, F = 0, G = 1 + u²,
e = g = 0 and p_uv · n = −1/√(1+u²): do Carmo's f = p_uv · n = −1/√(1+u²), meshlap's f = +1/√(1+u²).
Tier 2: invariants under the signs (K, n, the classification unchanged; κ₁ ≥ κ₂; principal
directions 90° apart in the tangent plane; κₙ at theta_max is κ₁). Tier 3: the tangent angle
against an independent computation from the 3-D vectors.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from meshlap_core.errors import MeshError
from meshlap_core.surfaces import (
    get_surface,
    normal_curvature,
    normal_curvature_curve,
    normal_curvature_figure,
    parameter_angle,
    plot_normal_curvature,
    point_geometry,
    surface_curvature_fields,
    tangent_angle,
)

SIGNS = ("outward", "do-carmo")
W = 1 + 0.8**2  # 1 + u² at the helicoid's (0.8, 0.3): G
THETA_UV = math.degrees(math.atan(1 / math.sqrt(W)))  # 37.985°: tan θ_uv = tan 45° / √G


# ------------------------------------------------------------------------------------------
# tier 1: by hand
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("signs, sign", [("outward", 1.0), ("do-carmo", -1.0)])
def test_helicoid_origin_in_both_signs(signs: str, sign: float) -> None:
    """E = G = 1, F = 0, e = g = 0, f = ±1: κₙ(θ) = ±sin 2θ, largest at π/4 (meshlap) or
    3π/4 (do Carmo, the coursework)."""
    g = point_geometry("helicoid", 0.0, 0.0, signs=signs)
    assert g.signs == signs
    assert (g.E, g.F, g.G) == pytest.approx((1, 0, 1), abs=1e-15)
    assert (g.e, g.f, g.g) == pytest.approx((0, sign, 0), abs=1e-15)
    assert (g.K, g.H, g.k1, g.k2) == pytest.approx((-1, 0, 1, -1), abs=1e-15)
    theta_max = math.pi / 4 if sign > 0 else 3 * math.pi / 4
    assert g.theta_max == pytest.approx(theta_max, abs=1e-15)
    assert g.theta_min == pytest.approx(math.pi - theta_max, abs=1e-15)
    assert (g.theta_uv_max, g.theta_uv_min) == pytest.approx((g.theta_max, g.theta_min))
    for angle in ("uv", "tangent"):
        theta, kn = normal_curvature_curve("helicoid", 0.0, 0.0, 73, angle=angle, signs=signs)
        np.testing.assert_allclose(kn, sign * np.sin(2 * theta), atol=1e-15)


@pytest.mark.parametrize("signs, sign", [("outward", 1.0), ("do-carmo", -1.0)])
def test_helicoid_at_0_8_0_3_by_hand(signs: str, sign: float) -> None:
    """G = 1.64: the principal directions are 45° and 135° from p_u in the tangent plane
    (κₙ = ±sin 2θ / 1.64 there) but 37.99° and 142.01° in the (u, v) plane (104° apart)."""
    g = point_geometry("helicoid", 0.8, 0.3, signs=signs)
    assert (g.E, g.F, g.G) == pytest.approx((1, 0, W), abs=1e-15)
    assert (g.e, g.f, g.g) == pytest.approx((0, sign / math.sqrt(W), 0), abs=1e-15)
    assert g.K == pytest.approx(-1 / W**2, abs=1e-15)
    assert g.H == pytest.approx(0, abs=1e-15)
    assert (g.k1, g.k2) == pytest.approx((1 / W, -1 / W), abs=1e-15)
    big, small = (45.0, 135.0) if sign > 0 else (135.0, 45.0)
    big_uv, small_uv = (THETA_UV, 180 - THETA_UV) if sign > 0 else (180 - THETA_UV, THETA_UV)
    deg = np.degrees([g.theta_max, g.theta_min, g.theta_uv_max, g.theta_uv_min])
    np.testing.assert_allclose(deg, [big, small, big_uv, small_uv], atol=1e-12)
    assert 180 - 2 * THETA_UV == pytest.approx(104.03, abs=0.01)  # what the issue measured
    # κₙ in each angle, written out from the forms: tangent θ: (f/√G) sin 2θ; (u, v) θ:
    # 2f cs / (c² + G s²)
    th = np.linspace(0, 2 * np.pi, 91)
    f = sign / math.sqrt(W)
    tangent = normal_curvature("helicoid", 0.8, 0.3, th, angle="tangent", signs=signs)
    np.testing.assert_allclose(tangent, f / math.sqrt(W) * np.sin(2 * th), atol=1e-15)
    c, s = np.cos(th), np.sin(th)
    uv = normal_curvature("helicoid", 0.8, 0.3, th, signs=signs)
    np.testing.assert_allclose(uv, 2 * f * c * s / (c * c + W * s * s), atol=1e-15)
    # the angle map with E = 1, F = 0: tan θ = √G tan θ_uv
    got = tangent_angle(g, th)
    assert np.all((got >= 0) & (got < 2 * np.pi))
    diff = np.angle(np.exp(1j * (got - np.arctan2(math.sqrt(W) * s, c))))
    np.testing.assert_allclose(diff, 0, atol=1e-14)


@pytest.mark.parametrize("r", [0.5, 2.0])
def test_sphere_H_sign_both_ways(r: float) -> None:
    """Outward n = p/r: meshlap's κ = H = +1/r (as on meshes), do Carmo's −1/r; K = 1/r²."""
    s = get_surface("sphere", r=r)
    out = point_geometry(s, 1.0, 2.0)
    dc = point_geometry(s, 1.0, 2.0, signs="do-carmo")
    np.testing.assert_allclose(out.n, out.p / r, atol=1e-15)
    np.testing.assert_allclose(dc.n, out.n, atol=0)
    assert (out.H, out.k1, out.k2) == pytest.approx((1 / r, 1 / r, 1 / r), rel=1e-13)
    assert (dc.H, dc.k1, dc.k2) == pytest.approx((-1 / r, -1 / r, -1 / r), rel=1e-13)
    assert out.K == pytest.approx(1 / r**2, rel=1e-13) and dc.K == pytest.approx(out.K, rel=0)
    assert out.classification == dc.classification == "umbilic"
    # umbilic: θ_max is p_u (0) by the stated rule, θ_min its perpendicular in the tangent plane
    assert (dc.theta_max, dc.theta_min) == pytest.approx((0.0, math.pi / 2), abs=1e-15)


def test_unknown_signs_is_a_clear_error() -> None:
    with pytest.raises(MeshError, match="unknown signs 'docarmo'; choose one of outward, do-c"):
        point_geometry("helicoid", 0.0, 0.0, signs="docarmo")
    with pytest.raises(MeshError, match="unknown angle"):
        normal_curvature("helicoid", 0.0, 0.0, 0.1, angle="degrees")


# ------------------------------------------------------------------------------------------
# tier 2: invariants
# ------------------------------------------------------------------------------------------

POINTS = [
    ("helicoid", 0.8, 0.3),
    ("helicoid", 0.6, 2.0),
    ("torus", 0.3, 2.5),
    ("torus", 1.0, 0.4),
    ("ellipsoid", 1.1, 0.7),
    ("catenoid", 1.0, 0.5),
    ("saddle", 0.3, -0.4),
    ("monkey_saddle", 0.4, 0.7),
    ("cylinder", 2.0, 1.0),
]


@pytest.mark.parametrize("name, u, v", POINTS)
def test_what_do_carmo_flips_and_what_it_keeps(name: str, u: float, v: float) -> None:
    out = point_geometry(name, u, v)
    dc = point_geometry(name, u, v, signs="do-carmo")
    scale = max(1.0, abs(out.k1), abs(out.k2))
    # kept: n, I, K, the classification
    np.testing.assert_array_equal(dc.n, out.n)
    assert (dc.E, dc.F, dc.G) == (out.E, out.F, out.G)
    assert dc.K == pytest.approx(out.K, abs=1e-12 * scale**2)
    assert dc.classification == out.classification
    # flipped: II, H, κₙ; κ₁, κ₂ become −κ₂, −κ₁ (ordered), so the directions swap roles
    assert (dc.e, dc.f, dc.g) == (-out.e, -out.f, -out.g)
    assert dc.H == pytest.approx(-out.H, abs=1e-12 * scale)
    assert (dc.k1, dc.k2) == pytest.approx((-out.k2, -out.k1), abs=1e-12 * scale)
    assert dc.k1 >= dc.k2 and out.k1 >= out.k2
    assert abs(dc.dir1 @ out.dir2) == pytest.approx(1, abs=1e-9)
    assert abs(dc.dir2 @ out.dir1) == pytest.approx(1, abs=1e-9)
    assert (dc.theta_max, dc.theta_min) == pytest.approx((out.theta_min, out.theta_max))
    assert (dc.theta_uv_max, dc.theta_uv_min) == pytest.approx((out.theta_uv_min, out.theta_uv_max))
    th = np.linspace(0, 2 * np.pi, 37)
    for angle in ("uv", "tangent"):
        np.testing.assert_array_equal(
            normal_curvature(name, u, v, th, angle=angle, signs="do-carmo"),
            -normal_curvature(name, u, v, th, angle=angle),
        )


@pytest.mark.parametrize("signs", SIGNS)
@pytest.mark.parametrize("name, u, v", POINTS)
def test_principal_angles_in_the_tangent_plane(name: str, u: float, v: float, signs: str) -> None:
    g = point_geometry(name, u, v, signs=signs)
    scale = max(1.0, abs(g.k1), abs(g.k2))
    for t in (g.theta_max, g.theta_min, g.theta_uv_max, g.theta_uv_min):
        assert 0 <= t < np.pi
    # 90° apart in the tangent plane (not in general in the (u, v) plane)
    assert abs(g.theta_max - g.theta_min) == pytest.approx(np.pi / 2, abs=1e-12)
    # κₙ at the tangent angles and at the parameter angles are κ₁, κ₂
    kn = normal_curvature(name, u, v, [g.theta_max, g.theta_min], angle="tangent", signs=signs)
    np.testing.assert_allclose(kn, [g.k1, g.k2], atol=1e-12 * scale)
    kn = normal_curvature(name, u, v, [g.theta_uv_max, g.theta_uv_min], signs=signs)
    np.testing.assert_allclose(kn, [g.k1, g.k2], atol=1e-12 * scale)
    # Euler's theorem in the tangent angle: κₙ(θ) = κ₁ cos²(θ − θ₁) + κ₂ sin²(θ − θ₁)
    th = np.linspace(0, 2 * np.pi, 121)
    euler = g.k1 * np.cos(th - g.theta_max) ** 2 + g.k2 * np.sin(th - g.theta_max) ** 2
    kn = normal_curvature(name, u, v, th, angle="tangent", signs=signs)
    np.testing.assert_allclose(kn, euler, atol=1e-12 * scale)
    # the tangent angle of each parameter angle, and back
    assert tangent_angle(g, g.theta_uv_max) == pytest.approx(g.theta_max, abs=1e-12)
    assert tangent_angle(g, g.theta_uv_min) == pytest.approx(g.theta_min, abs=1e-12)
    np.testing.assert_allclose(tangent_angle(g, parameter_angle(g, th[:-1])), th[:-1], atol=1e-12)


# ------------------------------------------------------------------------------------------
# tier 3: the tangent angle against the 3-D vectors
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name, u, v", POINTS)
def test_tangent_angle_against_the_3d_frame(name: str, u: float, v: float) -> None:
    """The closed form from I (a Cholesky factor) equals atan2(d·t₂, d·t₁) with t₁ = p_u/|p_u|,
    t₂ = n × t₁ and d = p_u cos θ_uv + p_v sin θ_uv computed in 3-D."""
    g = point_geometry(name, u, v)
    t1 = g.p_u / np.linalg.norm(g.p_u)
    t2 = np.cross(g.n, t1)
    assert t2 @ g.p_v > 0  # the angle turns towards p_v
    th = np.linspace(0, 2 * np.pi, 73)[:-1]
    d = np.cos(th)[:, None] * g.p_u + np.sin(th)[:, None] * g.p_v
    ref = np.arctan2(d @ t2, d @ t1) % (2 * np.pi)
    got = tangent_angle(g, th)
    np.testing.assert_allclose(np.angle(np.exp(1j * (got - ref))), 0, atol=1e-12)
    # the 3-D principal directions are at theta_max, theta_min (up to sign)
    for t, d3 in ((g.theta_max, g.dir1), (g.theta_min, g.dir2)):
        assert abs((math.cos(t) * t1 + math.sin(t) * t2) @ d3) == pytest.approx(1, abs=1e-12)
    # vectorized fields carry the same forms: the angle map works on them unchanged
    cf = surface_curvature_fields(name, np.array([u, u]), np.array([v, v]), signs="do-carmo")
    np.testing.assert_allclose(
        tangent_angle(cf, np.array([0.3, 1.2])), tangent_angle(g, [0.3, 1.2])
    )


# ------------------------------------------------------------------------------------------
# the figure: its axis names the angle, its title the signs
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("signs, sign", [("outward", 1.0), ("do-carmo", -1.0)])
def test_plot_axis_is_the_tangent_angle(tmp_path, signs: str, sign: float) -> None:
    fig, g = normal_curvature_figure("helicoid", 0.8, 0.3, n=181, signs=signs)
    ax = fig.axes[0]
    assert "tangent plane" in ax.get_xlabel() and "from p_u" in ax.get_xlabel()
    assert f"signs: {signs}" in ax.get_title()
    # the drawn curve is κₙ against the tangent angle: ±sin 2θ / 1.64, largest at θ_max
    x, y = ax.lines[0].get_xdata(), ax.lines[0].get_ydata()
    np.testing.assert_allclose(y, sign * np.sin(2 * x) / W, atol=1e-15)
    marked = [
        ln.get_xdata()[0] for ln in ax.lines if ln.get_linestyle() == ":" and len(ln.get_xdata())
    ]
    assert marked[:2] == pytest.approx([g.theta_max, g.theta_max + np.pi])
    assert np.degrees(g.theta_max) == pytest.approx(45.0 if sign > 0 else 135.0)
    # the saved PNG names its axis and its signs in its text chunks
    from PIL import Image

    out = tmp_path / "kn.png"
    plot_normal_curvature("helicoid", 0.8, 0.3, out, n=181, signs=signs)
    with Image.open(out) as im:
        text = dict(im.text)
    assert f"x: {ax.get_xlabel()}" in text["Description"]
    assert f"signs: {signs}" in text["Description"]


# ------------------------------------------------------------------------------------------
# the command line
# ------------------------------------------------------------------------------------------


def _cli(capsys, *argv: str) -> tuple[int, str, str]:
    from meshlap_core.cli import main

    try:
        code = main(["surface", *argv])
    except SystemExit as exc:  # argparse's own errors (one line, exit 2)
        code = int(exc.code)
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_cli_json_angles_and_signs(capsys) -> None:
    code, out, _ = _cli(capsys, "helicoid", "--u", "0.8", "--v", "0.3", "--json")
    assert code == 0
    d = json.loads(out)
    assert d["signs"] == "outward"
    assert np.degrees([d["theta_max"], d["theta_min"]]) == pytest.approx([45, 135])
    assert np.degrees([d["theta_uv_max"], d["theta_uv_min"]]) == pytest.approx(
        [THETA_UV, 180 - THETA_UV]
    )
    assert "tangent plane from the unit p_u" in d["angles"]["theta_max, theta_min"]
    assert "(u, v) plane" in d["angles"]["theta_uv_max, theta_uv_min"]
    code, out, _ = _cli(
        capsys, "helicoid", "--u", "0.8", "--v", "0.3", "--signs", "do-carmo", "--json"
    )
    assert code == 0
    dc = json.loads(out)
    assert dc["signs"] == "do-carmo"
    assert dc["f"] == pytest.approx(-1 / math.sqrt(W))
    assert dc["K"] == pytest.approx(d["K"])
    assert np.degrees([dc["theta_max"], dc["theta_min"]]) == pytest.approx([135, 45])


def test_cli_text_names_the_signs_and_the_angles(capsys, tmp_path) -> None:
    code, out, _ = _cli(capsys, "helicoid", "--signs", "do-carmo")
    assert code == 0
    assert "signs: do-carmo" in out and "e = p_uu . n" in out
    assert "f = -1 " in out  # the coursework's f at the origin
    assert "max at θ = 135°" in out
    assert "θ: angle in the tangent plane from the unit p_u direction" in out
    code, out, _ = _cli(capsys, "helicoid")
    assert "signs: outward" in out and "max at θ = 45°" in out
    png = tmp_path / "kn.png"
    code, out, _ = _cli(capsys, "helicoid", "--signs", "do-carmo", "--plot", str(png))
    assert code == 0
    from PIL import Image

    with Image.open(png) as im:
        assert "signs: do-carmo" in im.text["Description"]


def test_cli_bad_signs_exits_2_with_one_line(capsys) -> None:
    for bad in ("docarmo", "", "DO-CARMO"):
        code, out, err = _cli(capsys, "helicoid", "--signs", bad)
        assert code == 2 and out == ""
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("meshlap: error: ")
        assert "--signs" in lines[0] and "outward" in lines[0] and "do-carmo" in lines[0]
    # the convergence study compares meshes in the one convention: do-carmo is refused there
    code, out, err = _cli(capsys, "sphere", "--convergence", "--signs", "do-carmo")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("meshlap: error: --signs: cannot be combined with --convergence")


# ------------------------------------------------------------------------------------------
# the window computes with the same core functions
# ------------------------------------------------------------------------------------------


def test_window_and_cli_agree_and_one_setting_switches_the_signs(capsys) -> None:
    """The Surfaces panel's state reads the core's point (the CLI's numbers); its Euler curve
    and section angle come from the core's angle map, so a point computed with
    ``signs="do-carmo"`` is all the panel needs to show the course's sign."""
    from meshlap_app.state.surfaces import SurfaceState, euler_curve, geometric_angle

    s = SurfaceState()
    s.set_surface("helicoid", 8)
    assert s.set_uv(0.8, 0.3)
    _, out, _ = _cli(capsys, "helicoid", "--u", "0.8", "--v", "0.3", "--json")
    d = json.loads(out)
    for key in ("theta_max", "theta_min", "theta_uv_max", "theta_uv_min", "k1", "k2"):
        assert getattr(s.point, key) == d[key]
    for signs in SIGNS:
        p = point_geometry("helicoid", 0.8, 0.3, signs=signs)
        phi, kn = euler_curve(p, 73)
        np.testing.assert_allclose(
            kn, p.k1 * np.cos(phi) ** 2 + p.k2 * np.sin(phi) ** 2, atol=1e-15
        )
        # φ of the k1 parameter direction is 0, of the k2 one ±90° (a line: modulo 180°)
        assert geometric_angle(p, p.theta_uv_max) == pytest.approx(0.0, abs=1e-12)
        assert geometric_angle(p, p.theta_uv_min) % np.pi == pytest.approx(np.pi / 2, abs=1e-12)
