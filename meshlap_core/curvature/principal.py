"""The result of every principal-curvature estimator (:class:`PrincipalCurvatures`) and the
small linear algebra they share: tangent frames and closed-form 2×2 symmetric eigenpairs.

The sign convention is the project's: outward normal from the face orientation, curvature
positive where the surface bends away from it (``H > 0`` on a sphere), ``κ₁ ≥ κ₂``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..options import PRINCIPAL_FIELDS, check_choice
from ..types import FloatArray


@dataclass(frozen=True)
class PrincipalCurvatures:
    """Principal curvatures and directions at every vertex.

    Attributes
    ----------
    k1, k2 : (n,) float
        ``k1 ≥ k2``; positive where the surface bends away from ``normal``.
    d1, d2 : (n,3) float
        Unit tangent directions of ``k1`` and ``k2`` (a line field: ``±d`` are the same); zero
        where the estimator has none (an isolated vertex).
    normal : (n,3) float
        The unit normal the signs are measured against (outward for counter-clockwise faces).
    estimator : str

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core import PrincipalCurvatures, estimate_curvature, torus_mesh
    >>> V, F = torus_mesh(64, 32, R=3.0, r=1.0)
    >>> pc = estimate_curvature(V, F, "rusinkiewicz")
    >>> isinstance(pc, PrincipalCurvatures), bool((pc.k1 >= pc.k2).all())
    (True, True)
    >>> tangent = np.abs(np.sum(pc.d1 * pc.normal, axis=1)).max() < 1e-12
    >>> orthogonal = np.abs(np.sum(pc.d1 * pc.d2, axis=1)).max() < 1e-12
    >>> bool(tangent), bool(orthogonal)
    (True, True)
    >>> round(float(pc.k1.max()), 1)  # the tube's curvature 1/r
    1.0
    """

    k1: FloatArray
    k2: FloatArray
    d1: FloatArray
    d2: FloatArray
    normal: FloatArray
    estimator: str

    @property
    def H(self) -> FloatArray:
        """Mean curvature ``(k1 + k2)/2``, ``(n,)``."""
        return 0.5 * (self.k1 + self.k2)

    @property
    def K(self) -> FloatArray:
        """Gaussian curvature ``k1 k2``, ``(n,)``."""
        return self.k1 * self.k2

    def field(self, name: str) -> FloatArray:
        """One of :data:`~meshlap_core.options.PRINCIPAL_FIELDS` (``k1``, ``k2``, ``H``, ``K``,
        ``abs_max = max(|k1|, |k2|)``) as ``(n,)``."""
        check_choice(name, PRINCIPAL_FIELDS, "field")
        if name == "abs_max":
            return np.maximum(np.abs(self.k1), np.abs(self.k2))
        return np.asarray(getattr(self, name))

    def shape_operator(self, i: int) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The discrete shape operator at vertex ``i`` as a symmetric 2×2 tensor
        ``S = k1 c1 c1ᵀ + k2 c2 c2ᵀ`` in the tangent basis ``(t1, t2)`` of its normal
        (:func:`tangent_frames`; ``c1``, ``c2`` are ``d1``, ``d2`` in that basis): its
        eigenvalues are ``k1 ≥ k2`` and Euler's formula reads ``κn(θ) = uᵀ S u`` for the unit
        tangent ``u = (cos θ, sin θ)``.

        Returns
        -------
        S : (2,2) float
        t1, t2 : (3,) float
            The basis, ``t1 × t2 = normal[i]``.
        """
        t1, t2 = tangent_frames(self.normal[i : i + 1])
        c1 = np.array([self.d1[i] @ t1[0], self.d1[i] @ t2[0]])
        c2 = np.array([self.d2[i] @ t1[0], self.d2[i] @ t2[0]])
        S = self.k1[i] * np.outer(c1, c1) + self.k2[i] * np.outer(c2, c2)
        return S, t1[0], t2[0]


def tangent_frames(N: FloatArray) -> tuple[FloatArray, FloatArray]:
    """An orthonormal tangent basis ``(t1, t2)`` per unit normal, ``t1 × t2 = n``.

    Parameters
    ----------
    N : (n,3) float
        Unit normals (zero rows give an arbitrary frame).

    Returns
    -------
    t1, t2 : (n,3) float
    """
    ax = np.argmin(np.abs(N), axis=1)  # the axis least along n
    x, y, z = (np.ascontiguousarray(N[:, d]) for d in range(3))
    on0, on1 = ax == 0, ax == 1
    # e_ax × n on coordinate columns: e0 × n = (0, −z, y), e1 × n = (z, 0, −x), e2 × n = (−y, x, 0)
    zero = np.zeros_like(x)
    t1 = np.empty_like(N)
    t1[:, 0] = np.where(on0, zero, np.where(on1, z, -y))
    t1[:, 1] = np.where(on0, -z, np.where(on1, zero, x))
    t1[:, 2] = np.where(on0, y, np.where(on1, -x, zero))
    t1 /= np.maximum(np.linalg.norm(t1, axis=1, keepdims=True), 1e-300)
    a, b, c = t1[:, 0], t1[:, 1], t1[:, 2]
    t2 = np.empty_like(N)
    t2[:, 0] = y * c - z * b
    t2[:, 1] = z * a - x * c
    t2[:, 2] = x * b - y * a
    return t1, t2


def eig_sym2(a: FloatArray, b: FloatArray, c: FloatArray) -> tuple[FloatArray, ...]:
    """Eigen-decomposition of the symmetric ``[[a, b], [b, c]]`` per row, in closed form.

    Returns
    -------
    lam1, lam2 : (n,) float
        ``lam1 ≥ lam2``.
    cos, sin : (n,) float
        The unit eigenvector of ``lam1`` is ``(cos, sin)`` (angle ``½ atan2(2b, a − c)``).
    """
    m, r = 0.5 * (a + c), np.hypot(0.5 * (a - c), b)
    phi = 0.5 * np.arctan2(2.0 * b, a - c)
    return m + r, m - r, np.cos(phi), np.sin(phi)
