"""A correct student file that leans on libigl (cotmatrix, massmatrix, internal_angles,
is_border_vertex) and scipy's sparse eigensolver: allowed, and must pass."""

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def cotan_laplacian(V, F):
    n = len(V)
    F = F[igl.doublearea(V, F).ravel() > 0]  # libigl's cot of a zero-area triangle is inf
    C = igl.cotmatrix(V, F).tocoo()
    return sp.csr_matrix((C.data, (C.row, C.col)), shape=(n, n))


def mass_matrix(V, F):
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    m = np.zeros(len(V))
    m[: len(M)] = M
    return sp.diags(m)


def angle_defect(V, F, boundary):
    n = len(V)
    total = np.bincount(F.ravel(), igl.internal_angles(V, F).ravel(), minlength=n)
    d = 2 * np.pi - total
    on_b = np.zeros(n, bool)
    b = np.asarray(igl.is_border_vertex(F), bool)  # sized by F.max()+1
    on_b[: len(b)] = b
    if boundary == "pi":
        d[on_b] += -np.pi
    elif boundary == "zero":
        d[on_b] = 0
    d[total == 0] = 0
    return d


def eigenbasis(V, F, k):
    K = -cotan_laplacian(V, F)
    M = mass_matrix(V, F)
    if k >= len(V) - 1:
        import scipy.linalg as sla

        lam, U = sla.eigh(K.toarray(), M.toarray())
        return lam[:k], U[:, :k]
    lam, U = spla.eigsh(K.tocsc(), k=k, M=M.tocsc(), sigma=-1e-6, which="LM")
    return lam, U


def implicit_step(V, F, lam):
    M = mass_matrix(V, F)
    return spla.spsolve((M - lam * cotan_laplacian(V, F)).tocsc(), M @ V)


def heat_geodesic(V, F, source, m):
    K = -igl.cotmatrix(V, F)
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
    t = m * igl.avg_edge_length(V, F) ** 2
    delta = np.zeros(len(V))
    delta[source] = 1.0
    u = spla.splu((M + t * K).tocsc()).solve(delta)
    G = igl.grad(V, F)
    g = (G @ u).reshape(3, -1)
    X = -g / np.linalg.norm(g, axis=0)
    area = np.tile(0.5 * igl.doublearea(V, F).ravel(), 3)
    b = G.T @ (area * X.ravel())
    phi = np.zeros(len(V))
    phi[1:] = spla.splu(K[1:, 1:].tocsc()).solve(b[1:])  # vertex 0 pinned
    return phi - phi[source]


def biharmonic_displacement(V, F, handles, handle_displacement):
    return V + igl.harmonic(V, F, handles, handle_displacement, 2)


def _solve_fixed(Q, known_rows, known, b=None):
    n = Q.shape[0]
    free = np.setdiff1d(np.arange(n), known_rows)
    Q = sp.csc_matrix(Q)
    x = np.zeros((n, known.shape[1]))
    x[known_rows] = known
    rhs = -(Q[free][:, known_rows] @ known) + (0 if b is None else b[free])
    x[free] = spla.splu(Q[free][:, free].tocsc()).solve(np.asarray(rhs))
    return x


def arap_step(V, F, U, handles, targets):
    n = len(V)
    C = sp.csr_matrix(igl.cotmatrix(V, F))
    W = (C - sp.diags(C.diagonal())).tocsr()  # the spoke weights w_ij, off the diagonal
    deg = np.asarray(W.sum(axis=1)).ravel()
    X = U.copy()
    X[handles] = targets
    # S_i[a, c] = Σ_j w_ij (p_i − p_j)_a (x_i − x_j)_c, as sparse products
    S = np.zeros((n, 3, 3))
    for a in range(3):
        p = V[:, a]
        for c in range(3):
            x = X[:, c]
            S[:, a, c] = deg * p * x - p * (W @ x) - x * (W @ p) + W @ (p * x)
    # libigl takes the rows S_i[a, :] at a·n + i, and returns (3, 3n), block i being R_i
    stacked = np.ascontiguousarray(S.transpose(1, 0, 2).reshape(3 * n, 3))
    R = igl.fit_rotations(stacked, False).reshape(3, n, 3).transpose(1, 0, 2)
    b = np.zeros((n, 3))  # b_i = Σ_j (w_ij/2)(R_i + R_j)(p_i − p_j)
    for a in range(3):
        for c in range(3):
            r, p = R[:, a, c], V[:, c]
            b[:, a] += 0.5 * (r * (deg * p - W @ p) + p * (W @ r) - W @ (r * p))
    return _solve_fixed(-C, handles, targets, b)


def _graph_stiffness(F, n):
    A = sp.csr_matrix(igl.adjacency_matrix(F), shape=(n, n), dtype=float)
    return sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A


def tutte_map(V, F, loop, weights):
    at = igl.map_vertices_to_circle(np.asfortranarray(V), loop.astype(np.int32))
    if weights == "cotan":
        return igl.harmonic(V, F, loop, at, 1)
    return _solve_fixed(_graph_stiffness(F, len(V)), loop, at)


def lscm(V, F, pins, pin_uv):
    uv, _ = igl.lscm(V, F, pins, pin_uv)
    return uv
