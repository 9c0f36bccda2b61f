"""The host a panel is given: what it may use of the program that shows it (no polyscope).

The window (:class:`meshlap_app.viewer.Viewer`) and the headless animator are hosts. Panels,
the session code and the recorder type against :class:`Host`, never against the viewer, so
this module sits low in the layers: it imports nothing of the viewer wing above the state
(its types only). What a host and another panel see of a panel is :class:`HostedPanel`; the
full protocol a panel implements is :class:`meshlap_app.panels.base.Panel`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

if TYPE_CHECKING:
    from .state.app import AppState
    from .state.preview import MeshPreview
    from .ui import UI


class HostedPanel(Protocol):
    """What a host, the session code and other panels read of a panel (every
    :class:`~meshlap_app.panels.base.Panel` has it)."""

    name: str
    title: str
    state: Any  # its slice of the AppState (None: it has none)
    shows_curvature: bool
    shortcuts: tuple[tuple[str, str], ...]

    def capture(self, host: Host) -> dict[str, Any]: ...

    def configure(self, host: Host, values: dict[str, Any]) -> None: ...

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None: ...

    def busy(self) -> str: ...

    def export_items(self, host: Host) -> list[Any]: ...


class Host(Protocol):
    """What a panel may use of the program that shows it (the window or the animator)."""

    state: AppState
    ui: UI
    panels: dict[str, HostedPanel]  # every registered panel, in the registry's order

    def open(self, path: Path | None) -> bool:
        """Load the mesh file ``path`` (``None``: the bundled default); on failure the mesh's
        error is set and the mesh on screen stays."""
        ...

    def active(self) -> HostedPanel:
        """The panel of the active view."""
        ...

    def set_panel(self, name: str) -> None:
        """Switch the active view (its structures shown, the others hidden, re-framed)."""
        ...

    def sync_mesh(self) -> None:
        """Register the mesh if it changed (each panel's ``on_new_mesh``), sync every panel
        and show the active view."""
        ...

    def keep_view(self) -> None:
        """Keep the camera as it is now: no pending re-frame, the window size taken as seen."""
        ...

    def refresh(self) -> None:
        """Show the active view's structures and hide the others (after registering some)."""
        ...

    def request_frame(self) -> None:
        """Frame what is shown again at the end of this frame."""
        ...

    def frame(self, strip: float | None = None) -> bool:
        """Frame what is shown now (``strip``: an animation frame, that left fraction of the
        width kept for the colour bar; a kept camera is not moved); False when nothing is
        shown yet (the camera is not moved)."""
        ...

    def flush_frame(self) -> None:
        """Frame now if a re-frame was requested (before a recorded picture)."""
        ...

    def picture(self) -> np.ndarray:
        """The 3D view as it is on screen, left of meshlap's panel, with its colour bars and
        captions: ``(h, w, 3) uint8`` (a screenshot, a recorded frame)."""
        ...

    def set_ui_scale(self, scale: float) -> None:
        """Set the UI scale (text, widgets, the panel's width) everywhere it applies."""
        ...

    def mesh_points(self) -> np.ndarray:
        """Display positions ``(n,3)`` of the mesh's vertices (as uploaded)."""
        ...

    background: bool
    """Long operations run as jobs of ``state.jobs`` (the window); ``False``: right away (the
    animator, headless renders, tests)."""

    def loading(self) -> tuple[str, MeshPreview | None] | None:
        """The mesh file being opened (a job of the Mesh section): its name, and its preview
        once it is parsed (then shown in place of the mesh); ``None`` when none is."""
        ...

    def draw_job(self, *owners: str, reserve: bool = True) -> bool:
        """Draw the progress row (bar and Cancel button) of the running job of each of
        ``owners`` (a panel passes its name); True when one runs. With none running an empty
        row keeps its place (``reserve=False``: where a button of the same height takes it)."""
        ...
