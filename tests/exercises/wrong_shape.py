"""Mistake: the mean curvature normal returned flattened, shape (3n,) (``ravel``), and the
barycentric areas as (n, 3) (each vertex's area repeated)."""

import numpy as np


def _areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))


def barycentric_areas(V, F):
    return np.repeat(_areas(V, F)[:, None], 3, axis=1)


def mean_curvature_normal(V, F):
    return np.zeros((len(V), 3)).ravel()
