"""The Curvature lab: its state headless (the error map is the error against the exact surface,
disagreement is the max pairwise difference), and its widgets through the scripted UI on
polyscope's ``openGL_mock`` (crosses uploaded as 2-symmetric tangent line fields)."""

from __future__ import annotations

import numpy as np
import pytest
from meshlap_app.state.curvature_lab import (
    CurvatureLabState,
    cross_field,
    crosses_of,
)

from meshlap_core import primitives
from meshlap_core.curvature import estimators as ce
from meshlap_core.errors import MeshError
from meshlap_core.noise import add_noise


def _compute(lab: CurvatureLabState, V=None, F=None):
    return CurvatureLabState.compute(lab.params(), V, F)


def test_error_map_is_estimate_minus_exact_and_shrinks_with_resolution():
    lab = CurvatureLabState()  # torus, cotan, H, error
    rms = []
    for res in (16, 32):
        lab.set_number("res", res)
        r = _compute(lab)
        assert r.V.shape == (2 * res * res, 3)
        # exact H on the torus R = 3, r = 1
        v = np.arctan2(r.V[:, 2], np.hypot(r.V[:, 0], r.V[:, 1]) - 3.0)
        H = 0.5 * (1 + np.cos(v) / (3 + np.cos(v)))
        np.testing.assert_allclose(r.values, r.principal.H - H, atol=1e-9)
        rms.append(np.sqrt(np.mean(r.values**2)))
        assert "RMS error" in r.summary
    assert rms[1] < rms[0] / 3  # order 2: 4x per halving


def test_noise_and_jitter_change_the_mesh_and_bad_values_are_refused():
    lab = CurvatureLabState()
    lab.set_number("res", 16)
    clean = _compute(lab)
    lab.set_number("noise", 0.002)
    lab.set_number("jitter", 0.3)
    noisy = _compute(lab)
    assert np.abs(noisy.V - clean.V).max() > 0
    assert np.sqrt(np.mean(noisy.values**2)) > 3 * np.sqrt(np.mean(clean.values**2))
    for what, bad in (
        ("noise", -0.1),
        ("noise", "nan"),
        ("jitter", 0.9),
        ("res", 1e6),
        ("res", "x"),
    ):
        with pytest.raises(MeshError, match=what):
            lab.set_number(what, bad)
    assert (lab.noise, lab.jitter, lab.res) == (0.002, 0.3, 16)  # unchanged
    with pytest.raises(MeshError):
        lab.set_choice("estimator", "magic")


def test_noise_and_flips_reuse_the_cached_exact_surface():
    lab = CurvatureLabState()
    lab.set_number("res", 16)
    first = _compute(lab)
    lab.adopt(lab.inputs(0), first)
    assert lab.base() is first.base
    lab.set_number("noise", 0.003)
    lab.set_number("flips", 0.2)
    cached = CurvatureLabState.compute(lab.params(), None, None, lab.base())
    assert cached.base is None  # the cached exact values were used, not recomputed
    fresh = _compute(lab)  # the same result without the cache
    np.testing.assert_array_equal(cached.values, fresh.values)
    np.testing.assert_array_equal(cached.F, fresh.F)
    assert not np.array_equal(cached.F, first.F)  # the flips are there
    # the cached normals give the noise of add_noise (without flips, where they are used)
    lab.set_number("flips", 0.0)
    cached = CurvatureLabState.compute(lab.params(), None, None, lab.base())
    m = first.base.mesh
    noisy = add_noise(m.V, m.F, 0.003, mode="normal", seed=0)
    np.testing.assert_array_equal(cached.V, noisy)
    np.testing.assert_array_equal(cached.values, _compute(lab).values)
    # a cache for other settings is never used by mistake
    lab.set_number("jitter", 0.2)
    assert lab.base() is None
    moved = CurvatureLabState.compute(lab.params(), None, None, first.base)
    assert moved.base is not first.base and moved.base.key == (lab.surface, 16, 0.2)


def test_disagreement_on_a_loaded_mesh():
    V, F = primitives.bumpy_sphere(2)
    lab = CurvatureLabState()
    lab.set_choice("source", "mesh")
    lab.set_choice("show", "disagreement")
    r = _compute(lab, V, F)
    H = np.stack([ce.estimate_curvature(V, F, e).H for e in ce.ESTIMATOR_FUNCTIONS])
    np.testing.assert_allclose(r.values, H.max(0) - H.min(0), atol=1e-12)
    assert "disagree" in r.summary


