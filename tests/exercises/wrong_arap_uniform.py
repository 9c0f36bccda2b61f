"""Wrong: uniform weights (1 per edge) in the covariances and the global step, not the
cotangent ones."""

import numpy as np
import operator_helpers as oh


def arap_step(V, F, U, handles, targets):
    K = oh.graph_stiffness(F, len(V))
    i, j, _ = oh.spokes(K)  # every weight 1
    X = U.copy()
    X[handles] = targets
    S = np.zeros((len(V), 3, 3))
    np.add.at(S, i, np.einsum("ka,kb->kab", V[i] - V[j], X[i] - X[j]))
    R = oh.closest_rotations(S)
    b = np.zeros((len(V), 3))
    np.add.at(b, i, 0.5 * np.einsum("kab,kb->ka", R[i] + R[j], V[i] - V[j]))
    return oh.solve_known(K, handles, targets, b)
