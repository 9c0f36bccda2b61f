"""Discrete Laplacians: uniform (graph), cotangent stiffness, lumped mass, Laplace–Beltrami, and
the intrinsic quantities they are built from (squared edge lengths, face areas; the mean edge
length ``h``, the mesh's length scale).

Sign convention (the whole project uses it): every Laplacian here is **negative
semidefinite**, so that for a surface ``Δx = -2 H n`` with ``H > 0`` on a sphere whose normals
point outwards. Eigenvalues shown to users are the non-negative frequencies of ``-Δ``.

All matrices are ``scipy.sparse.csr_matrix`` of shape ``(n, n)`` with ``n = len(V)``, assembled
from COO triplets with that explicit shape (trailing unreferenced vertices keep a zero row).

References
----------
Pinkall & Polthier, "Computing discrete minimal surfaces and their conjugates", 1993.
Meyer, Desbrun, Schröder & Barr, "Discrete differential-geometry operators for triangulated
2-manifolds", 2003 (the mixed Voronoi area).
"""

from __future__ import annotations

import igl
import numpy as np
import scipy.sparse as sp

from .options import AREA_KINDS, DEFAULT_AREA, DEGENERATE_REL, MASS_AREA, AreaKind, check_choice
from .topology.edges import edges as unique_edges
from .types import FloatArray, IntArray, as_faces, as_mesh

# A face with 16 A² ≤ (2·DEGENERATE_REL)² (Σ l²)² is degenerate (see options.DEGENERATE_REL):
# its cotangent weights are set to zero instead of ±inf.
_DEGENERATE_REL16 = (2.0 * DEGENERATE_REL) ** 2


def squared_edge_lengths(V: FloatArray, F: IntArray) -> FloatArray:
    """Squared edge lengths, column ``i`` being the edge opposite corner ``i``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    l2 : (m,3) float
        ``l2[f, i] = |V[F[f, i+1]] - V[F[f, i+2]]|^2`` (indices mod 3).
    """
    V, F = as_mesh(V, F)
    P = V[F]  # (m,3,3)
    return np.stack(
        [
            np.sum((P[:, 1] - P[:, 2]) ** 2, axis=1),
            np.sum((P[:, 2] - P[:, 0]) ** 2, axis=1),
            np.sum((P[:, 0] - P[:, 1]) ** 2, axis=1),
        ],
        axis=1,
    )


def mean_edge_length(V: FloatArray, F: IntArray, edges: IntArray | None = None) -> float:
    """The mean length ``h`` of the mesh's edges, each edge counted once: the mesh's length
    scale (``igl.avg_edge_length``'s value), e.g. the heat method's ``t = m h²``, the jet fit's
    smallest radius and the ``h`` of every convergence order.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    edges : (e,2) int, optional
        The unique undirected edges of ``F`` when the caller has them already (an edge table
        it keeps); otherwise they are built (:func:`~meshlap_core.topology.edges`).

    Returns
    -------
    h : float
        ``0.0`` for a mesh without faces.
    """
    V, F = as_mesh(V, F)
    E = unique_edges(F) if edges is None else np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(E) == 0:
        return 0.0
    return float(np.mean(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1)))


def face_areas(V: FloatArray, F: IntArray) -> FloatArray:
    """Triangle areas ``|(b-a) x (c-a)| / 2``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    A : (m,) float
    """
    V, F = as_mesh(V, F)
    if len(F) == 0:
        return np.zeros(0)
    return 0.5 * igl.doublearea(V, F).ravel()


def cotangents_intrinsic(l2: FloatArray) -> FloatArray:
    """Cotangent of each corner angle from squared edge lengths only.

    ``cot θ_i = (l_j² + l_k² − l_i²) / (4 A)`` with ``16 A² = 2(a²b² + b²c² + c²a²) − a⁴ − b⁴ − c⁴``
    (Heron). Degenerate (zero-area) faces get cotangent 0, never ``inf`` or ``NaN``.

    Parameters
    ----------
    l2 : (m,3) float
        Squared lengths, column ``i`` opposite corner ``i``.

    Returns
    -------
    cot : (m,3) float
    """
    l2 = np.asarray(l2, dtype=np.float64)
    a, b, c = l2[:, 0], l2[:, 1], l2[:, 2]
    area16 = 2.0 * (a * b + b * c + c * a) - (a * a + b * b + c * c)  # = 16 A^2
    scale = (a + b + c) ** 2
    ok = area16 > _DEGENERATE_REL16 * scale
    four_area = np.where(ok, np.sqrt(np.where(ok, area16, 1.0)), 1.0)  # 4A
    num = np.stack([b + c - a, c + a - b, a + b - c], axis=1)
    return np.where(ok[:, None], num / four_area[:, None], 0.0)


