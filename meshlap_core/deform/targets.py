"""Where the handles go: a rigid motion of the handle vertices (rotated about their centroid,
then moved), as ``meshlap deform --rotate ax,ay,az,deg --move dx,dy,dz`` describes it.

Rotation by Rodrigues' formula: about the unit axis ``a`` by the angle ``θ``,
``R = I + sin θ [a]× + (1 − cos θ) [a]×²``; a handle vertex ``p`` goes to
``R (p − c) + c + t``, ``c`` the handles' centroid (the mean of their rest positions).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import MeshError
from ..types import FloatArray, IntArray, real_array


def _finite_vector(value: Any, size: int, name: str, what: str) -> FloatArray:
    """``value`` as a finite float vector of ``size`` entries (errors name ``name``)."""
    raw = real_array(value, name, what)
    try:
        arr = np.array(raw, dtype=np.float64).ravel()
    except (TypeError, ValueError, OverflowError) as exc:
        raise MeshError(f"{what} are not numbers ({exc})", name) from None
    if arr.shape != (size,) or np.ndim(raw) > 1:
        raise MeshError(f"expected {size} numbers, got shape {np.shape(raw)}", name)
    if not np.isfinite(arr).all():
        raise MeshError(f"{what} must be finite, got {arr.tolist()}", name)
    return arr


def rotation_matrix(axis: Any, degrees: float) -> FloatArray:
    """The ``(3,3)`` rotation about ``axis`` (any non-zero length) by ``degrees``
    (counter-clockwise seen from the tip of the axis: right-handed).

    Examples
    --------
    >>> R = rotation_matrix([0, 0, 1], 90)
    >>> np.round(R @ [1.0, 0.0, 0.0], 12).tolist()
    [0.0, 1.0, 0.0]
    """
    a = _finite_vector(axis, 3, "rotate", "rotation axis coordinates")
    length = float(np.linalg.norm(a))
    if not length > 0:
        raise MeshError("the rotation axis is the zero vector", "rotate")
    theta = np.deg2rad(_finite_vector(degrees, 1, "rotate", "rotation angle")[0])
    x, y, z = a / length
    cross = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(theta) * cross + (1.0 - np.cos(theta)) * (cross @ cross)


def rigid_targets(
    V: FloatArray,
    handles: IntArray,
    rotation: FloatArray | None = None,
    move: Any = None,
) -> FloatArray:
    """The handles' target positions: rotated about their centroid, then moved.

    Parameters
    ----------
    V : (n,3) float
        Rest positions.
    handles : (h,) int
        Checked handle vertices (:func:`~meshlap_core.deform.constraints.check_vertices`).
    rotation : (3,3) float, optional
        A rotation matrix (:func:`rotation_matrix`); none by default.
    move : (3,) float, optional
        The translation; none by default.

    Returns
    -------
    targets : (h,3) float
    """
    P = np.asarray(V, dtype=np.float64)[handles]
    c = P.mean(axis=0)
    R = np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)
    t = np.zeros(3) if move is None else _finite_vector(move, 3, "move", "move coordinates")
    return (P - c) @ R.T + c + t
