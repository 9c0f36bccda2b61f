"""A 50 GB allocation in one task; the next task is right and must still be checked."""

import numpy as np


def uniform_laplacian(V, F):
    big = np.ones((50 * 1024**3) // 8)  # 50 GB
    return big


def barycentric_areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))
