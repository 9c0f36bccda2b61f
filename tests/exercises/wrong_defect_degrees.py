"""Mistake: the angle defect in degrees (360° − Σθ), boundary rules right."""

import numpy as np


def angle_defect(V, F, boundary):
    total = np.zeros(len(V))
    for c in range(3):
        u = V[F[:, (c + 1) % 3]] - V[F[:, c]]
        w = V[F[:, (c + 2) % 3]] - V[F[:, c]]
        cos = np.einsum("ij,ij->i", u, w) / np.linalg.norm(u, axis=1) / np.linalg.norm(w, axis=1)
        total += np.bincount(F[:, c], np.arccos(np.clip(cos, -1, 1)), minlength=len(V))
    b = np.zeros(len(V), bool)
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    u, count = np.unique(e, axis=0, return_counts=True)
    b[u[count == 1].ravel()] = True
    d = 360.0 - np.degrees(total)
    if boundary == "pi":
        d[b] = 180.0 - np.degrees(total[b])
    elif boundary == "zero":
        d[b] = 0.0
    d[np.bincount(F.ravel(), minlength=len(V)) == 0] = 0.0
    return d
