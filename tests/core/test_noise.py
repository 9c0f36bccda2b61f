"""Tests of meshlap_core.noise: reproducibility, the requested sigma, direction of the offsets."""

from __future__ import annotations

import numpy as np
import pytest

from meshlap_core import noise as N
from meshlap_core.curvature import vertex_normals
from meshlap_core.errors import MeshError
from meshlap_core.primitives import bumpy_sphere, cube, icosphere


def test_bbox_diagonal_of_unit_cube():
    V, _ = cube()
    assert N.bbox_diagonal(V) == pytest.approx(np.sqrt(3.0))
    assert N.noise_sigma(V, 0.1) == pytest.approx(0.1 * np.sqrt(3.0))


def test_same_seed_same_noise_other_seed_other_noise():
    V, F = bumpy_sphere(3)
    a = N.add_noise(V, F, 0.01, seed=7)
    b = N.add_noise(V, F, 0.01, seed=7)
    c = N.add_noise(V, F, 0.01, seed=8)
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)
    an = N.add_noise(V, F, 0.01, mode="normal", seed=7)
    assert np.array_equal(an, N.add_noise(V, F, 0.01, mode="normal", seed=7))


def test_isotropic_noise_has_the_requested_sigma():
    rng = np.random.default_rng(123)
    V = rng.uniform(-1, 2, size=(40000, 3))
    alpha = 0.02
    sigma = alpha * N.bbox_diagonal(V)
    D = N.add_noise(V, None, alpha, seed=0) - V
    # 120000 samples: the sample std is within ~0.4% of sigma (3 standard errors)
    assert D.std() == pytest.approx(sigma, rel=0.01)
    assert abs(D.mean()) < 0.02 * sigma
    for c in range(3):  # isotropic: every coordinate has the same spread
        assert D[:, c].std() == pytest.approx(sigma, rel=0.02)


def test_normal_noise_is_along_the_normal_with_the_requested_sigma():
    V, F = icosphere(5)  # 10242 vertices
    alpha = 0.01
    sigma = alpha * N.bbox_diagonal(V)
    D = N.add_noise(V, F, alpha, mode="normal", seed=3) - V
    Nv = vertex_normals(V, F)
    along = np.einsum("ij,ij->i", D, Nv)
    np.testing.assert_allclose(np.cross(D, Nv), 0.0, atol=1e-15)
    assert along.std() == pytest.approx(sigma, rel=0.04)
    # on a sphere the vertex normals are radial
    np.testing.assert_allclose(Nv, V, atol=5e-3)


def test_zero_alpha_is_a_copy_and_input_untouched():
    V, F = icosphere(1)
    V0 = V.copy()
    out = N.add_noise(V, F, 0.0)
    assert np.array_equal(out, V) and out is not V
    N.add_noise(V, F, 0.1, mode="normal")
    assert np.array_equal(V, V0)


@pytest.mark.parametrize("alpha", [-0.1, float("nan"), float("inf"), "x"])
def test_bad_alpha_raises_naming_it(alpha):
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="alpha"):
        N.add_noise(V, F, alpha)


def test_bad_mode_seed_and_missing_faces():
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="mode"):
        N.add_noise(V, F, 0.1, mode="tangent")  # type: ignore[arg-type]
    with pytest.raises(MeshError, match="seed"):
        N.add_noise(V, F, 0.1, seed=-1)
    with pytest.raises(MeshError, match="faces"):
        N.add_noise(V, None, 0.1, mode="normal")
