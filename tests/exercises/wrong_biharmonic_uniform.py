"""Wrong: the biharmonic operator built from the uniform Laplacian L = D⁻¹A − I (strong form
(L² d)_free = 0), not from the cotangent weights."""

import numpy as np
import operator_helpers as oh
import scipy.sparse as sp


def biharmonic_displacement(V, F, handles, handle_displacement):
    K = oh.graph_stiffness(F, len(V))
    L = -(sp.diags(1.0 / K.diagonal()) @ K)  # D⁻¹A − I
    d = oh.solve_known(L @ L, handles, handle_displacement)
    return V + np.asarray(d)
