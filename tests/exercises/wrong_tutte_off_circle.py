"""Wrong: the boundary on a circle as long as the loop (radius L/2π, to keep the lengths),
not on the unit circle."""

import numpy as np
import operator_helpers as oh


def tutte_map(V, F, loop, weights):
    K = oh.graph_stiffness(F, len(V)) if weights == "uniform" else oh.cot_stiffness(V, F)
    length = np.linalg.norm(V[np.roll(loop, -1)] - V[loop], axis=1).sum()
    return oh.solve_known(K, loop, length / (2 * np.pi) * oh.circle_by_arc_length(V, loop))
