"""Wrong: the local step's rotations without the reflection fix (R = B Aᵀ even where it is a
reflection, det R = −1)."""

import numpy as np
import operator_helpers as oh


def arap_step(V, F, U, handles, targets):
    K = oh.cot_stiffness(V, F)
    i, j, w = oh.spokes(K)
    X = U.copy()
    X[handles] = targets
    S = np.zeros((len(V), 3, 3))
    np.add.at(S, i, w[:, None, None] * np.einsum("ka,kb->kab", V[i] - V[j], X[i] - X[j]))
    A, _, Bt = np.linalg.svd(S)
    R = Bt.transpose(0, 2, 1) @ A.transpose(0, 2, 1)  # no check of det R
    b = np.zeros((len(V), 3))
    np.add.at(b, i, 0.5 * w[:, None] * np.einsum("kab,kb->ka", R[i] + R[j], V[i] - V[j]))
    return oh.solve_known(K, handles, targets, b)
