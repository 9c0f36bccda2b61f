"""What the viewer puts in polyscope's scene: structure names, offsets, colours, framing.

Every panel registers its structures under the names defined here and places copies with
:func:`side_offset`; the camera is framed by :func:`frame_scene_left`. Imports polyscope.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
import polyscope as ps

from meshlap_core.io import atomic_write

# ---------------------------------------------------------------- structure names
MESH = "mesh"
MESH_B = "mesh (second estimator)"
RING_CURVE = "one-ring order"
RING_POINTS = "one-ring neighbours"
RING_CENTER = "selected vertex"
SURFACE = "surface"
SURFACE_POINT = "surface point"
RECON = "reconstruction"
EIGEN = "eigenfunction"
SMOOTHED = "smoothed"
SMOOTH_INPUT = "smoothing input"

# ---------------------------------------------------------------- colours (RGBA / RGB)
RED = (1.0, 0.35, 0.35, 1.0)
INPUT_COLOR = (0.85, 0.75, 0.6)
SMOOTHED_COLOR = (0.55, 0.7, 0.9)

# parametric surfaces are written z-up; the viewer is y-up: display them rotated (x, y, z) ->
# (x, z, -y) with a polyscope transform, so the data (and the numbers in the panel) are unchanged
Z_TO_Y = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


def side_offset(V: np.ndarray) -> np.ndarray:
    """Offset of a copy shown beside a mesh: to its right as seen from the default camera."""
    return np.array([-1.15 * float(np.ptp(V[:, 0])) - 1e-9, 0.0, 0.0])


def remove_structure(name: str) -> None:
    """Remove a registered structure of any of the kinds the viewer uses (no-op if absent)."""
    for has, remove in (
        (ps.has_surface_mesh, ps.remove_surface_mesh),
        (ps.has_curve_network, ps.remove_curve_network),
        (ps.has_point_cloud, ps.remove_point_cloud),
    ):
        if has(name):
            remove(name)


def frame_scene_left(
    names: Iterable[str],
    points: Callable[[str], np.ndarray | None],
    fraction: float = 0.6,
) -> None:
    """Look at the enabled surface meshes among ``names`` from the front so they fill the left
    ``fraction`` of the window (the panel sits on the right).

    ``points(name)`` gives a structure's world positions ``(k,3)`` (``None``: unknown).
    """
    pts = []
    for name in names:
        if ps.has_surface_mesh(name) and ps.get_surface_mesh(name).is_enabled():
            P = points(name)
            if P is not None:
                pts.append(P)
    if not pts:
        ps.reset_camera_to_home_view()
        return
    P = np.vstack(pts)
    lo, hi = P.min(axis=0), P.max(axis=0)
    c = 0.5 * (lo + hi)
    w, h = ps.get_window_size()
    fov = np.radians(ps.get_view_camera_parameters().get_fov_vertical_deg())
    tan_v = np.tan(fov / 2.0)
    tan_h = tan_v * w / h
    # y is up and the camera looks along +z from the front (scans face -z): seen from there,
    # screen-right is -x, so aiming at c - shift puts the scene centre left of the window centre
    depth = hi[2] - lo[2]
    d = max((hi[0] - lo[0]) / (2 * fraction * tan_h), (hi[1] - lo[1]) / (2 * 0.85 * tan_v))
    d += 0.5 * depth
    shift = (0.5 - 0.5 * fraction) * 2 * d * tan_h
    eye = np.array([c[0] - shift, c[1] + 0.15 * (hi[1] - lo[1]), lo[2] - d])
    ps.look_at(eye, np.array([c[0] - shift, c[1], c[2]]))


def save_screenshot(path: Path) -> None:
    """Render the window (with meshlap's panel) into the PNG ``path``, atomically."""
    write_png(path, ps.screenshot_to_buffer(transparent_bg=False, include_UI=True))


def write_png(path: Path, rgba: np.ndarray) -> None:
    """Write an RGBA buffer as PNG atomically (matplotlib's encoder, no extra dependency)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg

    with atomic_write(path, mode="wb") as fh:
        mpimg.imsave(fh, rgba, format="png")
