"""Wrong: the Dirichlet energy alone (no area term) with the two pins."""

import operator_helpers as oh


def lscm(V, F, pins, pin_uv):
    n = len(V)
    return oh.pinned_uv(oh.lscm_matrix(oh.cot_stiffness(V, F), F, n, 0.0), n, pins, pin_uv)
