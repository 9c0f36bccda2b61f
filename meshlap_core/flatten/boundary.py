"""Where a fixed-boundary map puts the outer boundary loop: the unit circle or the unit square.

Both place the loop's vertices by arc length (the share of the loop's length walked from its
first vertex), in the loop's order, which follows the face orientation, so that the interior
lands on the left and the map keeps the faces' orientation:

* ``"circle"``: the unit circle around the origin, ``(cos 2πt, sin 2πt)`` for the arc-length
  share ``t`` (libigl's ``map_vertices_to_circle`` places them the same way);
* ``"square"``: the square ``[−1, 1]²``. The four vertices nearest to the quarter points of the
  loop's length become its corners (counter-clockwise from ``(−1, −1)``), and each side's
  vertices are spread along it by arc length, so the square's corners are vertices and every
  side is straight.

A convex boundary is what Tutte's theorem needs (Tutte 1963; Floater 2003): with the circle,
every three boundary vertices are in general position and the Tutte map is one-to-one; on the
square, a face with its three corners on one side is flattened to a segment (zero area).
"""

from __future__ import annotations

import numpy as np

from ..errors import MeshError
from ..options import FLATTEN_BOUNDARIES, check_choice
from ..types import FloatArray, IntArray

_CORNERS = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]])


def arc_shares(V: FloatArray, loop: IntArray) -> FloatArray:
    """The share of the loop's length from its first vertex to each vertex, ``(b,)`` in
    ``[0, 1)``; equal shares when the loop has zero length."""
    seg = np.linalg.norm(V[np.roll(loop, -1)] - V[loop], axis=1)
    total = float(seg.sum())
    if not total > 0:
        return np.arange(len(loop)) / max(len(loop), 1)
    return np.concatenate([[0.0], np.cumsum(seg[:-1])]) / total


def circle_positions(V: FloatArray, loop: IntArray) -> FloatArray:
    """The loop's vertices on the unit circle by arc length, ``(b,2)``."""
    angle = 2.0 * np.pi * arc_shares(V, loop)
    return np.stack([np.cos(angle), np.sin(angle)], axis=1)


def square_positions(V: FloatArray, loop: IntArray) -> FloatArray:
    """The loop's vertices on the square ``[−1, 1]²``, four of them on its corners, ``(b,2)``."""
    b = len(loop)
    t = arc_shares(V, loop)
    # (the first corner is the loop's first vertex, whose share is 0)
    corner = np.array([int(np.argmin(np.abs(t - q))) for q in (0.0, 0.25, 0.5, 0.75)])
    if len(np.unique(corner)) < 4:
        raise MeshError(
            f"the outer boundary has {b} vertices; a square boundary needs four distinct "
            "corner vertices",
            "boundary",
        )
    out = np.empty((b, 2))
    ends = np.append(corner, b)
    for side in range(4):
        i0, i1 = ends[side], ends[side + 1]
        t0 = t[i0]
        t1 = t[i1] if i1 < b else 1.0
        s = (t[i0:i1] - t0) / (t1 - t0)
        out[i0:i1] = (1 - s)[:, None] * _CORNERS[side] + s[:, None] * _CORNERS[side + 1]
    return out


def boundary_positions(V: FloatArray, loop: IntArray, shape: str) -> FloatArray:
    """The loop's vertices on the ``shape`` (``"circle"`` or ``"square"``), ``(b,2)``.

    Raises
    ------
    MeshError
        An unknown shape, ``"free"`` (no positions), or a loop of fewer than three vertices
        (whose positions span no area).
    """
    check_choice(shape, FLATTEN_BOUNDARIES, "boundary")
    if shape == "free":
        raise MeshError("a free boundary has no prescribed positions", "boundary")
    if len(loop) < 3:
        raise MeshError(
            f"the outer boundary has only {len(loop)} vertices; a fixed boundary needs at "
            "least three",
            "boundary",
        )
    return circle_positions(V, loop) if shape == "circle" else square_positions(V, loop)
