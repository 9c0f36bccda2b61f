"""meshlap's answer reached through a name built at run time: refused when the call imports it,
while the file's other task (numpy only) is still checked and passes."""

import importlib

import numpy as np


def cotan_laplacian(V, F):
    lap = __import__("meshlap" + "_core.laplacian", fromlist=["x"])
    return lap.cotan_stiffness(V, F)


def barycentric_areas(V, F):
    lap = importlib.import_module("meshlap" + "_core.laplacian")
    return lap.vertex_areas(V, F, "barycentric")


def voronoi_areas(V, F):  # wrong on purpose, but it runs: only meshlap is refused
    return np.zeros(len(V))
