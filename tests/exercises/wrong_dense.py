"""Mistake: dense numpy matrices throughout (n×n), with a hand-made generalized eigensolver
(M^(-1/2) K M^(-1/2), then back): right on small meshes, out of memory on the 20,480-vertex one."""

import numpy as np


def _uniform_dense(V, F):  # a dense (n,n) L: fine for a step, not timed as a task
    n = len(V)
    A = np.zeros((n, n))
    for a, b in ((0, 1), (1, 2), (2, 0)):
        A[F[:, a], F[:, b]] = 1.0
        A[F[:, b], F[:, a]] = 1.0
    deg = A.sum(axis=1)
    A /= np.where(deg > 0, deg, 1.0)[:, None]
    A[np.diag_indices(n)] -= deg > 0
    return A


def cotan_laplacian(V, F):
    n = len(V)
    C = np.zeros((n, n))
    for k in range(3):
        o, i, j = F[:, k], F[:, (k + 1) % 3], F[:, (k + 2) % 3]
        e1, e2 = V[i] - V[o], V[j] - V[o]
        cross = np.sqrt(((np.cross(e1, e2)) ** 2).sum(axis=1))
        cot = np.divide((e1 * e2).sum(axis=1), cross, out=np.zeros(len(F)), where=cross > 0)
        np.add.at(C, (i, j), cot / 2)
        np.add.at(C, (j, i), cot / 2)
    C -= np.diag(C.sum(axis=1))
    return C


def _voronoi(V, F):
    n = len(V)
    out = np.zeros(n)
    P = V[F]  # (m,3,3)
    area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    for k in range(3):
        p, q, r = P[:, k], P[:, (k + 1) % 3], P[:, (k + 2) % 3]
        cos_p = ((q - p) * (r - p)).sum(axis=1)
        cos_q = ((p - q) * (r - q)).sum(axis=1)
        cos_r = ((p - r) * (q - r)).sum(axis=1)
        cot_q = np.divide(cos_q, 2 * area, out=np.zeros(len(F)), where=area > 0)
        cot_r = np.divide(cos_r, 2 * area, out=np.zeros(len(F)), where=area > 0)
        vor = (((p - q) ** 2).sum(axis=1) * cot_r + ((p - r) ** 2).sum(axis=1) * cot_q) / 8
        obtuse_here = cos_p < 0
        obtuse_other = (cos_q < 0) | (cos_r < 0)
        a = np.where(obtuse_here, area / 2, np.where(obtuse_other, area / 4, vor))
        np.add.at(out, F[:, k], a)
    return out


def voronoi_areas(V, F):
    return _voronoi(V, F)


def mass_matrix(V, F):
    return np.diag(_voronoi(V, F))


def mean_curvature_normal(V, F):
    m = _voronoi(V, F)
    Lx = cotan_laplacian(V, F) @ V
    out = np.zeros_like(V)
    out[m > 0] = -0.5 * Lx[m > 0] / m[m > 0, None]
    return out


def eigenbasis(V, F, k):
    K = -cotan_laplacian(V, F)
    s = 1.0 / np.sqrt(_voronoi(V, F))
    lam, W = np.linalg.eigh(s[:, None] * K * s[None, :])
    order = np.argsort(lam)[:k]
    return lam[order], s[:, None] * W[:, order]


def spectral_reconstruction(X, U, M):
    M = np.asarray(M.todense()) if hasattr(M, "todense") else np.asarray(M)
    coeff = np.einsum("ik,ij,jc->kc", U, M, X)
    return U @ coeff


def implicit_step(V, F, lam):
    M = mass_matrix(V, F)
    return np.linalg.solve(M - lam * cotan_laplacian(V, F), M @ V)


def explicit_step(V, F, lam):
    return V + lam * _uniform_dense(V, F) @ V


def heat_geodesic(V, F, source, m):
    """Dense throughout; the singular Poisson system solved by least squares (minimum norm)."""
    n = len(V)
    K = -cotan_laplacian(V, F)
    lengths = {}
    for f in F:
        for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            lengths[(min(a, b), max(a, b))] = np.linalg.norm(V[a] - V[b])
    t = m * np.mean(list(lengths.values())) ** 2
    u = np.linalg.solve(np.diag(_voronoi(V, F)) + t * K, np.eye(n)[source])
    div = np.zeros(n)
    for f in F:
        p = V[f]
        normal = np.cross(p[1] - p[0], p[2] - p[0])
        area = 0.5 * np.linalg.norm(normal)
        normal /= 2 * area
        hats = [np.cross(normal, p[(c + 2) % 3] - p[(c + 1) % 3]) / (2 * area) for c in range(3)]
        g = sum(u[f[c]] * hats[c] for c in range(3))
        x = -g / np.linalg.norm(g)
        for c in range(3):
            div[f[c]] += area * hats[c] @ x
    phi = np.linalg.lstsq(K, div, rcond=None)[0]
    return phi - phi[source]
