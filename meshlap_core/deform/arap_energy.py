"""The as-rigid-as-possible energy, its covariances and the right-hand side of its global step.

Sorkine & Alexa, "As-rigid-as-possible surface modeling", SGP 2007: with rest positions ``p``,
deformed positions ``x`` and one rotation ``R_i`` per vertex,

    E(x, R) = Σ_i Σ_{j ∈ N(i)} w_ij ‖(x_i − x_j) − R_i (p_i − p_j)‖²,
    w_ij = ½ (cot α_ij + cot β_ij)                       (the cotangent weights, ``C_ij``)

summed here face by face: every face ``f`` contributes, for each corner ``c``, the edge
``(j, k)`` opposite it with the weight ``½ cot θ_c`` to the rotation of each of its rotation
owners ``r`` — the two ends of that edge for the *spokes* energy (the paper's), all three
corners for *spokes and rims* (Chao, Pinkall, Sanan & Schröder 2010; libigl's default on
triangle meshes in 3D). Each term ``c ‖(x_j − x_k) − R_r (p_j − p_k)‖²`` counts every edge
``μ`` times (μ = 2 spokes, 3 spokes and rims), so:

* **local step**: for fixed ``x``, ``R_r`` maximizes ``tr(R_r S_r)`` with the covariance
  ``S_r = Σ_{t ∋ r} c_t e_t e'_tᵀ`` (``e = p_j − p_k``, ``e' = x_j − x_k``): one sparse product
  ``Z x`` for all vertices at once (``Z`` a ``(3n, n)`` matrix with the pattern of the
  Laplacian's rows);
* **global step**: for fixed ``R``, ``∂E/∂x = 0`` is ``K x = b`` with ``K = −C`` the cotangent
  stiffness and ``b = (1/μ) Σ_t c_t R_r e_t (δ_j − δ_k)`` — for spokes
  ``b_i = Σ_j (w_ij/2) (R_i + R_j)(p_i − p_j)`` (eq. 9 of the paper); ``b = Zᵀ R / μ``;
* the weights are the cotangents, negative across obtuse angles, so a term, a vertex's share
  and even the total can fall below 0 on a mesh with obtuse triangles (libigl's too): the
  iterations then stretch the edges of negative weight (``rigidity.rotation_error``, with
  ``|w|``, shows where);
* **energy** of the global step's minimizer: ``E = μ (tr xᵀKx − 2 tr xᵀb + tr pᵀKp)``
  (three products, no loop over terms; exact up to round-off of order ``ε μ tr pᵀKp``), and
  each vertex's share from the terms directly (:meth:`ArapEnergy.vertex_energy`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..laplacian import cotangents_intrinsic, squared_edge_lengths
from ..options import ARAP_ENERGIES, DEFAULT_ARAP_ENERGY, ArapEnergyKind, check_choice
from ..types import BoolArray, FloatArray, IntArray
from .constraints import solid_faces
from .stiffness import stiffness


def arap_terms(F: IntArray, half_cot: FloatArray, kind: str) -> tuple[IntArray, ...]:
    """The energy's terms ``(owner r, j, k, weight c)`` for each face, corner and owner.

    Parameters
    ----------
    F : (m,3) int
    half_cot : (m,3) float
        ``½ cot`` of each corner's angle (the weight of the edge opposite it).
    kind : {"spokes", "spokes-and-rims"}

    Returns
    -------
    r, j, k : (T,) int
    c : (T,) float
        ``T = 6m`` (spokes) or ``9m``.
    """
    parts = []
    for corner in range(3):
        j, k = F[:, (corner + 1) % 3], F[:, (corner + 2) % 3]
        for owner in range(3):
            if kind == "spokes" and owner == corner:
                continue  # the edge opposite a corner is a rim of that corner's ring
            parts.append((F[:, owner], j, k, half_cot[:, corner]))
    r, j, k, c = (np.concatenate(x) for x in zip(*parts, strict=True))
    return r, j, k, c


class ArapEnergy:
    """The ARAP energy of one rest mesh (see the module docstring for the formulas).

    Parameters
    ----------
    V : (n,3) float
        Rest positions ``p``.
    F : (m,3) int
    kind : {"spokes", "spokes-and-rims"}
    absolute : bool
        Use ``|c|`` for the weights (a non-negative energy; :func:`rotation_error`'s choice).
    solid : (m,) bool, optional
        The faces that are not degenerate, when the caller has them.
    l2 : (m,3) float, optional
        The squared edge lengths, when the caller has them (a deformer does).

    Attributes
    ----------
    K : (n,n) scipy.sparse.csr_matrix
        The cotangent stiffness ``−C`` (with ``|c|``: the graph Laplacian of those weights).
    multiplicity : int
        ``μ``: how often each edge is counted (2 or 3).
    """

    def __init__(
        self,
        V: FloatArray,
        F: IntArray,
        kind: ArapEnergyKind = DEFAULT_ARAP_ENERGY,
        absolute: bool = False,
        solid: BoolArray | None = None,
        l2: FloatArray | None = None,
    ) -> None:
        self.kind = check_choice(kind, ARAP_ENERGIES, "ARAP energy", "energy")
        self.P = V
        n = self.n = len(V)
        self.multiplicity = 2 if self.kind == "spokes" else 3
        if self.kind == "spokes":
            K = stiffness(V, F, solid_faces(V, F) if solid is None else solid, l2)
            self.K, self.Z, self.terms = _spokes(V, K, absolute)
        else:
            half = 0.5 * cotangents_intrinsic(squared_edge_lengths(V, F) if l2 is None else l2)
            if absolute:
                half = np.abs(half)
            self.K = _graph_laplacian(F, half, n)
            self.terms = arap_terms(F, half, self.kind)
            self.Z = _covariance_operator(V, self.terms, n)
        self.Zt = (self.Z.T / self.multiplicity).tocsr()
        self.rest = self.multiplicity * float(np.einsum("ij,ij->", V, self.K @ V))

    def covariances(self, X: FloatArray) -> FloatArray:
        """``S_r = Σ_t c e e'ᵀ`` of the positions ``X`` ``(n,3)``, component-major ``(3,3,n)``."""
        out = self.Z @ X  # (3n, 3): row a·n + r, column b (one pass over Z)
        return np.ascontiguousarray(out.reshape(3, self.n, 3).transpose(0, 2, 1))

    def rhs(self, R: FloatArray) -> FloatArray:
        """The global step's ``b`` ``(n,3)`` for rotations ``R`` ``(3,3,n)``."""
        return self.Zt @ R.transpose(1, 2, 0).reshape(3 * self.n, 3)  # row c·n + r, column a

    def energy(self, X: FloatArray, b: FloatArray) -> float:
        """``E(X, R)`` from ``b = rhs(R)`` (three products; see the module docstring)."""
        quad = float(np.einsum("ij,ij->", X, self.K @ X))
        cross = float(np.einsum("ij,ij->", X, b))
        return self.multiplicity * (quad - 2.0 * cross) + self.rest

    def vertex_energy(self, X: FloatArray, R: FloatArray) -> FloatArray:
        """Each rotation owner's terms ``Σ_{t ∋ r} c ‖e'_t − R_r e_t‖²`` ``(n,)``, summed term by
        term (exact; they add up to :meth:`energy`)."""
        r, j, k, c = self.terms
        e = self.P[j] - self.P[k]
        d = X[j] - X[k]
        for a in range(3):
            d[:, a] -= R[a, 0, r] * e[:, 0] + R[a, 1, r] * e[:, 1] + R[a, 2, r] * e[:, 2]
        return np.bincount(r, c * np.einsum("ij,ij->i", d, d), minlength=self.n)

    def rest_terms(self) -> FloatArray:
        """Each owner's ``Σ_{t ∋ r} c ‖e_t‖²`` ``(n,)`` (the energy of collapsing the ring)."""
        r, j, k, c = self.terms
        e = self.P[j] - self.P[k]
        return np.bincount(r, c * np.einsum("ij,ij->i", e, e), minlength=self.n)


def _spokes(
    V: FloatArray, K: sp.csr_matrix, absolute: bool
) -> tuple[sp.csr_matrix, sp.csr_matrix, tuple[IntArray, ...]]:
    """The spokes energy's stiffness, covariance operator ``Z`` and terms, from the cotangent
    stiffness ``K`` (sorted CSR, its diagonal stored) without assembling anything:
    ``Z_a[r, j] = −w_rj (p_r − p_j)_a`` and ``Z_a[r, r] = Σ_j w_rj (p_r − p_j)_a`` have the
    pattern of ``K``, and the terms are its off-diagonal entries (each directed spoke once,
    ``c = w_rj``). ``absolute``: ``|w_rj|`` (and ``K`` rebuilt from them)."""
    n = K.shape[0]
    rows = np.repeat(np.arange(n), np.diff(K.indptr))
    cols = K.indices
    off = rows != cols
    w = np.where(off, -K.data, 0.0)
    diagonal = np.flatnonzero(~off)
    if absolute:
        w = np.abs(w)
        kdata = -w
        kdata[diagonal] = np.bincount(rows, w, minlength=n)[rows[diagonal]]
        K = sp.csr_matrix((kdata, cols, K.indptr), shape=(n, n))
    data = []
    for a in range(3):
        e = w * (V[rows, a] - V[cols, a])  # w_rj (p_r − p_j)_a, 0 on the diagonal
        z = -e
        z[diagonal] = np.bincount(rows, e, minlength=n)[rows[diagonal]]
        data.append(z)
    nnz = len(cols)
    indptr = np.concatenate([K.indptr, K.indptr[1:] + nnz, K.indptr[1:] + 2 * nnz])
    Z = sp.csr_matrix((np.concatenate(data), np.tile(cols, 3), indptr), shape=(3 * n, n))
    terms = (rows[off], rows[off], cols[off], w[off])
    return K, Z, terms


def _covariance_operator(V: FloatArray, terms: tuple[IntArray, ...], n: int) -> sp.csr_matrix:
    """``Z`` ``(3n, n)`` assembled from the terms: row ``a·n + r`` holds ``c e_a`` at ``j`` and
    ``−c e_a`` at ``k`` for each term ``(r, j, k, c)``, ``e = p_j − p_k``."""
    r, j, k, c = terms
    e = V[j] - V[k]
    rows = np.concatenate([a * n + r for a in range(3)] * 2)
    cols = np.concatenate([j, j, j, k, k, k])
    vals = np.concatenate([c * e[:, a] for a in range(3)] + [-c * e[:, a] for a in range(3)])
    return sp.coo_matrix((vals, (rows, cols)), shape=(3 * n, n)).tocsr()


def _graph_laplacian(F: IntArray, half: FloatArray, n: int) -> sp.csr_matrix:
    """``Σ_f Σ_c w (δ_j − δ_k)(δ_j − δ_k)ᵀ`` with the face weights ``half`` (positive
    semidefinite; the cotangent stiffness when ``half`` are the half cotangents)."""
    i = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    j = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    w = np.concatenate([half[:, 0], half[:, 1], half[:, 2]])
    rows = np.concatenate([i, j, i, j])
    cols = np.concatenate([j, i, i, j])
    vals = np.concatenate([-w, -w, w, w])
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()
