"""Mistakes in the angle defect: the boundary term missing (every vertex 2π − Σθ whatever the
rule, angle_defect)."""

import numpy as np


def angle_defect(V, F, boundary):
    total = np.zeros(len(V))
    for c in range(3):
        u = V[F[:, (c + 1) % 3]] - V[F[:, c]]
        w = V[F[:, (c + 2) % 3]] - V[F[:, c]]
        cos = np.einsum("ij,ij->i", u, w) / np.linalg.norm(u, axis=1) / np.linalg.norm(w, axis=1)
        total += np.bincount(F[:, c], np.arccos(np.clip(cos, -1, 1)), minlength=len(V))
    d = 2 * np.pi - total
    d[np.bincount(F.ravel(), minlength=len(V)) == 0] = 0.0
    return d
