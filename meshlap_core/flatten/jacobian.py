"""The Jacobian of a piecewise-linear map to the plane, face by face.

Each face gets an isometric 2-D frame: ``e₁`` along its first edge, ``e₂ = n × e₁`` in its plane
(``n`` the unit normal of the face orientation), and its corners' coordinates in that frame,
``x₀ = (0, 0)``, ``x₁ = (ℓ, 0)``, ``x₂ = (a, b)`` with ``b > 0``. A map sending the corners to
``u₀, u₁, u₂`` is linear on the face with the 2×2 Jacobian

    ``J = [u₁ − u₀, u₂ − u₀] · [x₁ − x₀, x₂ − x₀]⁻¹``,

so ``J`` acts on tangent vectors written in ``(e₁, e₂)``. Its singular values ``σ₁ ≥ σ₂`` (the
stretches along the principal directions) come in closed form: with ``J = [[a, b], [c, d]]``,
``σ₁,₂ = √(((a+d)² + (c−b)²)/4) ± √(((a−d)² + (b+c)²)/4)`` (the conformal and anti-conformal
parts of ``J``), ``det J = σ₁σ₂`` times the sign of the orientation, and the rotation closest to
``J`` has the angle ``atan2(c − b, a + d)`` (what ARAP's local step needs; Liu et al. 2008).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..types import FloatArray, IntArray


@dataclass(frozen=True, eq=False)
class FaceFrames:
    """Each face's isometric frame and its corners in it.

    Attributes
    ----------
    e1, e2 : (m,3) float
        Orthonormal basis of each face's plane (``e₁`` along the edge from corner 0 to 1).
    x : (m,3,2) float
        The corners' frame coordinates (``x[:, 0] = 0``).
    inverse : (m,2,2) float
        ``[x₁ − x₀, x₂ − x₀]⁻¹``.
    area : (m,) float
        The faces' areas (``ℓ·b/2``).
    """

    e1: FloatArray
    e2: FloatArray
    x: FloatArray
    inverse: FloatArray
    area: FloatArray


def face_frames(V: FloatArray, F: IntArray) -> FaceFrames:
    """The isometric frame of every face of ``(V, F)`` (no zero-area face, as checked by
    :func:`~meshlap_core.flatten.disk.make_disk`)."""
    p0, p1, p2 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    d1, d2 = p1 - p0, p2 - p0
    ell = np.linalg.norm(d1, axis=1)
    e1 = d1 / ell[:, None]
    n = np.cross(d1, d2)
    n /= np.linalg.norm(n, axis=1)[:, None]
    e2 = np.cross(n, e1)
    a = np.einsum("ij,ij->i", d2, e1)
    b = np.einsum("ij,ij->i", d2, e2)
    m = len(F)
    x = np.zeros((m, 3, 2))
    x[:, 1, 0] = ell
    x[:, 2, 0] = a
    x[:, 2, 1] = b
    inverse = np.zeros((m, 2, 2))
    inverse[:, 0, 0] = 1.0 / ell
    inverse[:, 0, 1] = -a / (ell * b)
    inverse[:, 1, 1] = 1.0 / b
    return FaceFrames(e1=e1, e2=e2, x=x, inverse=inverse, area=0.5 * ell * b)


def jacobians(frames: FaceFrames, F: IntArray, uv: FloatArray) -> FloatArray:
    """``J`` of the map ``uv`` ``(n,2)`` on every face, ``(m,2,2)`` (rows: ``u``, ``v``;
    columns: the frame's ``e₁``, ``e₂``)."""
    u0 = uv[F[:, 0]]
    d1, d2 = uv[F[:, 1]] - u0, uv[F[:, 2]] - u0
    inv = frames.inverse  # upper triangular
    J = np.empty((len(F), 2, 2))
    J[:, :, 0] = d1 * inv[:, 0, 0, None]
    J[:, :, 1] = d1 * inv[:, 0, 1, None] + d2 * inv[:, 1, 1, None]
    return J


def singular_values(J: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``σ₁ ≥ σ₂ ≥ 0`` of every 2×2 matrix of ``J`` ``(m,2,2)``, in closed form (see the
    module); two ``(m,)`` arrays."""
    a, b, c, d = J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1]
    q = 0.5 * np.hypot(a + d, c - b)  # the conformal part's scale
    r = 0.5 * np.hypot(a - d, b + c)  # the anti-conformal part's
    return q + r, np.abs(q - r)


def closest_rotations(J: FloatArray) -> FloatArray:
    """The rotation nearest each 2×2 ``J`` in the Frobenius norm (never a reflection),
    ``(m,2,2)``: angle ``atan2(c − b, a + d)``, which maximizes ``tr(RᵀJ)``."""
    theta = np.arctan2(J[:, 1, 0] - J[:, 0, 1], J[:, 0, 0] + J[:, 1, 1])
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([np.stack([c, -s], axis=1), np.stack([s, c], axis=1)], axis=1)
