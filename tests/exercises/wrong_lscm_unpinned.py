"""Wrong: only the first pin is held (its two coordinates): the conformal energy is then
smallest for the map of every vertex to that pin."""

import numpy as np
import operator_helpers as oh


def lscm(V, F, pins, pin_uv):
    n = len(V)
    L = oh.lscm_matrix(oh.cot_stiffness(V, F), F, n)
    x = oh.solve_known(L, [pins[0], n + pins[0]], np.array([[pin_uv[0, 0]], [pin_uv[0, 1]]]))
    return np.stack([x[:n, 0], x[n:, 0]], axis=1)
