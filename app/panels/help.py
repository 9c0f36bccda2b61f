"""The Help panel: shortcuts, mouse use, polyscope's own panels and the UI scale."""

from __future__ import annotations

from typing import TYPE_CHECKING

import polyscope as ps

from .base import NoStructures

if TYPE_CHECKING:
    from ..viewer import Viewer

SHORTCUTS = (
    ("1-5", "panels: curvature, one-ring, spectral, smoothing, surfaces"),
    ("space", "play / pause smoothing"),
    ("right / left", "smoothing: one step; spectral: k + 1 / k - 1"),
    ("F", "frame what the panel shows"),
    ("R", "reset (smoothing run, or the camera)"),
    ("H", "this help"),
    ("mouse", "left-drag rotate, right-drag pan, wheel zoom; click a vertex for its one-ring"),
    ("drop", "drop a mesh file (or a session .json) on the window to open it"),
)


class HelpPanel(NoStructures):
    """Shortcut list, a toggle for polyscope's own panels, the UI scale, saved sessions."""

    def __init__(self, ui_scale: float = 1.0) -> None:
        self.open: bool | None = None  # H toggles: force the header open / closed once
        self.shown = False
        self.polyscope_panels = False
        self.ui_scale = ui_scale
        from ..session import SessionWidgets

        self.session = SessionWidgets()  # save / load a session (app/session.py)

    def toggle(self) -> None:
        self.shown = not self.shown
        self.open = self.shown

    def draw(self, viewer: Viewer) -> None:
        ui = viewer.ui
        self.shown = ui.header("Help and window (H)", default_open=False, force=self.open)
        self.open = None
        if not self.shown:
            return
        self.session.draw(viewer)  # first: the lecture's prepared view, one click away
        for key, what in SHORTCUTS:
            ui.text(f"{key:>12}  {what}")
        ch, on = ui.checkbox(
            "polyscope's own panels",
            self.polyscope_panels,
            "show polyscope's options and structure list on the left",
        )
        if ch:
            self.polyscope_panels = on
            ps.set_build_default_gui_panels(on)
            viewer.reframe = True
        ch, scale = ui.slider_float(
            "UI scale", self.ui_scale, 0.5, 3.0, "%.2f", "size of text and widgets (projectors)"
        )
        if ch:
            self.set_scale(viewer, scale)

    def set_scale(self, viewer: Viewer, scale: float) -> None:
        """UI scale in [0.5, 3] (MeshError for a non-finite value)."""
        from meshlap_core.errors import MeshError

        if not 0 < scale < float("inf"):
            raise MeshError(f"must be a number between 0.5 and 3, got {scale!r}", "UI scale")
        self.ui_scale = min(max(float(scale), 0.5), 3.0)
        ps.set_ui_scale(self.ui_scale)
        viewer.ui.scale = self.ui_scale
        viewer.reframe = True
