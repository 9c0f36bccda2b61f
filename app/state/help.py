"""The Help and window section's spec: the keys, polyscope's own panels, the UI scale and
saved sessions. No settings of its own (the UI scale is the session's
top-level ``ui_scale``)."""

from __future__ import annotations

from ..panel_spec import PanelSpec

SPEC = PanelSpec(
    name="help",
    title="Help and window (H)",
    summary="the keys, polyscope's own panels, the UI scale and saved sessions",
    panel="HelpPanel",
    view=False,
    unsaved={
        "UI scale": "the session keeps it as its own ui_scale (the window's, not a panel's)",
        "polyscope's own panels": "a look at polyscope's structure panels, not part of a view",
        "session file": "the file save session / load session act on (a session is that file)",
        "save session": "an action: writes the session file",
        "load session": "an action: reads a session file",
    },
)
"""The Help and window section (drawn on every frame)."""
