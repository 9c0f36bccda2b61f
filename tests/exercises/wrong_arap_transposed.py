"""Wrong: R_i = A Bᵀ (the transpose: it takes current edges back to rest ones)."""

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
    A[np.linalg.det(A @ Bt) < 0, :, 2] *= -1.0  # the reflection fix, on the wrong product
    R = A @ Bt
    b = np.zeros((len(V), 3))
    np.add.at(b, i, 0.5 * w[:, None] * np.einsum("kab,kb->ka", R[i] + R[j], V[i] - V[j]))
    return oh.solve_known(K, handles, targets, b)
