"""A correct student file whose work is in a helper module beside it (``mesh_helpers.py``,
imported): angles from ``arctan2``, cot as cos/sin, edges as integer keys. The checker copies
the module it imports with it, and it passes."""

import mesh_helpers as mh
import numpy as np
import scipy.sparse as sp


def uniform_laplacian(V, F):
    n = len(V)
    keys = mh.edge_keys(F, n)
    i, j = keys // n, keys % n
    deg = np.bincount(np.concatenate([i, j]), minlength=n).astype(float)
    W = sp.coo_matrix((np.ones(2 * len(i)), (np.concatenate([i, j]), np.concatenate([j, i]))),
                      shape=(n, n)).tocsr()  # fmt: skip
    inv = np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)
    return sp.diags(inv) @ W - sp.diags((deg > 0).astype(float))


def cotan_laplacian(V, F):
    half = mh.half_cotangents(V, F)
    i = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])  # the edge opposite corner 0, 1, 2
    j = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    return mh.weights_to_laplacian(i, j, half.T.ravel(), len(V))


def barycentric_areas(V, F):
    return mh.vertex_thirds(V, F)


def voronoi_areas(V, F):
    theta = mh.corner_angles(V, F)
    area = mh.face_areas(V, F)
    half = mh.half_cotangents(V, F)
    out = np.zeros(len(V))
    obtuse = theta > np.pi / 2
    for k in range(3):
        a, b = (k + 1) % 3, (k + 2) % 3
        lb = ((V[F[:, a]] - V[F[:, k]]) ** 2).sum(axis=1)  # edge k-a, opposite corner b
        la = ((V[F[:, b]] - V[F[:, k]]) ** 2).sum(axis=1)  # edge k-b, opposite corner a
        vor = (lb * half[:, b] + la * half[:, a]) / 4
        share = np.where(obtuse.any(axis=1), np.where(obtuse[:, k], area / 2, area / 4), vor)
        np.add.at(out, F[:, k], share)
    return out


def mass_matrix(V, F):
    return sp.diags(voronoi_areas(V, F)).tocsr()


def explicit_step(V, F, lam):
    return V + lam * (uniform_laplacian(V, F) @ V)
