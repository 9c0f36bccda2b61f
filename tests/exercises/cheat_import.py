"""A file that returns meshlap's own answer: refused before it runs (every task)."""

from meshlap_core.laplacian import cotan_stiffness


def cotan_laplacian(V, F):
    return cotan_stiffness(V, F)


def uniform_laplacian(V, F):
    return cotan_stiffness(V, F)
