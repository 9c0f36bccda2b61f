"""Mistake: the cot weight of edge ij taken from the angle at a corner of the edge instead of the
one opposite it (no classic mistake gives that), and a right mean curvature normal built on
this cotan_laplacian: it fails because its dependency does (``failed_dependency``)."""

import numpy as np
import scipy.sparse as sp


def cotan_laplacian(V, F):
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        dot, cross = np.einsum("ij,ij->i", u, w), np.linalg.norm(np.cross(u, w), axis=1)
        h = 0.5 * np.divide(dot, cross, out=np.zeros(len(F)), where=cross > 0)
        rows += [a, b, a, b]  # the mistake: edge (a, b) is not opposite corner a
        cols += [b, a, a, b]
        vals += [h, h, -h, -h]
    r, c_, v = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    return sp.coo_matrix((v, (r, c_)), shape=(n, n)).tocsr()


def _voronoi(V, F):
    P = V[F]
    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    dots = np.stack(
        [np.einsum("ij,ij->i", P[:, (c + 1) % 3] - P[:, c], P[:, (c + 2) % 3] - P[:, c])
         for c in range(3)], axis=1,
    )  # fmt: skip
    cots = np.divide(dots, 2 * A[:, None], out=np.zeros_like(dots), where=A[:, None] > 0)
    out = np.zeros(len(V))
    obtuse = (dots < 0).any(axis=1)
    for c in range(3):
        j, k = (c + 1) % 3, (c + 2) % 3
        lj = np.sum((P[:, j] - P[:, c]) ** 2, axis=1)
        lk = np.sum((P[:, k] - P[:, c]) ** 2, axis=1)
        vor = (lj * cots[:, k] + lk * cots[:, j]) / 8
        a = np.where(obtuse, np.where(dots[:, c] < 0, A / 2, A / 4), vor)
        out += np.bincount(F[:, c], a, minlength=len(V))
    return out


def mean_curvature_normal(V, F):
    a = _voronoi(V, F)
    Cx = cotan_laplacian(V, F) @ V
    return -0.5 * np.divide(Cx, a[:, None], out=np.zeros_like(Cx), where=a[:, None] > 0)
