"""Helper module of ``right_helper_module.py`` (not a submission: it defines no task function):
corner angles from ``arctan2``, edges as integer keys, accumulation with ``np.add.at``."""

import numpy as np
import scipy.sparse as sp


def corner_angles(V, F):
    """theta[f, k]: the angle at corner k of face f (arctan2 of |cross| and dot)."""
    out = np.zeros(F.shape)
    for k in range(3):
        u = V[F[:, (k + 1) % 3]] - V[F[:, k]]
        w = V[F[:, (k + 2) % 3]] - V[F[:, k]]
        out[:, k] = np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), (u * w).sum(axis=1))
    return out


def face_areas(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def vertex_thirds(V, F):
    out = np.zeros(len(V))
    np.add.at(out, F.ravel(), np.repeat(face_areas(V, F) / 3, 3))
    return out


def edge_keys(F, n):
    """Every undirected edge once, as i * n + j with i < j."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    return np.unique(e.min(axis=1) * n + e.max(axis=1))


def weights_to_laplacian(i, j, w, n):
    """Symmetric weights w on edges (i, j), the diagonal minus the row sums."""
    W = sp.coo_matrix((np.concatenate([w, w]), (np.concatenate([i, j]), np.concatenate([j, i]))),
                      shape=(n, n)).tocsr()  # fmt: skip
    return W - sp.diags(np.asarray(W.sum(axis=1)).ravel())


def half_cotangents(V, F):
    """½ cot of each corner's angle; 0 in a triangle of zero area (its angles are 0, 0, π)."""
    theta = corner_angles(V, F)
    area = face_areas(V, F)[:, None]
    s = np.sin(theta)
    return np.where(area > 0, 0.5 * np.cos(theta) / np.where(s > 0, s, 1.0), 0.0)
