"""An exception two calls deep in one task (only these frames are shown); the next task is
right and must still be checked."""

import numpy as np


def uniform_laplacian(V, F):
    return _degrees(F, len(V))


def _degrees(F, n):
    counts = np.bincount(F.ravel(), minlength=n)
    return np.diag(1.0 / counts[counts.argmin() : 0])[5]  # IndexError


def barycentric_areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))
