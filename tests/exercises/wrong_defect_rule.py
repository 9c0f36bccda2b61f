"""Mistake: the boundary rule "zero" is ignored (treated as "pi"); "pi" and "2pi" are right."""

import igl
import numpy as np


def angle_defect(V, F, boundary):
    n = len(V)
    total = np.bincount(F.ravel(), igl.internal_angles(V, F).ravel(), minlength=n)
    on_b = np.zeros(n, bool)
    b = np.asarray(igl.is_border_vertex(F), bool)
    on_b[: len(b)] = b
    d = 2 * np.pi - total
    if boundary != "2pi":
        d[on_b] = np.pi - total[on_b]
    d[np.bincount(F.ravel(), minlength=n) == 0] = 0.0
    return d
