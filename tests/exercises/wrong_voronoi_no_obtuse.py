"""Mistake: circumcentric Voronoi cells everywhere, without Meyer's rule for obtuse triangles."""

import numpy as np


def voronoi_areas(V, F):
    out = np.zeros(len(V))
    for c in range(3):
        j, k = (c + 1) % 3, (c + 2) % 3
        a, b, o = V[F[:, c]], V[F[:, j]], V[F[:, k]]

        def cot(p, q, r):  # cot of the angle at p in triangle p, q, r
            u, w = q - p, r - p
            return np.einsum("ij,ij->i", u, w) / np.linalg.norm(np.cross(u, w), axis=1)

        lab = np.sum((b - a) ** 2, axis=1)  # opposite corner k
        lao = np.sum((o - a) ** 2, axis=1)  # opposite corner j
        out += np.bincount(F[:, c], (lab * cot(o, a, b) + lao * cot(b, a, o)) / 8, minlength=len(V))
    return out
