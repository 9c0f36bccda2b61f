"""Rigid moves of handle discs, as a session saves them and a user makes them (no polyscope).

A *move* is ``{"rotate": [ax, ay, az, degrees], "move": [dx, dy, dz]}``: the disc rotated about
its centroid (the axis any non-zero vector, right-handed), then moved (mesh units, mesh axes),
as ``meshlap deform --rotate --move`` says it. Here: the checks of the seeds and moves a session
holds (what is wrong, or ``None``), their normal form, and the move of a rotation matrix and a
translation (Rodrigues' formula read back) and back.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from meshlap_core.deform import rotation_matrix
from meshlap_core.types import FloatArray

from .settings import MAX_INT, integer_problem, number_problem, shown

MAX_HANDLES = 64
"""Most handle seeds (and fixed seeds) the panel holds: each is a disc and a gizmo."""
MAX_MOVE = 1e6
"""Largest move coordinate a session may hold (in units of the mesh's bounding-box diagonal
it is checked against the mesh: :func:`.deform.check_mesh`)."""
IDENTITY: dict[str, list[float]] = {"rotate": [0.0, 0.0, 1.0, 0.0], "move": [0.0, 0.0, 0.0]}
"""A handle not moved."""


# ---------------------------------------------------------------- the settings' checks
def check_seeds(x: Any) -> str | None:
    """A list of at most :data:`MAX_HANDLES` vertex indices (the session's mesh bounds them
    further: :func:`.deform.check_mesh`)."""
    if not isinstance(x, list):
        return f"must be a list of vertices, got {shown(x)}"
    if len(x) > MAX_HANDLES:
        return f"holds {len(x)} vertices; at most {MAX_HANDLES}"
    for v in x:
        if integer_problem(v, 0, MAX_INT - 1):
            return f"has {shown(v)}; a seed is a vertex index (an integer >= 0)"
    return None


def distinct(seeds: list[int]) -> list[int]:
    """The seeds without repeats, in their order."""
    return [int(v) for v in dict.fromkeys(seeds)]


def move_problem(m: Any) -> str | None:
    """What is wrong with one move ``{"rotate": [ax, ay, az, deg], "move": [dx, dy, dz]}``."""
    if not (isinstance(m, dict) and set(m) == {"rotate", "move"}):
        form = '{"rotate": [ax, ay, az, deg], "move": [dx, dy, dz]}'
        return f"each move must be {form}, got {shown(m)}"
    rot, mv = m["rotate"], m["move"]
    if not (isinstance(rot, list) and len(rot) == 4 and isinstance(mv, list) and len(mv) == 3):
        return "rotate takes 4 numbers (axis and degrees), move 3"
    for x in (*rot[:3], *mv):
        if number_problem(x, -MAX_MOVE, MAX_MOVE):
            return f"has {shown(x)}; coordinates are finite numbers within ±{MAX_MOVE:g}"
    if number_problem(rot[3], -360.0, 360.0):
        return f"has the angle {shown(rot[3])}; degrees are -360 to 360"
    if rot[3] != 0 and not any(float(a) != 0 for a in rot[:3]):
        return "rotates about the zero axis"
    return None


def check_moves(x: Any) -> str | None:
    """A list of moves (:func:`move_problem`), one per handle seed (:func:`check_section`)."""
    if not isinstance(x, list):
        return f"must be a list of moves, got {shown(x)}"
    if len(x) > MAX_HANDLES:
        return f"holds {len(x)} moves; at most {MAX_HANDLES}"
    for m in x:
        problem = move_problem(m)
        if problem:
            return problem
    return None


def normal_moves(x: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Moves as the state keeps them (floats)."""
    return [
        {"rotate": [float(a) for a in m["rotate"]], "move": [float(a) for a in m["move"]]}
        for m in x
    ]


def identity() -> dict[str, list[float]]:
    return {"rotate": list(IDENTITY["rotate"]), "move": list(IDENTITY["move"])}


def diagonal(V: FloatArray) -> float:
    """The bounding-box diagonal of ``V (n,3)`` (1 for an empty or flat-to-a-point mesh)."""
    if len(V) == 0:
        return 1.0
    V = np.asarray(V, dtype=np.float64)
    d = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    return d if d > 0 and math.isfinite(d) else 1.0


def move_matrix(m: dict[str, Any]) -> tuple[FloatArray, FloatArray]:
    """The rotation ``(3,3)`` and translation ``(3,)`` of one move."""
    ax, ay, az, deg = m["rotate"]
    R = np.eye(3) if deg == 0 else rotation_matrix([ax, ay, az], deg)
    return R, np.asarray(m["move"], dtype=np.float64)


def move_of(R: FloatArray, t: FloatArray) -> dict[str, list[float]]:
    """The move of the rotation ``R (3,3)`` (axis and angle, Rodrigues' formula read back) and
    translation ``t (3,)``."""
    R = np.asarray(R, dtype=np.float64)
    c = min(max((float(np.trace(R)) - 1.0) / 2.0, -1.0), 1.0)
    theta = math.acos(c)
    axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    s = float(np.linalg.norm(axis))
    if theta < 1e-12:
        rot = [0.0, 0.0, 1.0, 0.0]
    elif s > 1e-9:
        a = axis / s
        rot = [float(a[0]), float(a[1]), float(a[2]), math.degrees(theta)]
    else:  # a half turn: the axis from the symmetric part R + I = 2 a a^T
        B = (R + np.eye(3)) / 2.0
        k = int(np.argmax(np.diag(B)))
        a = B[:, k] / math.sqrt(max(B[k, k], 1e-300))
        rot = [float(a[0]), float(a[1]), float(a[2]), 180.0]
    return {"rotate": rot, "move": [float(x) for x in np.asarray(t, dtype=np.float64)]}
