"""Heat method without the final shift: φ pinned at vertex 0 is returned, not φ − φ[source]."""

import igl
import numpy as np
import scipy.sparse.linalg as spla


def heat_geodesic(V, F, source, m):
    K = -igl.cotmatrix(V, F)
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
    delta = np.zeros(len(V))
    delta[source] = 1.0
    u = spla.spsolve((M + m * igl.avg_edge_length(V, F) ** 2 * K).tocsc(), delta)
    G = igl.grad(V, F)
    g = (G @ u).reshape(3, -1)
    X = -g / np.linalg.norm(g, axis=0)
    b = G.T @ (np.tile(0.5 * igl.doublearea(V, F).ravel(), 3) * X.ravel())
    phi = np.zeros(len(V))
    phi[1:] = spla.spsolve(K[1:, 1:].tocsc(), b[1:])
    return phi  # missing: − phi[source]
