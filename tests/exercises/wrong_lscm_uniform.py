"""Wrong: uniform weights (D − A) in the Dirichlet energy of the conformal energy."""

import operator_helpers as oh


def lscm(V, F, pins, pin_uv):
    n = len(V)
    return oh.pinned_uv(oh.lscm_matrix(oh.graph_stiffness(F, n), F, n), n, pins, pin_uv)
