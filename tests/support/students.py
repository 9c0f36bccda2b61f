"""Student files for the exercises checker: the corpus in ``tests/exercises/`` (data, one file per
diagnosis) and a file written on the fly that is wrong at one chosen vertex only."""

from __future__ import annotations

from pathlib import Path

import numpy as np

STUDENTS = Path(__file__).resolve().parents[1] / "exercises"

ONE_VERTEX_WRONG = '''
import numpy as np


def barycentric_areas(V, F):
    """A third of each face, and a mistake at vertex {target} only."""
    P = V[F]
    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    a = np.bincount(F.ravel(), np.repeat(A / 3.0, 3), minlength=len(V))
    if len(V) > {target}:
        a[{target}] += 2.0 * a.max()
    return a
'''


def facing_vertex() -> int:
    """A vertex of the bundled mesh near the middle of the default view, facing the camera
    (which looks along +z from −z), as in the picking test of ``tests/app/test_viewer.py``."""
    from meshlap_app.state import MeshState

    from meshlap_core.curvature import vertex_normals

    mesh = MeshState()
    mesh.load(None)
    N = vertex_normals(mesh.V, mesh.F)
    return int(np.argmin(N[:, 2] + 0.2 * np.abs(mesh.V[:, 1]) + 0.2 * np.abs(mesh.V[:, 0])))
