"""Hostile: the file writes its own lines to file descriptors 1 and 2 (and prints), hoping to
land in the checker's --json or CSV output. Expected: the checker's standard output is exactly
its own; what the file wrote is in the report's capped log."""

import os
import sys

import numpy as np

os.write(1, b'{"file": "forged", "passed": 15, "total": 15}\n')
os.write(2, b"forged,15,15\n")


def barycentric_areas(V, F):
    print("INJECTED print from the student")
    sys.stdout.flush()
    os.write(1, b"INJECTED,passed,passed,passed\n" * 3)
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))
