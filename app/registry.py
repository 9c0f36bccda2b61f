"""The registry of the viewer's panels: the one place that lists them.

Each line names a panel. Its code lives in ``app/panels/<name>.py`` (a class named ``PANEL``
there, following :class:`meshlap_app.panels.base.Panel`) and its polyscope-free state, when it
has one, in ``app/state/<name>.py``. The viewer, the session, the animator, the recorder, the
export and the help all loop over this tuple and never name a panel.

Adding a panel: write ``app/panels/<name>.py`` (and ``app/state/<name>.py``), its tests, and
one line here. ``view=True`` puts it in the *view* combo and on a number key (in this order);
``view=False`` is a section drawn on every frame (the mesh, export and help sections).

This module imports nothing heavy: ``meshlap view --help`` reads the view names from it.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType


@dataclass(frozen=True)
class Entry:
    """One registered panel: its ``name`` (module, session section and ``--panel`` value) and
    whether it is a ``view`` of the combo or an always-drawn section."""

    name: str
    view: bool = True

    def panel_module(self) -> ModuleType:
        """``meshlap_app.panels.<name>`` (imports polyscope)."""
        return importlib.import_module(f"meshlap_app.panels.{self.name}")

    def state_module(self) -> ModuleType | None:
        """``meshlap_app.state.<name>`` (no polyscope), or ``None`` when the panel has none."""
        try:
            return importlib.import_module(f"meshlap_app.state.{self.name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"meshlap_app.state.{self.name}":
                raise
            return None


REGISTRY: tuple[Entry, ...] = (
    Entry("mesh_info", view=False),
    Entry("curvature"),
    Entry("onering"),
    Entry("spectral"),
    Entry("smoothing"),
    Entry("surfaces"),
    Entry("check"),
    Entry("diffusion"),
    Entry("curvature_lab"),
    Entry("export", view=False),
    Entry("help", view=False),
)

VIEWS: tuple[str, ...] = tuple(e.name for e in REGISTRY if e.view)
"""The views of the *view* combo, in its order (keys 1, 2, ...); the first is the default."""
