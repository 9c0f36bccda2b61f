"""The conformal energy and the least-squares conformal map (LSCM).

A map ``z = u + iv`` of a surface to the plane is conformal where its Jacobian is a rotation
times a scale. Its Dirichlet energy ``E_D = ½∫|∇u|² + |∇v|²`` is at least the (signed) area
``𝒜`` of the image, with equality exactly for conformal maps, so the **conformal energy**

    ``E_C(u, v) = E_D − 𝒜 = ½ xᵀ L_C x``,  ``x = [u; v]`` (``2n`` unknowns),
    ``L_C = [[K, 0], [0, K]] − Q_A``,

measures the departure from conformality (Hutchinson 1991; Mullen, Tong, Alliez & Desbrun,
"Spectral conformal parameterization", SGP 2008, sec. 3). ``K = −C`` is the cotangent
stiffness; the image's area is a sum over the boundary half-edges ``a → b`` (interior on the
left), ``𝒜 = ½ Σ (u_a v_b − u_b v_a)``, whose symmetric matrix ``Q_A`` (``½ xᵀQ_Ax = 𝒜``) has
``±½`` at ``(u_a, v_b)`` and ``(u_b, v_a)``. ``L_C`` is positive semidefinite with zero row
sums; its null space holds the translations (and, on a developable surface, every similarity).

**LSCM** (Lévy, Petitjean, Ray & Maillot, "Least squares conformal maps", SIGGRAPH 2002; the
same minimizer as Desbrun, Meyer & Alliez 2002) minimizes ``E_C`` with two vertices pinned,
which removes the similarities: here the two outer-boundary vertices farthest apart (a double
sweep), at ``(0, 0)`` and ``(d, 0)``, ``d`` their distance in space. The same two vertices
pinned anywhere else give the same map up to a similarity (``E_C`` does not see
similarities); two other vertices give another map: the pins pull on the layout, the bias
the spectral map removes. ``L_C`` is factorized once with the four pinned unknowns
decoupled.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..types import FloatArray, IntArray
from .fixed_boundary import DirichletSolver, sorted_csr


def area_matrix(halfedges: IntArray, n: int) -> sp.csr_matrix:
    """``Q_A`` ``(2n,2n)``: ``½ xᵀ Q_A x`` is the signed area enclosed by the boundary
    half-edges ``(b,2)`` (interior on the left) under the map ``x = [u; v]``."""
    a, b = halfedges[:, 0], halfedges[:, 1]
    half = np.full(len(a), 0.5)
    rows = np.concatenate([a, n + b, b, n + a])
    cols = np.concatenate([n + b, a, n + a, b])
    vals = np.concatenate([half, half, -half, -half])
    return sp.coo_matrix((vals, (rows, cols)), shape=(2 * n, 2 * n)).tocsr()


def conformal_energy(K: sp.csr_matrix, halfedges: IntArray) -> sp.csr_matrix:
    """``L_C = diag(K, K) − Q_A`` ``(2n,2n)`` (sorted CSR, diagonal stored): ``½ xᵀL_Cx`` is
    the conformal energy of the map ``x = [u; v]``."""
    n = K.shape[0]
    return sorted_csr(sp.block_diag([K, K], format="csr") - area_matrix(halfedges, n))


def image_area(uv: FloatArray, halfedges: IntArray) -> float:
    """``|𝒜|``: the area the boundary half-edges ``(h,2)`` enclose in the layout ``uv``
    (the shoelace formula)."""
    a, b = uv[halfedges[:, 0]], uv[halfedges[:, 1]]
    return abs(0.5 * float(np.sum(a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1])))


def far_pair(V: FloatArray, loop: IntArray) -> tuple[int, int]:
    """Two vertices of ``loop`` far apart in space (a double sweep: the farthest from the
    loop's first vertex, then the farthest from that one)."""
    P = V[loop]
    a = int(np.argmax(np.linalg.norm(P - P[0], axis=1)))
    b = int(np.argmax(np.linalg.norm(P - P[a], axis=1)))
    return int(loop[a]), int(loop[b])


class LSCMSolver:
    """The least-squares conformal map of a disk with two pinned vertices (factorized once).

    Parameters
    ----------
    V : (n,3) float
    K : (n,n) scipy.sparse.csr_matrix
        The cotangent stiffness ``−C`` (sorted, diagonal stored).
    halfedges : (b,2) int
        Every boundary half-edge (interior on the left).
    pins : (int, int)
        The pinned vertices (distinct).
    """

    def __init__(
        self, V: FloatArray, K: sp.csr_matrix, halfedges: IntArray, pins: tuple[int, int]
    ) -> None:
        n = K.shape[0]
        self.n = n
        self.pins = (int(pins[0]), int(pins[1]))
        self.distance = float(np.linalg.norm(V[self.pins[0]] - V[self.pins[1]]))
        self.L = conformal_energy(K, halfedges)
        i, j = self.pins
        self._solver = DirichletSolver(self.L, np.array([i, j, n + i, n + j]))

    def solve(self) -> FloatArray:
        """The map ``(n,2)``: pins at ``(0, 0)`` and ``(d, 0)``."""
        x = self._solver.solve(np.array([[0.0], [self.distance], [0.0], [0.0]]))[:, 0]
        return np.stack([x[: self.n], x[self.n :]], axis=1)
