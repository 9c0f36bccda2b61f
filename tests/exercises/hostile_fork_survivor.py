"""Hostile: a task forks through ctypes (libc's ``fork``, which no Python audit sees), the
child leaves the process group (``setsid``), names itself ``meshlap-orphan`` and waits to
outlive the check. Expected: the task is refused (C calls through ctypes), and no process named
``meshlap-orphan`` is left once the check is over."""

import ctypes
import time

import numpy as np


def uniform_laplacian(V, F):
    libc = ctypes.CDLL(None)
    if libc.fork() == 0:
        libc.setsid()
        libc.prctl(15, b"meshlap-orphan", 0, 0, 0)  # PR_SET_NAME
        while True:
            time.sleep(1)
    return np.zeros((len(V), len(V)))


def barycentric_areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))
