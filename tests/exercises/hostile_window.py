"""Hostile: the student shows their mesh with polyscope at import time (a window in an
unattended checker). Expected: every task ``import_error``, diagnosis ``opens_window``."""

import numpy as np
import polyscope as ps


def uniform_laplacian(V, F):
    ps.init()
    ps.register_surface_mesh("mine", V, F)
    ps.show()
    return np.zeros((len(V), len(V)))
