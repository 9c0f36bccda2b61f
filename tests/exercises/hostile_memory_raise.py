"""Hostile: the file raises its own memory limit to the hard limit, then fills 3 GB. Expected:
the limit cannot be raised (soft = hard), the allocation fails: OUT OF MEMORY; the next task
(right) still passes."""

import resource

import numpy as np


def uniform_laplacian(V, F):
    _soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (hard, hard))
    big = np.ones(3 * 1024**3 // 8)  # 3 GB, every page written
    return big[: len(V)]


def barycentric_areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))
