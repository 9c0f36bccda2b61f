"""The spectral conformal map (Mullen, Tong, Alliez & Desbrun, SGP 2008).

LSCM removes the conformal energy's null space by pinning two vertices, which biases the
result towards them. Mullen et al. instead minimize ``E_C(x) = ½ xᵀL_Cx`` (:mod:`.conformal`)
under the constraints ``xᵀBx = 1`` and ``xᵀBe = 0`` (``e`` the two translations), ``B`` the
diagonal matrix with 1 at every boundary vertex (for both coordinates) and 0 inside: the map
is the **Fiedler vector** of the generalized eigenproblem

    ``L_C x = λ B x``,

the eigenvector of the smallest eigenvalue above the translations' ``λ = 0``. ``L_C`` commutes
with the rotation by 90° (``[u; v] → [−v; u]``) and so does ``B``: every eigenvalue is double,
and any vector of the Fiedler pair's plane is the same map turned and scaled.

``B`` is zero inside, so the eigenproblem lives on the boundary. The interior rows read
``K u_I + K_IB u_B = 0`` (``Q_A`` has no interior entries): the map is *harmonic inside*, and
eliminating the interior leaves the pencil ``S x_B = λ x_B`` with the Schur complement
``S = diag(S_K, S_K) − Q_A``, ``S_K = K_BB − K_BI K_II⁻¹ K_IB`` (the discrete
Dirichlet-to-Neumann map of the boundary, :mod:`.schur`), dense, ``2b × 2b``. That pencil is
solved by the project's eigensolver (:func:`~meshlap_core.linalg.eigsolve.pencil_eigenpairs`,
dense path, with its residual and Sylvester inertia checks), then the interior is the
harmonic extension ``u_I = −K_II⁻¹ K_IB u_B``. The result is centred and scaled so that its
area is the surface's.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from ..linalg.common import ProgressCallback, report_progress
from ..linalg.eigsolve import DENSE_HARD_MAX_N, pencil_eigenpairs
from ..types import FloatArray, IntArray
from .conformal import area_matrix, image_area
from .schur import BoundaryReduction


def _fiedler(U: FloatArray, b: int) -> FloatArray:
    """The dominant direction, once the two translations are removed, of the lowest
    eigenvectors ``U`` ``(2b,k)`` (``B = I`` on the boundary): the Fiedler pair's plane (or,
    on a developable patch, a similarity of its layout)."""
    T = np.zeros((2 * b, 2))
    T[:b, 0] = T[b:, 1] = 1.0 / np.sqrt(b)
    W = U - T @ (T.T @ U)
    left, _, _ = np.linalg.svd(W, full_matrices=False)
    return left[:, 0]


def spectral_conformal(
    K: sp.csr_matrix,
    halfedges: IntArray,
    boundary: IntArray,
    area: float,
    *,
    progress: ProgressCallback | None = None,
    cancel: Any = None,
) -> FloatArray:
    """The spectral conformal map of a disk (see the module).

    Parameters
    ----------
    K : (n,n) scipy.sparse.csr_matrix
        The cotangent stiffness ``−C``.
    halfedges : (h,2) int
        Every boundary half-edge (interior on the left).
    boundary : (b,) int
        Every boundary vertex (all loops).
    area : float
        The surface's area (the result's area).
    progress : callable, optional
        ``progress(fraction, message)``.
    cancel : threading.Event or callable, optional
        Checked between blocks of solves and in the eigensolver.

    Returns
    -------
    uv : (n,2) float

    Raises
    ------
    MeshError
        A boundary longer than the dense eigensolver allows (``2b`` above
        :data:`~meshlap_core.linalg.eigsolve.DENSE_HARD_MAX_N`).
    Cancelled
    """
    n = K.shape[0]
    bnd = np.unique(boundary)
    b = len(bnd)
    if 2 * b > DENSE_HARD_MAX_N:
        raise MeshError(
            f"the boundary has {b} vertices; the spectral conformal map's eigenproblem on it "
            f"is dense ({2 * b} unknowns) and limited to {DENSE_HARD_MAX_N // 2} boundary "
            "vertices (use lscm)",
            "method",
        )
    reduction = BoundaryReduction(K, bnd, progress=progress, cancel=cancel)
    local = np.full(n, -1)
    local[bnd] = np.arange(b)
    S = np.zeros((2 * b, 2 * b))
    S[:b, :b] = S[b:, b:] = reduction.S
    S -= area_matrix(local[halfedges], b).toarray()
    report_progress(progress, 0.9, f"boundary eigenproblem, {2 * b} unknowns")
    _, U, _ = pencil_eigenpairs(sp.csr_matrix(S), np.ones(2 * b), 4, method="dense", cancel=cancel)
    x = _fiedler(U, b)
    xb = np.stack([x[:b], x[b:]], axis=1)
    xb -= xb.mean(axis=0)
    uv = reduction.extend(xb)
    report_progress(progress, 1.0, "spectral conformal map done")
    return uv * np.sqrt(area / max(image_area(uv, halfedges), np.finfo(float).tiny))
