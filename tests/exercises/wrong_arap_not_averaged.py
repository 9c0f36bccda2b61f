"""Wrong: b_i = Σ_j w_ij R_i (p_i − p_j), the rotation of vertex i alone on each edge."""

import numpy as np
import operator_helpers as oh


def arap_step(V, F, U, handles, targets):
    K = oh.cot_stiffness(V, F)
    i, j, w = oh.spokes(K)
    X = U.copy()
    X[handles] = targets
    S = np.zeros((len(V), 3, 3))
    np.add.at(S, i, w[:, None, None] * np.einsum("ka,kb->kab", V[i] - V[j], X[i] - X[j]))
    R = oh.closest_rotations(S)
    b = np.zeros((len(V), 3))
    np.add.at(b, i, w[:, None] * np.einsum("kab,kb->ka", R[i], V[i] - V[j]))
    return oh.solve_known(K, handles, targets, b)
