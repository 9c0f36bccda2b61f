"""``AppState``: every state object and setting of the viewer, in one owner (no polyscope).

The viewer (and the headless animator) hold one :class:`AppState`; panels read and change it
through their host. What belongs to one panel lives in that panel's *slice*
(``slices[name]``, made by its spec's ``state`` factory); what several panels read
lives here: the mesh, its curvature fields, the display transform, the active view, the UI
scale, the export folder and the background jobs (:class:`~meshlap_app.jobs.Jobs`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from meshlap_core.errors import MeshError
from meshlap_core.options import DEFAULT_UP, check_choice

from ..jobs import Jobs
from ..registry import REGISTRY, VIEWS
from .curvature import CurvatureState
from .display import UP_BY_MESH, Display
from .mesh import MeshState

UI_SCALES = (0.5, 3.0)
"""The UI scale's range (text and widgets; projectors use 1.5 to 2)."""


def make_slices() -> dict[str, Any]:
    """A fresh state slice for every registered panel that has one (its spec's ``state``)."""
    return {spec.name: spec.state() for spec in REGISTRY if spec.state is not None}


@dataclass
class AppState:
    """The mesh on screen and everything derived from it or set by the user.

    ``panel`` is the active view (one of :data:`~meshlap_app.registry.VIEWS`); ``folder`` is
    where exports, recordings and relative session files go; ``errors`` maps a section to the
    message shown in red there.
    """

    mesh: MeshState = field(default_factory=MeshState)
    curv: CurvatureState = field(default_factory=CurvatureState)
    display: Display = field(default_factory=Display)
    panel: str = VIEWS[0]
    ui_scale: float = 1.0
    folder: Path = field(default_factory=Path.cwd)
    slices: dict[str, Any] = field(default_factory=make_slices)
    errors: dict[str, str] = field(default_factory=dict)
    jobs: Jobs = field(default_factory=Jobs)  # background jobs, applied on the UI thread
    up_given: dict[str, str] = field(default_factory=dict)  # file name -> --up / session's

    def up_for(self, name: str) -> str:
        """The up axis of the mesh file ``name``: given (``--up``, a session), else its
        entry of :data:`.display.UP_BY_MESH`, else ``"y"`` (the rule of :mod:`.display`)."""
        return self.up_given.get(name) or UP_BY_MESH.get(name, DEFAULT_UP)

    def check_panel(self, name: str, flag: str = "view") -> str:
        """``name`` if it is a view, else a :class:`MeshError` naming the views."""
        return check_choice(name, VIEWS, "panel", flag)

    def set_ui_scale(self, scale: float) -> float:
        """Set the UI scale, clamped to :data:`UI_SCALES`; returns it.

        Raises
        ------
        MeshError
            ``scale`` is not a finite positive number (the previous scale stays).
        """
        lo, hi = UI_SCALES
        if not 0 < float(scale) < float("inf"):
            message = f"must be a number between {lo:g} and {hi:g}, got {scale!r}"
            raise MeshError(message, "UI scale")
        self.ui_scale = min(max(float(scale), lo), hi)
        return self.ui_scale

    def set_folder(self, text: str) -> Path:
        """Use the existing folder ``text`` for exports; returns it resolved.

        Raises
        ------
        MeshError
            The folder does not exist (the previous folder stays).
        """
        folder = Path(text.strip()).expanduser()
        if not folder.is_dir():
            raise MeshError(
                f"{text!r} is not an existing folder; create it first (exports and recordings "
                f"still go to {self.folder})",
                "export folder",
            )
        self.folder = folder.resolve()
        return self.folder

    def in_folder(self, text: str) -> Path:
        """The path ``text`` names: as typed when absolute, else in the export folder."""
        path = Path(text.strip()).expanduser()
        return path if path.is_absolute() else self.folder / path