def cotan_stiffness_intrinsic(l2: FloatArray, F: IntArray, n: int) -> sp.csr_matrix:
    """Cotangent stiffness matrix built by hand from squared edge lengths (teaching version).

    ``C_ij = ½ (cot α_ij + cot β_ij)`` for an edge ``ij`` and ``C_ii = −Σ_j C_ij``, so ``C`` is
    symmetric negative semidefinite and ``C·1 = 0``. Equal to :func:`cotan_stiffness` (libigl's
    ``cotmatrix``), which the tests check.

    Parameters
    ----------
    l2 : (m,3) float
        Squared edge lengths, column ``i`` opposite corner ``i``.
    F : (m,3) int
    n : int
        Number of vertices (the matrix is ``(n,n)``).

    Returns
    -------
    C : (n,n) scipy.sparse.csr_matrix
    """
    F = as_faces(F, n)
    half_cot = 0.5 * cotangents_intrinsic(l2)
    # the edge opposite corner k joins corners k+1 and k+2
    i = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    j = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    w = np.concatenate([half_cot[:, 0], half_cot[:, 1], half_cot[:, 2]])
    rows = np.concatenate([i, j, i, j])
    cols = np.concatenate([j, i, i, j])
    vals = np.concatenate([w, w, -w, -w])
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()


def cotan_stiffness(V: FloatArray, F: IntArray) -> sp.csr_matrix:
    """Cotangent stiffness matrix ``C`` (libigl ``cotmatrix``), negative semidefinite.

    ``C_ij = ½ (cot α_ij + cot β_ij)`` for an edge ``ij``, ``C_ii = −Σ_j C_ij``. On a boundary edge
    only one angle contributes. ``C`` is the weak (integrated) Laplacian; the pointwise
    Laplace–Beltrami operator is ``Δ = M⁻¹ C`` (see :func:`laplace_beltrami`).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    C : (n,n) scipy.sparse.csr_matrix, symmetric, rows summing to 0

    Examples
    --------
    One right triangle, by hand: the right angle at vertex 0 gives edge 12 weight
    ½ cot 90° = 0, the 45° angles give edges 01 and 02 weight ½ cot 45° = ½:

    >>> from meshlap_core import cotan_stiffness
    >>> C = cotan_stiffness([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> C.toarray().round(12).tolist()
    [[-1.0, 0.5, 0.5], [0.5, -0.5, 0.0], [0.5, 0.0, -0.5]]
    """
    V, F = as_mesh(V, F)
    n = len(V)
    if len(F) == 0:
        return sp.csr_matrix((n, n))
    C = igl.cotmatrix(V, F).tocsr()
    if not np.isfinite(C.data).all():  # degenerate faces: fall back to the guarded version
        return cotan_stiffness_intrinsic(squared_edge_lengths(V, F), F, n)
    return C


def vertex_areas(V: FloatArray, F: IntArray, area: AreaKind = DEFAULT_AREA) -> FloatArray:
    """Lumped per-vertex areas (the diagonal of the mass matrix).

    ``barycentric``: ``A_i = ⅓ Σ`` areas of the faces around ``i``. ``voronoi``: the mixed
    Voronoi area of Meyer et al. 2003 (Voronoi region for non-obtuse triangles, half / quarter of
    the triangle area at obtuse ones), as computed by libigl. Both sum to the surface area.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    area : {"barycentric", "voronoi"}

    Returns
    -------
    a : (n,) float
        Zero for unreferenced vertices.

    Examples
    --------
    One right triangle of area ½, by hand: the barycentric areas are thirds; the mixed
    Voronoi area gives the right-angled corner ¼ and the other two ⅛ each:

    >>> from meshlap_core import vertex_areas
    >>> V, F = [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]
    >>> vertex_areas(V, F, "barycentric").round(6).tolist()
    [0.166667, 0.166667, 0.166667]
    >>> vertex_areas(V, F, "voronoi").round(12).tolist()
    [0.25, 0.125, 0.125]
    """
    check_choice(area, AREA_KINDS, "area")
    V, F = as_mesh(V, F)
    n = len(V)
    if len(F) == 0:
        return np.zeros(n)
    if area == "barycentric":
        A = face_areas(V, F) / 3.0
        return np.bincount(F.ravel(), weights=np.repeat(A, 3), minlength=n)
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
    a = np.zeros(n)  # libigl sizes M by F.max() + 1: trailing unreferenced vertices get 0
    d = np.asarray(M.diagonal(), dtype=np.float64)
    a[: len(d)] = d
    if not np.isfinite(a).all():  # degenerate faces: igl divides by zero
        a = np.where(np.isfinite(a), a, 0.0)
    return a


