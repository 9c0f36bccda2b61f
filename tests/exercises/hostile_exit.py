"""Hostile (or careless): a task calls ``sys.exit()``. Expected: reported as such (ERROR,
diagnosis ``calls_exit``), not as a crash in native code; the next task (right) passes."""

import sys

import numpy as np


def uniform_laplacian(V, F):
    sys.exit(0)


def barycentric_areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))
