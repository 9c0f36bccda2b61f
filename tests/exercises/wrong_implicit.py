"""Mistakes of the implicit step: the mass matrix missing, (I − λC) x′ = x (implicit_step)."""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def implicit_step(V, F, lam):
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        h = 0.5 * np.einsum("ij,ij->i", u, w) / np.linalg.norm(np.cross(u, w), axis=1)
        rows += [b, o, b, o]
        cols += [o, b, b, o]
        vals += [h, h, -h, -h]
    r, c_, v = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    C = sp.coo_matrix((v, (r, c_)), shape=(n, n)).tocsc()
    return spla.spsolve(sp.identity(n, format="csc") - lam * C, V)
