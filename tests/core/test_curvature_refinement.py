"""The one convergence machinery (meshlap_core.curvature.refinement): orders by hand, exact
values at the poles, and the two studies built on it measuring the same h and the same orders."""

import math

import numpy as np
import pytest

from meshlap_core.curvature.convergence import convergence_study
from meshlap_core.curvature.refinement import (
    exact_curvature_at,
    exact_principal,
    fitted_order,
    observed_orders,
    sphere_level,
    surface_level,
)
from meshlap_core.curvature.study import curvature_study
from meshlap_core.laplacian import mean_edge_length
from meshlap_core.surfaces import get_surface, mesh_surface


def test_observed_orders_by_hand():
    """e = h²: halving h divides e by 4, order 2; e = h: order 1; one fewer than the levels."""
    assert observed_orders([1.0, 0.5, 0.25], [1.0, 0.25, 0.0625]) == [2.0, 2.0]
    assert observed_orders([0.3, 0.1], [0.3, 0.1]) == [pytest.approx(1.0)]
    assert observed_orders([1.0], [1.0]) == []


@pytest.mark.parametrize(
    ("h", "err", "floor"),
    [
        ([1.0, 1.0], [1.0, 0.5], 0.0),  # equal h
        ([1.0, 0.5], [1.0, 0.0], 0.0),  # an exact estimate
        ([1.0, 0.5], [1e-14, 1e-15], 1e-12),  # rounding level
        ([1.0, 0.5], [math.nan, 0.1], 0.0),
        ([1.0, 0.5], [math.inf, 0.1], 0.0),
    ],
)
def test_observed_order_is_none_where_undefined(h, err, floor):
    assert observed_orders(h, err, floor) == [None]


def test_fitted_order_is_the_least_squares_slope():
    """Exactly 3 h² over four levels: slope 2; a noisy middle point moves it the least-squares
    way (not through the end points); NaN without two distinct usable levels."""
    h = np.array([0.4, 0.2, 0.1, 0.05])
    assert fitted_order(h, 3 * h**2) == pytest.approx(2.0)
    e = 3 * h**2 * np.array([1.0, 1.2, 1.0, 1.0])
    slope = np.polyfit(np.log(h), np.log(e), 1)[0]
    assert fitted_order(h, e) == pytest.approx(slope) and fitted_order(h, e) != pytest.approx(2.0)
    assert math.isnan(fitted_order([0.1, 0.1], [1.0, 2.0]))
    assert math.isnan(fitted_order([0.2, 0.1], [1.0, 0.0]))


def test_pole_limits_are_the_limits_and_agree_with_exact_curvature_at():
    """On the (u, v) sphere of radius 2 every vertex, the poles included, has H = 1/2 and
    K = 1/4 when the poles are evaluated just inside (their exact values are NaN otherwise)."""
    s = get_surface("sphere", r=2.0)
    m = mesh_surface(s, 8)
    assert m.pole.any()
    ex = exact_principal(m, s, pole_limits=True, directions=False)
    np.testing.assert_allclose(ex.H, 0.5, rtol=1e-6)
    np.testing.assert_allclose(ex.K, 0.25, rtol=1e-6)
    assert ex.d1 is None and ex.d2 is None
    H, K = exact_curvature_at(s, m.uv, m.pole)
    np.testing.assert_array_equal(H, ex.H)
    np.testing.assert_array_equal(K, ex.K)
    plain = exact_principal(m, s)
    assert np.isnan(plain.H[m.pole]).all() and not plain.compared[m.pole].any()


def test_a_level_measures_h_on_the_clean_mesh_and_keeps_the_noisy_positions():
    s = get_surface("torus")
    m = mesh_surface(s, (16, 8))
    noisy = m.V + 0.01
    lev = surface_level(s, 8, m, noisy)
    assert lev.res == 8 and lev.V is noisy and lev.F is m.F
    assert lev.h == mean_edge_length(m.V, m.F)
    ico = sphere_level(2.0, 2)
    np.testing.assert_allclose(ico.exact.k1, 0.5)
    np.testing.assert_allclose(ico.exact.K, 0.25)
    assert ico.exact.compared.all() and ico.uv is None


@pytest.mark.parametrize("surface", ["saddle", "sphere"])
def test_both_studies_measure_the_same_h(surface):
    """The surfaces' convergence table and the estimators' study share the machinery: on the
    same grids (the saddle has a boundary, the sphere poles) the same h, each edge once (the
    study used to average over half-edges, counting the saddle's boundary edges half)."""
    levels = (8, 16, 32)
    table = convergence_study(surface, levels)
    rows = curvature_study([surface], ["cotan"], levels)
    assert [r["h"] for r in rows] == table.h
    m = mesh_surface(surface, 8)
    assert table.h[0] == mean_edge_length(m.V, m.F)
