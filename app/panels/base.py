"""The one protocol every panel of the viewer follows."""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from ..viewer import Viewer


class Panel(Protocol):
    """A section of meshlap's window: its widgets and the structures it registers.

    ``draw`` runs every frame while the panel is shown (it reads widgets, calls its state's
    methods and pushes arrays only when something changed); ``on_new_mesh`` forgets what
    belonged to the previous mesh; ``show`` enables this panel's structures when ``panel`` is the
    current panel and disables them otherwise; ``points`` gives the display positions of a
    structure this panel registered (for camera framing), ``None`` for other names.
    """

    def draw(self, viewer: Viewer) -> None: ...

    def on_new_mesh(self, viewer: Viewer) -> None: ...

    def show(self, viewer: Viewer, panel: str) -> None: ...

    def points(self, viewer: Viewer, name: str) -> np.ndarray | None: ...


class NoStructures:
    """Defaults for a panel that registers nothing of its own."""

    def on_new_mesh(self, viewer: Viewer) -> None:
        return None

    def show(self, viewer: Viewer, panel: str) -> None:
        return None

    def points(self, viewer: Viewer, name: str) -> np.ndarray | None:
        return None