def test_shape_operator_at_a_vertex_has_the_principal_values_and_euler_matches_exact():
    lab = CurvatureLabState()  # the torus, cotan
    lab.set_number("res", 32)
    lab.adopt(lab.inputs(0), _compute(lab))
    with pytest.raises(MeshError, match="vertex"):
        lab.pick(10**6)
    lab.pick(0)  # u = v = 0: the outer equator, k1 = 1 (around the tube), k2 = 1/4
    so = lab.shape_operator()
    S = np.array(so["S"])
    np.testing.assert_allclose(S, S.T)
    np.testing.assert_allclose(np.linalg.eigvalsh(S)[::-1], [so["k1"], so["k2"]], atol=1e-12)
    assert (so["k1"], so["k2"]) == pytest.approx((1.0, 0.25), abs=2e-3)
    # Euler's formula: the extremes of kn are k1 (θ = 0) and k2 (θ = 90°), close to exact
    assert so["kn"][0] == pytest.approx(so["k1"]) and so["kn"].min() == pytest.approx(so["k2"])
    np.testing.assert_allclose(so["kn"], so["exact_kn"], atol=3e-3)


def test_cross_field_is_the_direction_in_the_tangent_basis():
    V, F = primitives.torus_mesh(24, 12)
    p = ce.estimate_curvature(V, F, "rusinkiewicz")
    vals, bx, by = cross_field(p, 1)
    d = vals[:, :1] * bx + vals[:, 1:] * by
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    np.testing.assert_allclose(np.abs(np.sum(d * p.d1, axis=1)), 1, atol=1e-9)
    np.testing.assert_allclose(np.sum(bx * p.normal, axis=1), 0, atol=1e-12)


def test_a_quantity_move_recolours_the_cached_estimate():
    """The estimate is kept per (surface, res, jitter, noise, flips, estimator): a quantity or
    show move gives the same values as a fresh computation without running the estimator."""
    lab = CurvatureLabState()
    lab.set_number("res", 12)
    lab.set_number("noise", 0.002)
    assert lab.estimate() is None and lab.light()  # cotan: a thread of the window
    lab.adopt(lab.inputs(0), _compute(lab))
    est = lab.estimate()
    assert est is not None and est.principal is lab.result.principal
    lab.set_choice("quantity", "K")
    cached = CurvatureLabState.compute(lab.params(), None, None, lab.base(), None, est)
    assert cached.principal is est.principal and cached.crosses is est.crosses
    np.testing.assert_array_equal(cached.values, _compute(lab).values)
    # an estimate for other settings is never used by mistake
    lab.set_number("noise", 0.001)
    assert lab.estimate() is None
    other = CurvatureLabState.compute(lab.params(), None, None, lab.base(), None, est)
    assert other.principal is not est.principal
    np.testing.assert_array_equal(other.values, _compute(lab).values)
    # the slow estimators and the disagreement of all of them stay in a child process
    lab.set_choice("estimator", "jet")
    assert not lab.light()
    lab.set_choice("estimator", "cotan")
    lab.set_choice("show", "disagreement")
    assert not lab.light()


def test_crosses_share_one_basis_and_equal_cross_field():
    V, F = primitives.torus_mesh(24, 12)
    p = ce.estimate_curvature(V, F, "cotan")
    c = crosses_of(p, p.d2)
    for which, vals in ((1, c.k1), (2, c.k2)):
        ref, bx, by = cross_field(p, which)
        np.testing.assert_allclose(vals, ref, atol=1e-12)
        np.testing.assert_allclose(c.basis_x, bx)
        np.testing.assert_allclose(c.basis_y, by)
    # the exact direction (d2 here) is scaled as k1's cross and orthogonal to it
    np.testing.assert_allclose(np.linalg.norm(c.exact, axis=1), np.linalg.norm(c.k1, axis=1))
    np.testing.assert_allclose(np.sum(c.exact * c.k1, axis=1), 0, atol=1e-12)


# ---------------------------------------------------------------- widgets (openGL_mock)
ps = pytest.importorskip("polyscope")

from tests.support.drivers.curvature import drive_curvature_estimator  # noqa: E402
from tests.support.drivers.curvature_lab import drive_panel_curvature_lab  # noqa: E402
from tests.support.widgets import drive, frames  # noqa: E402


