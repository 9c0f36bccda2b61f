"""Wrong: E_D + A, the area term with the wrong sign."""

import operator_helpers as oh


def lscm(V, F, pins, pin_uv):
    n = len(V)
    return oh.pinned_uv(oh.lscm_matrix(oh.cot_stiffness(V, F), F, n, -1.0), n, pins, pin_uv)