def mass_matrix(V: FloatArray, F: IntArray, area: AreaKind = MASS_AREA) -> sp.csr_matrix:
    """Lumped (diagonal) mass matrix ``M = diag(vertex_areas(V, F, area))``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    area : {"barycentric", "voronoi"}

    Returns
    -------
    M : (n,n) scipy.sparse.csr_matrix, diagonal

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core import icosphere, mass_matrix
    >>> V, F = icosphere(0)
    >>> M = mass_matrix(V, F)
    >>> M.shape, M.nnz  # diagonal
    ((12, 12), 12)
    >>> a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    >>> area = np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2
    >>> bool(np.isclose(M.diagonal().sum(), area))  # the areas sum to the surface area
    True
    """
    a = vertex_areas(V, F, area)
    return sp.csr_matrix(sp.diags(a, format="csr"))


def adjacency_matrix(F: IntArray, n: int) -> sp.csr_matrix:
    """Symmetric 0/1 vertex adjacency matrix (``A_ij = 1`` when ``ij`` is an edge).

    Parameters
    ----------
    F : (m,3) int
    n : int
        Number of vertices.

    Returns
    -------
    A : (n,n) scipy.sparse.csr_matrix of float
    """
    F = as_faces(F, n)
    i = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    j = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    A = sp.coo_matrix(
        (np.ones(2 * len(i)), (np.concatenate([i, j]), np.concatenate([j, i]))), shape=(n, n)
    ).tocsr()
    A.data[:] = 1.0  # duplicates (an edge shared by two faces) were summed
    return A


def uniform_laplacian(F: IntArray, n: int) -> sp.csr_matrix:
    """Uniform (graph) Laplacian ``L = D⁻¹A − I``, negative semidefinite in the ``D`` inner product.

    ``(L f)_i = (1/|N₁(i)|) Σ_{j∈N₁(i)} (f_j − f_i)``: the course formula. Rows sum to 0;
    rows of isolated vertices are zero. ``L`` is not symmetric; ``D L = A − D`` is.

    Parameters
    ----------
    F : (m,3) int
    n : int
        Number of vertices.

    Returns
    -------
    L : (n,n) scipy.sparse.csr_matrix

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core import icosphere, uniform_laplacian
    >>> V, F = icosphere(0)
    >>> L = uniform_laplacian(F, len(V))
    >>> L[0].toarray().round(12).tolist()[0][:7]  # −1 on the diagonal, 1/5 per neighbour
    [-1.0, 0.2, 0.2, 0.2, 0.2, 0.2, 0.0]
    >>> bool(np.allclose(L @ np.ones(len(V)), 0))  # L·1 = 0
    True
    """
    A = adjacency_matrix(F, n)
    deg = np.asarray(A.sum(axis=1)).ravel()
    inv = np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)
    return (sp.diags(inv) @ A - sp.diags((deg > 0).astype(np.float64))).tocsr()


def laplace_beltrami(V: FloatArray, F: IntArray, area: AreaKind = DEFAULT_AREA) -> sp.csr_matrix:
    """Pointwise Laplace–Beltrami operator ``Δ = M⁻¹ C`` (negative semidefinite).

    Applied to the coordinates it gives ``Δx = −2 H n``. Rows of vertices with zero area
    (unreferenced) are zero.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    area : {"barycentric", "voronoi"}
        Which lumped area ``M`` uses.

    Returns
    -------
    L : (n,n) scipy.sparse.csr_matrix

    Examples
    --------
    ``Δx = −2Hn``: on the unit sphere ``H = 1`` at every vertex:

    >>> import numpy as np
    >>> from meshlap_core import icosphere, laplace_beltrami, vertex_normals
    >>> V, F = icosphere(2)
    >>> L = laplace_beltrami(V, F, "voronoi")
    >>> H = -0.5 * np.sum((L @ V) * vertex_normals(V, F), axis=1)
    >>> round(float(H.min()), 3), round(float(H.max()), 3)
    (1.0, 1.0)
    """
    C = cotan_stiffness(V, F)
    a = vertex_areas(V, F, area)
    inv = np.divide(1.0, a, out=np.zeros_like(a), where=a > 0)
    return (sp.diags(inv) @ C).tocsr()
