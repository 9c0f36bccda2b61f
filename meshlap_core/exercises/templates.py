"""The student file ``meshlap exercises init`` writes: the conventions, then one stub per task
(its signature, shapes, the formula to implement and its reference, no solution), each taken
from the task's declaration in :mod:`.tasks`."""

from __future__ import annotations

from collections.abc import Sequence

from .tasks import EXERCISE_TASKS, TASKS

HEADER = '''"""meshlap exercises: implement each function, then run

    meshlap check {filename}

(or ``meshlap check {filename} --task cotan_laplacian`` for one task).

Conventions (the same as the lab's):
- V is an (n,3) float array of positions, F an (m,3) int array of counter-clockwise triangles.
- n = len(V) always: a vertex in no face still has its row (of zeros) and its entry.
- Every Laplacian is NEGATIVE semidefinite: Δx = −2 H n, with H > 0 on a sphere (outward normals).
- Matrices are scipy.sparse (n, n); a dense n×n array fails on the checker's mesh of 20,480
  vertices (3.4 GB).
- A triangle of zero area (collinear corners) adds nothing: its cot weights, normal and areas
  are 0 — never NaN or inf. Thin but non-degenerate triangles count in full.
- Answers are real float64 arrays (not float32, not complex).
- Use numpy and scipy freely (libigl too); meshlap itself is not available to your file (it
  would be the answer). Your file runs alone in a sandbox: no network, no files outside its
  folder, no other processes; what it prints is shown in the report.
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
'''


def template(filename: str = "exercises.py", tasks: Sequence[str] = EXERCISE_TASKS) -> str:
    """The student file's text with a stub for each task in ``tasks``."""
    return HEADER.format(filename=filename) + "".join("\n" + TASKS[t].stub for t in tasks)
