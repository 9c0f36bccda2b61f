"""What the viewer puts in polyscope's scene: structure names, offsets, colours, framing.

Every panel registers its structures under the names defined here and places copies with
:func:`side_offset`; the camera is framed by :func:`frame_scene_left`. Imports polyscope.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps

from meshlap_core.io import atomic_write

# ---------------------------------------------------------------- structure names
PANE_WIDTH = 500
"""polyscope's width of the right-hand pane at UI scale 1 (``set_right_gui_pane_width``; the
viewer narrows it so that the pane never covers more than half the window)."""
PANEL_PX = 520
"""Width of meshlap's panel on the right (pixels at UI scale 1): framing keeps clear of it."""


def scene_fraction(window_width: int, ui_scale: float, cap: float = 0.95) -> float:
    """The fraction of a window ``window_width`` pixels wide left of meshlap's panel at
    ``ui_scale``: where the viewer frames the scene (``cap`` 0.95 leaves a margin) and what
    a recording keeps (``cap`` 1); at least 0.3 on a narrow window."""
    w = max(window_width, 1)
    return min(max((w - PANEL_PX * ui_scale) / w, 0.3), cap)


def scene_width(window_width: int, ui_scale: float) -> int:
    """Pixels of a window ``window_width`` wide left of meshlap's panel at ``ui_scale``, even
    (a video encoder's need): what a recording keeps of each frame, and what an animation of
    a saved view keeps of its window."""
    keep = int(window_width * scene_fraction(window_width, ui_scale, cap=1.0))
    return max(keep // 2 * 2, 2)


MESH = "mesh"
MESH_B = "mesh (second estimator)"
RING_CURVE = "one-ring order"
RING_POINTS = "one-ring neighbours"
RING_CENTER = "selected vertex"
INSPECT_WEIGHTS = "inspector: w_ij"
INSPECT_NEGATIVE = "inspector: negative w_ij"
INSPECT_ARCS = "inspector: corner angles"
INSPECT_CELL = "inspector: area cell"
INSPECT_CELL_EDGE = "inspector: area cell outline"
INSPECT_ARROWS = "inspector: n and Lx"
INSPECTOR = (
    INSPECT_WEIGHTS,
    INSPECT_NEGATIVE,
    INSPECT_ARCS,
    INSPECT_CELL,
    INSPECT_CELL_EDGE,
    INSPECT_ARROWS,
)
SURFACE = "surface"
SURFACE_POINT = "surface point"
NORMAL_SECTION = "normal section"
SECTION_DIRECTION = "normal section direction"
RECON = "reconstruction"
SMOOTHED = "smoothed"
SMOOTH_INPUT = "smoothing input"

# ---------------------------------------------------------------- colours (RGBA / RGB)
RED = (1.0, 0.35, 0.35, 1.0)
COLORBAR_AT = (15.0, 15.0)  # polyscope's on-screen colour bar: top-left, clear of the panel
COLORBAR_STEP_PX = 285.0  # a colour bar's height plus a gap, at UI scale 1


def colorbar_at(slot: int, ui_scale: float = 1.0) -> tuple[float, float]:
    """Where the ``slot``-th on-screen colour bar goes (0: :data:`COLORBAR_AT`, 1 below it,
    ...), spaced for ``ui_scale`` so that two bars never overlap."""
    return COLORBAR_AT[0], COLORBAR_AT[1] + slot * COLORBAR_STEP_PX * float(ui_scale)


COLORBAR_STRIP = 0.17
"""Left fraction of an animation frame kept clear for polyscope's colour bar (``COLORBAR_AT``)."""
COLORBAR_PX = 150.0  # width of the colour bar's box at UI scale 1: the camera frames right of it
INPUT_COLOR = (0.85, 0.75, 0.6)
SMOOTHED_COLOR = (0.55, 0.7, 0.9)
NEGATIVE_COLOR = (0.85, 0.1, 0.85)  # negative cotangent weights: outside the coolwarm map
ARC_COLOR = (1.0, 0.6, 0.0)
CELL_COLOR = (0.35, 0.8, 0.35)
NORMAL_COLOR = (0.1, 0.1, 0.1)
LAPLACIAN_COLOR = (0.0, 0.6, 0.6)

# parametric surfaces are written z-up; the viewer is y-up: display them rotated (x, y, z) ->
# (x, z, -y) with a polyscope transform, so the data (and the numbers in the panel) are unchanged
Z_TO_Y = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


def scalar_for_upload(
    values: np.ndarray, vminmax: tuple[float, float]
) -> tuple[np.ndarray, tuple[float, float], str]:
    """Scalars safe for float32: rescaled by a power of ten when their range is beyond
    ``[1e-30, 1e30]``; returns the values, range and a label suffix such as ``" (x 1e-74)"``."""
    r = max(abs(float(vminmax[0])), abs(float(vminmax[1])))
    if r == 0 or 1e-30 <= r <= 1e30 or not np.isfinite(r):
        return values, vminmax, ""
    e = int(np.floor(np.log10(r)))
    f = 10.0**-e
    return np.asarray(values) * f, (vminmax[0] * f, vminmax[1] * f), f" (x 1e{e})"


def side_offset(
    V: np.ndarray, toward_eye: tuple[float, float, float] = (0.0, 0.15, -1.0)
) -> np.ndarray:
    """Offset of a copy shown beside a mesh ``V (n,3)``: to its right on screen as seen from
    ``toward_eye`` (the mesh's front view, y up), so the mesh keeps the left side whichever
    way the camera looks at it."""
    d = -np.asarray(toward_eye, dtype=np.float64)  # where the camera looks
    right = np.array([-d[2], 0.0, d[0]])  # d x y: the screen's right, in the ground plane
    right /= max(float(np.linalg.norm(right)), 1e-12)
    width = float(np.ptp(np.asarray(V, dtype=np.float64) @ right))
    return right * (1.15 * width + 1e-9)


def front_view(mesh_name: str) -> tuple[float, float, float]:
    """The direction from the mesh named ``mesh_name`` towards the camera: its entry of
    :data:`FRONT_VIEWS`, else :data:`DEFAULT_VIEW`."""
    return FRONT_VIEWS.get(mesh_name, DEFAULT_VIEW)


def picked_vertex(hit: Any, V: np.ndarray, F: np.ndarray) -> int | None:
    """The vertex of ``V (n,3)`` that polyscope's pick result ``hit`` points at: the picked
    vertex, or the nearest corner of a picked face of ``F (m,3)`` (``V`` in the coordinates
    of ``hit.position``); ``None`` for another kind of element."""
    data = hit.structure_data
    kind = data.get("element_type")
    if kind == "vertex":
        return int(data["index"])
    if kind == "face":
        f = F[int(data["index"])]
        return int(f[np.argmin(np.linalg.norm(V[f] - np.asarray(hit.position), axis=1))])
    return None


def remove_structure(name: str) -> None:
    """Remove a registered structure of any of the kinds the viewer uses (no-op if absent)."""
    for has, remove in (
        (ps.has_surface_mesh, ps.remove_surface_mesh),
        (ps.has_curve_network, ps.remove_curve_network),
        (ps.has_point_cloud, ps.remove_point_cloud),
    ):
        if has(name):
            remove(name)


LARGE_MESH_FACES = 1_000_000
"""Above this many faces the ground's shadow is off (:func:`shadow_for`): with Mesa's software
OpenGL the shadow is a second render pass of the whole mesh, about half of each redraw of a
1.4M-face scan (0.5 s of CPU)."""


def shadow_for(n_faces: int, turned_off: bool) -> bool:
    """Turn the ground's shadow off for a mesh of more than :data:`LARGE_MESH_FACES` faces,
    back on for a smaller one when this rule turned it off (``turned_off``); returns whether
    it is now off by this rule (a shadow turned off elsewhere, e.g. an animation's, stays
    off)."""
    if n_faces > LARGE_MESH_FACES:
        ps.set_ground_plane_mode("none")
        return True
    if turned_off:
        ps.set_ground_plane_mode("shadow_only")
    return False


def show_preview(
    points: np.ndarray,
    F: np.ndarray,
    values: np.ndarray,
    vminmax: tuple[float, float],
    label: str,
    ui_scale: float = 1.0,
) -> Any:
    """Register ``points (n,3)``, ``F (m,3)`` as the main mesh :data:`MESH` (replacing it),
    coloured by ``values (n,)`` under ``label`` with its colour bar: the preview of a mesh
    being opened (:mod:`meshlap_app.state.preview`). Returns the structure."""
    remove_structure(MESH)
    sm = ps.register_surface_mesh(MESH, points, F, smooth_shade=True)
    sm.add_scalar_quantity(
        label,
        values,
        defined_on="vertices",
        cmap="coolwarm",
        vminmax=vminmax,
        enabled=True,
        onscreen_colorbar_enabled=True,
        onscreen_colorbar_location=colorbar_at(0, ui_scale),
    )
    sm.set_enabled(True)
    return sm


# the direction from a mesh towards the camera (y up): scans face -z; meshes known to face +z
# get their front; the parametric surfaces (torus, helicoid, ...) are seen obliquely from above
DEFAULT_VIEW = (0.0, 0.15, -1.0)
FRONT_VIEWS: dict[str, tuple[float, float, float]] = {
    "armadillo_igl.obj": (0.0, 0.15, 1.0),
    "nefertiti.obj": (0.0, 0.15, 1.0),  # in display coordinates: z-up, turned (UP_BY_MESH)
}
OBLIQUE_VIEW = (0.55, 0.75, -1.0)


def register_surface(name: str, P: np.ndarray, F: np.ndarray, shown: bool) -> Any:
    """``ps.register_surface_mesh`` (smooth shading) shown or hidden as told: polyscope
    remembers a structure's enabled flag by its name, so a copy removed while hidden (a new
    mesh opened in another view) came back hidden when registered again (the Smoothing view
    stayed empty until re-entered)."""
    return ps.register_surface_mesh(name, P, F, smooth_shade=True, enabled=bool(shown))


def box_of(P: np.ndarray) -> np.ndarray:
    """``[min, max]`` ``(2,3)`` of the points ``P (k,3)`` (``(0,3)`` when there are none): what
    :func:`frame_points` reads of a structure (its bounding box's corners frame the same)."""
    return np.array([P.min(axis=0), P.max(axis=0)]) if len(P) else np.zeros((0, 3))


def frame_points(
    P: np.ndarray,
    toward_eye: tuple[float, float, float] = DEFAULT_VIEW,
    fraction: float = 0.6,
    left: float = 0.0,
) -> None:
    """Point the camera at the points ``P (k,3)`` (display coordinates) from the direction
    ``toward_eye`` so that they fill the window between ``left`` and ``fraction`` of its width
    (meshlap's panel covers the right, the colour bar the left strip), with y up.

    With ``s = fraction − left``, the distance ``d`` fits the bounding box's extent across (``w``)
    and up (``h``) the view: ``d = max(w / (2 s tan(fov_h/2)), h / (2 · 0.85 tan(fov_v/2))) +
    depth/2``, and the target moves right by ``(1 − left − fraction) d tan(fov_h/2)`` so the
    box's centre lands at ``(left + fraction)/2`` of the width.
    """
    P = np.asarray(P, dtype=np.float64)
    if len(P) == 0:
        ps.reset_camera_to_home_view()
        return
    lo, hi = P.min(axis=0), P.max(axis=0)
    c = 0.5 * (lo + hi)
    back = np.asarray(toward_eye, dtype=np.float64)
    back /= np.linalg.norm(back)
    right = np.cross(np.array([0.0, 1.0, 0.0]), back)  # camera x (looking along -back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    corners = np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )
    rel = corners - c
    w = np.ptp(rel @ right)
    h = np.ptp(rel @ up)
    depth = np.ptp(rel @ back)
    width, height = ps.get_window_size()
    fov = np.radians(ps.get_view_camera_parameters().get_fov_vertical_deg())
    tan_v = np.tan(fov / 2.0)
    tan_h = tan_v * width / max(height, 1)
    span = max(fraction - left, 0.05)
    d = max(w / (2 * span * tan_h), h / (2 * 0.85 * tan_v), 1e-12) + 0.5 * depth
    target = c + (1.0 - left - fraction) * d * tan_h * right
    look_at(target + d * back, target)


NEAR_CLIP = 0.005
"""The near plane's distance as a fraction of the distance to what is framed (polyscope's
ratio, applied to the framed target instead of a stale view centre)."""


def look_at(eye: np.ndarray, target: np.ndarray) -> None:
    """Put the camera at ``eye`` looking at ``target`` (display coordinates), with the clip
    planes fitted to that view.

    polyscope places its near and far planes at ``nearClip`` and ``farClip`` times the
    distance from the camera to its view centre ("Center Relative"), and ``look_at`` leaves
    that centre at the old view's distance: a one-ring framed 0.01 from the camera after a
    whole-mesh view 2.5 away got a near plane at 0.0125, through the ring. Here the view
    centre becomes ``target`` (turning the view turns it about what is framed), the near plane
    :data:`NEAR_CLIP` of the distance, and the far plane beyond every structure's bounding box.
    """
    eye, target = np.asarray(eye, dtype=np.float64), np.asarray(target, dtype=np.float64)
    ps.look_at(tuple(eye), tuple(target))
    ps.set_view_center_raw(tuple(target))
    d = max(float(np.linalg.norm(target - eye)), 1e-30)
    lo, hi = (np.asarray(b, dtype=np.float64) for b in ps.get_bounding_box())
    reach = float(np.linalg.norm(0.5 * (lo + hi) - eye) + 0.5 * np.linalg.norm(hi - lo))
    view = json.loads(ps.get_view_as_json())
    if None in view.get("viewMat", [None]):  # no valid view (eye at the target): keep it
        return
    for key in ("windowWidth", "windowHeight"):  # the camera only: never resize the window
        view.pop(key, None)
    view["nearClip"] = NEAR_CLIP
    view["farClip"] = max(20.0, 1.5 * reach / d) if np.isfinite(reach) else 20.0
    ps.set_view_from_json(json.dumps(view))


def frame_scene_left(
    names: Iterable[str],
    points: Callable[[str], np.ndarray | None],
    fraction: float = 0.6,
    toward_eye: tuple[float, float, float] = DEFAULT_VIEW,
    left: float = 0.0,
) -> bool:
    """Frame the enabled structures among ``names`` between ``left`` and ``fraction`` of the
    width (:func:`frame_points`); ``points(name)`` gives a structure's display positions
    ``(k,3)`` (``None``: unknown). False, and the camera untouched, when none is shown yet
    (a view whose structures a job still computes): the caller frames again when they are
    (polyscope's home view, fitted to whatever else is registered, could put the camera
    inside the surface that comes next)."""
    pts = []
    for name in names:
        if ps.has_surface_mesh(name) and ps.get_surface_mesh(name).is_enabled():
            P = points(name)
            if P is not None and len(P):
                pts.append(P)
    if not pts:
        return False
    frame_points(np.vstack(pts), toward_eye, fraction, left)
    return True


def save_screenshot(path: Path) -> None:
    """Render the window (with meshlap's panel) into the PNG ``path``, atomically: the
    headless ``meshlap view --screenshot`` (outside any frame; a window's *screenshot* button
    writes its view instead, :meth:`meshlap_app.viewer.Viewer.picture`)."""
    write_png(path, ps.screenshot_to_buffer(transparent_bg=False, include_UI=True))


def crop_to_scene(buf: np.ndarray, window_width: int, ui_scale: float) -> np.ndarray:
    """The part of a window's picture ``buf (h, w, c)`` left of meshlap's panel, where the
    viewer frames the scene (:func:`scene_width`, an even width): what a screenshot of the
    view and a recorded frame keep. ``buf`` may have more pixels than the window
    (``w != window_width`` on a high-density screen): the same fraction is kept."""
    width = max(int(window_width), 1)
    keep = scene_width(width, ui_scale) * buf.shape[1] // width
    return buf[:, : max(keep // 2 * 2, 2)]


def write_png(path: Path, rgba: np.ndarray) -> None:
    """Write an RGBA buffer as PNG atomically (matplotlib's encoder, no extra dependency)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg

    with atomic_write(path, mode="wb") as fh:
        mpimg.imsave(fh, rgba, format="png")
