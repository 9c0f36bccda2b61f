"""The polyscope layer: registers structures, reads widgets, pushes arrays. No mathematics here.

``run`` opens a window (or, with ``screenshot``, renders one frame with the EGL backend and
exits). Paths are resolved before ``polyscope.init()``, which may change the working directory.
"""

from __future__ import annotations

from pathlib import Path

import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.io import atomic_write

from .state import FIELD_LABELS, CurvatureState, MeshState

MESH = "mesh"


def _init(backend: str) -> None:
    if backend == "openGL3_egl" or backend == "openGL_mock":
        ps.set_allow_headless_backends(True)
    try:
        ps.init(backend)
    except RuntimeError as exc:
        if backend == "auto":
            raise MeshError(
                "no display could be opened for the viewer window; render headless with "
                "`meshlap view MESH --screenshot out.png`",
                "view",
            ) from exc
        raise MeshError(f"polyscope could not start its {backend} backend: {exc}", "view") from exc
    ps.set_program_name("meshlap")
    ps.set_up_dir("z_up")
    ps.set_ground_plane_mode("shadow_only")


def push_mesh(mesh: MeshState, curv: CurvatureState) -> None:
    """(Re)register the surface mesh and every curvature field as a colour map."""
    ps.remove_all_structures()
    sm = ps.register_surface_mesh(MESH, mesh.V, mesh.F, smooth_shade=True, edge_width=0.0)
    curv.update(mesh)
    for name, values in curv.fields.items():
        label, signed = FIELD_LABELS[name]
        lo, hi = curv.color_range(name)
        sm.add_scalar_quantity(
            label,
            values,
            defined_on="vertices",
            cmap="coolwarm" if signed else "viridis",
            vminmax=(lo, hi),
            enabled=(name == curv.field_name),
        )


class Viewer:
    """Holds the state objects and draws the panels each frame."""

    def __init__(self, mesh: MeshState, curv: CurvatureState) -> None:
        self.mesh = mesh
        self.curv = curv
        self.path_text = ""

    def callback(self) -> None:
        psim = ps.imgui
        psim.PushItemWidth(260)
        psim.TextUnformatted(
            f"{self.mesh.name}: {self.mesh.info.get('n_vertices', 0)} vertices, "
            f"{self.mesh.info.get('n_faces', 0)} faces"
        )
        _, self.path_text = psim.InputText("mesh path", self.path_text)
        if psim.Button("Open") and self.path_text:
            if self.mesh.load(Path(self.path_text).expanduser()):
                push_mesh(self.mesh, self.curv)
        if self.mesh.error:
            psim.TextColored((1.0, 0.3, 0.3, 1.0), self.mesh.error)
        psim.PopItemWidth()


def run(
    path: str | Path | None = None,
    screenshot: str | Path | None = None,
    field: str = "cotan",
    backend: str | None = None,
) -> int:
    """Open the viewer on ``path`` (the bundled default mesh when ``None``).

    With ``screenshot`` a single frame is rendered headless (EGL) into that PNG and the
    function returns.
    """
    path = Path(path).resolve() if path is not None else None
    shot = Path(screenshot).resolve() if screenshot is not None else None
    if shot is not None and not shot.parent.is_dir():
        raise MeshError(f"output directory {shot.parent} does not exist", shot)
    if field not in FIELD_LABELS:
        raise MeshError(
            f"unknown field {field!r}; choose one of {', '.join(FIELD_LABELS)}", "--field"
        )
    mesh = MeshState()
    if not mesh.load(path):
        raise MeshError(mesh.error.split(": ", 1)[-1], path) if path else MeshError(mesh.error)
    curv = CurvatureState(field_name=field)
    _init(backend or ("openGL3_egl" if shot else "auto"))
    push_mesh(mesh, curv)
    viewer = Viewer(mesh, curv)
    ps.set_user_callback(viewer.callback)
    if shot is not None:
        ps.reset_camera_to_home_view()
        buf = ps.screenshot_to_buffer(transparent_bg=False)
        _write_png(shot, buf)
        ps.remove_all_structures()
        return 0
    ps.show()
    return 0


def _write_png(path: Path, rgba) -> None:
    """Write an RGBA buffer as PNG atomically (matplotlib's encoder, no extra dependency)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg

    with atomic_write(path, mode="wb") as fh:
        mpimg.imsave(fh, rgba, format="png")
