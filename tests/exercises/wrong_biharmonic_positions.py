"""Wrong: solves Δ²x = 0 for the positions (handles at V + d), not for the displacement."""

import operator_helpers as oh
import scipy.sparse as sp


def biharmonic_displacement(V, F, handles, handle_displacement):
    K = oh.cot_stiffness(V, F)
    Q = K @ sp.diags(1.0 / oh.voronoi_areas(V, F)) @ K
    return oh.solve_known(Q, handles, V[handles] + handle_displacement)
