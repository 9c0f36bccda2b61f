"""A correct student file whose work is in a helper module beside it (``mesh_helpers.py``,
imported): the checker copies the helper with it, and it passes."""

import mesh_helpers


def barycentric_areas(V, F):
    return mesh_helpers.vertex_thirds(V, F)
