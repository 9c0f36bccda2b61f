"""Pinhole projection of world points to window pixels (pure numpy, no polyscope import).

Used to draw the one-ring's order numbers next to the neighbours and, in tests, to find where a
known vertex is on screen before picking there.
"""

from __future__ import annotations

import numpy as np

from meshlap_core.types import FloatArray


def project_to_screen(
    P: FloatArray, view: FloatArray, fov_vertical_deg: float, width: int, height: int
) -> tuple[FloatArray, np.ndarray]:
    """Window coordinates (pixels, origin top-left) of world points.

    Parameters
    ----------
    P : (k,3) float
        World positions.
    view : (4,4) float
        World-to-camera matrix (camera looks down its −z axis, OpenGL convention).
    fov_vertical_deg : float
    width, height : int
        Window size in pixels.

    Returns
    -------
    xy : (k,2) float
    in_front : (k,) bool
        Points in front of the camera (others have meaningless ``xy``).
    """
    P = np.asarray(P, dtype=np.float64).reshape(-1, 3)
    Ph = np.hstack([P, np.ones((len(P), 1))]) @ np.asarray(view, dtype=np.float64).T
    depth = -Ph[:, 2]
    in_front = depth > 1e-12
    f = 1.0 / np.tan(np.radians(fov_vertical_deg) / 2.0)
    aspect = width / height
    d = np.where(in_front, depth, 1.0)
    x_ndc = f / aspect * Ph[:, 0] / d
    y_ndc = f * Ph[:, 1] / d
    xy = np.stack([(x_ndc + 1.0) * 0.5 * width, (1.0 - y_ndc) * 0.5 * height], axis=1)
    return xy, in_front
