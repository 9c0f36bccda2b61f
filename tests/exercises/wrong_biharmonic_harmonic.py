"""Wrong: C d = 0 (harmonic) where Δ²d = 0 (biharmonic) is asked."""

import operator_helpers as oh


def biharmonic_displacement(V, F, handles, handle_displacement):
    return V + oh.solve_known(oh.cot_stiffness(V, F), handles, handle_displacement)
