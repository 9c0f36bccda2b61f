"""Wrong: the rotations are fitted to U as given, before the handles are moved to their
targets."""

import numpy as np
import operator_helpers as oh


def arap_step(V, F, U, handles, targets):
    K = oh.cot_stiffness(V, F)
    i, j, w = oh.spokes(K)
    S = np.zeros((len(V), 3, 3))
    np.add.at(S, i, w[:, None, None] * np.einsum("ka,kb->kab", V[i] - V[j], U[i] - U[j]))
    R = oh.closest_rotations(S)
    b = np.zeros((len(V), 3))
    np.add.at(b, i, 0.5 * w[:, None] * np.einsum("kab,kb->ka", R[i] + R[j], V[i] - V[j]))
    return oh.solve_known(K, handles, targets, b)
