"""Wrong: the boundary spaced evenly by index, angle 2πk/b, not by arc length."""

import numpy as np
import operator_helpers as oh


def tutte_map(V, F, loop, weights):
    K = oh.graph_stiffness(F, len(V)) if weights == "uniform" else oh.cot_stiffness(V, F)
    theta = 2 * np.pi * np.arange(len(loop)) / len(loop)
    return oh.solve_known(K, loop, np.stack([np.cos(theta), np.sin(theta)], axis=1))
