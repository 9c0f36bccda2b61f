"""Hostile: the file stops the clocks of its own process (``time.perf_counter``,
``time.monotonic``, ``time.time`` return a constant), then works far past the time limit.
Expected: the checker's own clock stops it (TIMEOUT at the task's limit); the next task
(right) still passes."""

import time

import numpy as np

_real_sleep = time.sleep
time.perf_counter = time.monotonic = time.time = lambda: 1000.0


def uniform_laplacian(V, F):
    for _ in range(2000):  # 200 s
        _real_sleep(0.1)
    return np.zeros((len(V), len(V)))


def barycentric_areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))
