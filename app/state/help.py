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
)
"""The Help and window section (drawn on every frame)."""
