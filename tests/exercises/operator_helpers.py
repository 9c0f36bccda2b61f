"""Helper module of the wrong deformation and flattening files (not a submission: it defines no
task function): the operators they share, right, so that each file's one mistake is its own."""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def half_edges(F):
    """(3m, 2): every face's half-edges a -> b, the face on their left."""
    return np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])


def cot_stiffness(V, F):
    """K = −C (cotangent weights, positive semidefinite), CSR."""
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):
        o, i, j = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[i] - V[o], V[j] - V[o]
        h = 0.5 * np.einsum("ij,ij->i", u, w) / np.linalg.norm(np.cross(u, w), axis=1)
        rows += [i, j, i, j]
        cols += [j, i, i, j]
        vals += [-h, -h, h, h]
    return sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )


def graph_stiffness(F, n):
    """D − A (weight 1 per edge)."""
    e = np.unique(np.sort(half_edges(F), axis=1), axis=0)
    A = sp.csr_matrix((np.ones(2 * len(e)), (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                      shape=(n, n))  # fmt: skip
    return (sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A).tocsr()


def voronoi_areas(V, F):
    """Mixed Voronoi areas (Meyer et al. 2003)."""
    P = V[F]
    area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    dots = np.stack([np.einsum("ij,ij->i", P[:, (c + 1) % 3] - P[:, c], P[:, (c + 2) % 3] - P[:, c])
                     for c in range(3)], axis=1)  # fmt: skip
    cot = dots / (2 * area[:, None])
    obtuse = dots < 0
    out = np.zeros(len(V))
    for c in range(3):
        j, k = (c + 1) % 3, (c + 2) % 3
        lj = np.sum((P[:, j] - P[:, c]) ** 2, axis=1)
        lk = np.sum((P[:, k] - P[:, c]) ** 2, axis=1)
        vor = (lj * cot[:, k] + lk * cot[:, j]) / 8
        a = np.where(obtuse.any(axis=1), np.where(obtuse[:, c], area / 2, area / 4), vor)
        out += np.bincount(F[:, c], a, minlength=len(V))
    return out


def solve_known(Q, rows, known, b=None):
    """Q_ff x_f = b_f − Q_fk known, x_k = known."""
    n = Q.shape[0]
    rows = np.asarray(rows)
    free = np.setdiff1d(np.arange(n), rows)
    Q = sp.csr_matrix(Q)
    x = np.zeros((n, known.shape[1]))
    x[rows] = known
    rhs = -(Q[free][:, rows] @ known) + (0.0 if b is None else b[free])
    x[free] = spla.splu(sp.csc_matrix(Q[free][:, free])).solve(np.asarray(rhs))
    return x


def closest_rotations(S, reflection_fix=True):
    """R_i = B Aᵀ for S_i = A Σ Bᵀ, (n,3,3); with the fix, det R_i = +1."""
    A, _, Bt = np.linalg.svd(S)
    B = Bt.transpose(0, 2, 1).copy()
    if reflection_fix:
        B[np.linalg.det(B @ A.transpose(0, 2, 1)) < 0, :, 2] *= -1.0
    return B @ A.transpose(0, 2, 1)


def spokes(K):
    """(i, j, w): every directed edge once, w_ij = −K_ij."""
    W = K.tocoo()
    off = W.row != W.col
    return W.row[off], W.col[off], -W.data[off]


def circle_by_arc_length(V, loop):
    seg = np.linalg.norm(V[np.roll(loop, -1)] - V[loop], axis=1)
    theta = 2 * np.pi * np.concatenate([[0.0], np.cumsum(seg[:-1])]) / seg.sum()
    return np.stack([np.cos(theta), np.sin(theta)], axis=1)


def lscm_matrix(K, F, n, area_sign=1.0):
    """diag(K, K) − area_sign · Q_A."""
    he = half_edges(F)
    outer = ~np.isin(he[:, 1] * n + he[:, 0], he[:, 0] * n + he[:, 1])
    a, b = he[outer, 0], he[outer, 1]
    h = np.full(len(a), 0.5)
    rows, cols = np.r_[a, n + b, b, n + a], np.r_[n + b, a, n + a, b]
    QA = sp.coo_matrix((np.r_[h, h, -h, -h], (rows, cols)), shape=(2 * n, 2 * n))
    return (sp.block_diag([K, K]) - area_sign * QA).tocsr()


def pinned_uv(L, n, pins, pin_uv):
    rows = [pins[0], pins[1], n + pins[0], n + pins[1]]
    known = np.array([[pin_uv[0, 0]], [pin_uv[1, 0]], [pin_uv[0, 1]], [pin_uv[1, 1]]])
    x = solve_known(L, rows, known)[:, 0]
    return np.stack([x[:n], x[n:]], axis=1)
