"""Mistake: an explicit step x + λ M⁻¹C x where the implicit step (M − λC) x′ = M x is asked."""

import igl
import numpy as np


def implicit_step(V, F, lam):
    C = igl.cotmatrix(V, F)
    m = np.zeros(len(V))
    d = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    m[: len(d)] = d
    return V + lam * (C @ V) / m[:, None]
