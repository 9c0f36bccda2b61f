"""Wrong: Q = C C, the mass matrix left out between the two Laplacians."""

import operator_helpers as oh


def biharmonic_displacement(V, F, handles, handle_displacement):
    K = oh.cot_stiffness(V, F)
    return V + oh.solve_known(K @ K, handles, handle_displacement)
