"""Mistakes in the vertex areas: the barycentric area where the mixed Voronoi one is asked
(voronoi_areas and mass_matrix), and the face area not divided by 3 (barycentric_areas)."""

import numpy as np
import scipy.sparse as sp


def _face_areas(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def barycentric_areas(V, F):
    return np.bincount(F.ravel(), np.repeat(_face_areas(V, F), 3), minlength=len(V))


def voronoi_areas(V, F):
    return np.bincount(F.ravel(), np.repeat(_face_areas(V, F) / 3, 3), minlength=len(V))


def mass_matrix(V, F):
    return sp.diags(voronoi_areas(V, F))
