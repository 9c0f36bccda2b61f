"""A group of vertices moved rigidly by the mouse: polyscope's transformation gizmo, or a drag
in the screen plane (any panel that moves points: handles, pins).

The panels keep moves in mesh coordinates; polyscope shows display coordinates
(:class:`~.state.display.Display`: ``x_d = R (x − c) s``). A move ``(Rm, t)`` of a group whose
rest centroid is ``p`` (mesh) shows as the gizmo transform ``[R Rm Rᵀ | R (p + t − c) s]``, and
a gizmo transform reads back as that move (:func:`gizmo_of`, :func:`move_of_gizmo`). A drag in
the screen plane follows the mouse on the plane through the pressed point facing the camera
(:func:`screen_plane_point`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import polyscope as ps


def display_frame(display: Any) -> tuple[np.ndarray, float, np.ndarray]:
    """``(R (3,3), s, c (3,))`` of a :class:`~.state.display.Display`."""
    return np.asarray(display.rotation, float), float(display.scale), np.asarray(display.centre)


def gizmo_of(display: Any, centroid: np.ndarray, R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The gizmo's 4×4 transform (display coordinates) showing the move ``(R (3,3), t (3,))``
    of a group whose rest centroid is ``centroid`` (mesh coordinates): its rotation, placed at
    the moved centroid."""
    Rd, s, c = display_frame(display)
    T = np.eye(4)
    T[:3, :3] = Rd @ np.asarray(R, float) @ Rd.T
    T[:3, 3] = Rd @ ((np.asarray(centroid) + np.asarray(t) - c) * s)
    return T


def move_of_gizmo(
    display: Any, centroid: np.ndarray, T: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """The move ``(R, t)`` (mesh coordinates) a gizmo transform ``T (4,4)`` shows (its linear
    part made the nearest rotation: float32 rounds; ``None`` for a reflection)."""
    Rd, s, c = display_frame(display)
    T = np.asarray(T, float)
    U, _, Vt = np.linalg.svd(T[:3, :3])
    Rg = U @ Vt
    if np.linalg.det(Rg) < 0:
        return None
    return Rd.T @ Rg @ Rd, Rd.T @ T[:3, 3] / s + c - np.asarray(centroid)


def screen_plane_point(xy: tuple[float, float], anchor: np.ndarray) -> np.ndarray | None:
    """Where the mouse at window pixel ``xy`` points on the plane through ``anchor`` (display
    coordinates) facing the camera (``None``: the ray runs along the plane)."""
    cam = ps.get_view_camera_parameters()
    eye = np.asarray(cam.get_position(), float)
    look = np.asarray(cam.get_look_dir(), float)
    ray = np.asarray(ps.screen_coords_to_world_ray(xy), float)
    denom = float(ray @ look)
    if not np.all(np.isfinite(ray)) or abs(denom) < 1e-12:
        return None
    return eye + float((np.asarray(anchor) - eye) @ look) / denom * ray


def view_axis() -> np.ndarray:
    """The camera's looking direction (display coordinates)."""
    return np.asarray(ps.get_view_camera_parameters().get_look_dir(), float)


class Gizmo:
    """One transformation gizmo (translate and rotate, no scaling) a panel shows and reads:
    :meth:`place` puts it, :meth:`moved` says whether the user moved it since."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._g: Any = None
        self.placed: np.ndarray | None = None  # the transform it was last placed at or read
        self.key: Any = None  # what it shows (the caller's)

    def place(self, T: np.ndarray, key: Any) -> None:
        if self._g is None:
            # a name of its own per gizmo: one outlives a panel that was not shut down
            self._g = ps.add_transformation_gizmo(f"{self.name} {id(self):x}")
            self._g.set_allow_scaling(False)
        self._g.set_transform(np.asarray(T, float))
        self._g.set_enabled(True)
        self.placed, self.key = np.asarray(T, float), key

    def moved(self) -> np.ndarray | None:
        """Its transform when the user moved it since it was placed or last read, else None."""
        if self._g is None or self.placed is None:
            return None
        T = np.asarray(self._g.get_transform(), float)
        if np.allclose(T, self.placed, atol=1e-6):
            return None
        self.placed = T
        return T

    def transform(self) -> np.ndarray | None:
        return None if self._g is None else np.asarray(self._g.get_transform(), float)

    def set_transform(self, T: np.ndarray) -> None:
        """Move it as the user's mouse would (tests)."""
        if self._g is not None:
            self._g.set_transform(np.asarray(T, float))

    def remove(self) -> None:
        if self._g is not None:
            self._g.remove()
        self._g, self.placed, self.key = None, None, None

    @property
    def shown(self) -> bool:
        return self._g is not None