def test_curvature_lab_widgets(viewer):
    drive_panel_curvature_lab(viewer)


def test_a_new_estimate_on_the_same_faces_moves_the_registered_vertices(viewer, monkeypatch):
    """A noise or estimator move keeps the registered mesh (its vertices moved, its crosses
    replaced or removed); new faces (a resolution move) register it again."""
    from meshlap_app.panels.curvature_lab import LAB

    viewer.set_panel("curvature_lab")
    frames(viewer, 2)
    drive(viewer, "resolution", 12)
    lab = viewer.panels["curvature_lab"].state
    registered = []
    real = ps.register_surface_mesh
    monkeypatch.setattr(
        ps,
        "register_surface_mesh",
        lambda name, *a, **k: registered.append(name) or real(name, *a, **k),
    )
    before = lab.result
    drive(viewer, "noise", 0.002)
    drive(viewer, "estimator", "normal_cycle")
    assert lab.result.F is before.F and not np.array_equal(lab.result.V, before.V)
    assert registered == []
    sm = ps.get_surface_mesh(LAB)
    assert sm.n_vertices() == len(lab.result.V)
    sm.remove_quantity("k1 direction (max)", error_if_absent=True)  # the crosses are there
    drive(viewer, "crosses", False)
    with pytest.raises(Exception, match="k2 direction"):  # and gone with the checkbox
        ps.get_surface_mesh(LAB).remove_quantity("k2 direction (min)", error_if_absent=True)
    drive(viewer, "crosses", True)
    drive(viewer, "resolution", 13)
    assert registered == [LAB] and ps.get_surface_mesh(LAB).n_vertices() == 2 * 13 * 13


def test_curvature_estimator_widgets(viewer):
    drive_curvature_estimator(viewer)


def test_the_flipped_triangulation_and_its_topology_are_kept_per_base():
    """A noise move on a flipped mesh reuses the flips (the same faces, normals and topology as
    flipped_and_noisy makes), and a base sent to a child process leaves them behind."""
    import pickle

    from meshlap_core.curvature.study import flipped_and_noisy

    lab = CurvatureLabState()
    lab.set_number("res", 12)
    first = _compute(lab)
    base = first.base
    m, normals, topo = base.triangulation(0.3)
    assert base.triangulation(0.3)[2] is topo  # kept
    ref, Vn = flipped_and_noisy(base.mesh, 0.002, flips=0.3)
    np.testing.assert_array_equal(m.F, ref.F)
    np.testing.assert_array_equal(topo.F, ref.F)
    _, V = flipped_and_noisy(m, 0.002, normals=normals)
    np.testing.assert_array_equal(V, Vn)
    assert base.triangulation(0.0)[0] is base.mesh
    assert len(pickle.loads(pickle.dumps(base)).kept) == 0
    assert len(base.kept) == 2


def test_the_resolution_line_names_the_mesh_meshlap_surface_makes(viewer, tmp_path):
    """The lab's torus "res 32" had 2,048 vertices where ``meshlap surface --res 32`` has
    1,024: the line under the slider says what N means and which command makes that mesh;
    the command run as written gives the lab's mesh (the same vertex count and positions)."""
    import re

    from meshlap_core.cli import main
    from meshlap_core.io import load_mesh
    from tests.support.widgets import drive, frames

    viewer.set_panel("curvature_lab")
    lab = viewer.panels["curvature_lab"].state
    drive(viewer, "lab surface", "torus")
    drive(viewer, "resolution", 32)
    for _ in range(200):
        frames(viewer)
        if lab.result is not None and len(lab.result.V) == 2048:
            break
    lines = [t for sec, t, _ in viewer.ui.texts if sec == "curvature_lab" and "cells" in t]
    assert lines[-1] == "torus: 64 x 32 cells, 2,048 vertices (meshlap surface torus --res 64,32)"
    command = re.search(r"\((meshlap surface .*)\)", lines[-1]).group(1).split()[1:]
    out = tmp_path / "torus.obj"
    assert main([*command, "--mesh", str(out)]) == 0
    mesh = load_mesh(out)
    assert len(mesh.V) == len(lab.result.V) == 2048
    assert np.allclose(np.sort(mesh.V, axis=0), np.sort(lab.result.V, axis=0), atol=1e-5)
