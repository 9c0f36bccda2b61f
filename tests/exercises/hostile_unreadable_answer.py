"""Hostile: answers that are not numbers — an object that raises when turned into an array, a
dict, a generator, nothing (``None``). Expected: each task FAILED or ERROR for this file only
(``not_numbers``, ``no_answer``); a folder run goes on and writes its reports."""

import numpy as np


class Exploding:
    def __array__(self, dtype=None, copy=None):
        raise RuntimeError("boom (while the answer is read)")

    def __reduce__(self):
        raise RuntimeError("boom (while unpickled)")


def uniform_laplacian(V, F):
    return Exploding()


def barycentric_areas(V, F):
    return {"areas": np.zeros(len(V))}


def voronoi_areas(V, F):
    return (x for x in range(len(V)))


def mass_matrix(V, F):
    M = np.diag(np.ones(len(V)))  # computed, and never returned: the answer is None
    del M
