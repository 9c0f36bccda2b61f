"""The Export section's spec: a screenshot, or what is on screen written to files in a chosen
folder (the app's ``folder``: recordings and relative session files go there too). No
settings of its own."""

from __future__ import annotations

from ..panel_spec import PanelSpec

SPEC = PanelSpec(
    name="export",
    title="Export",
    summary="the export folder, a screenshot, and what is shown written there (PLY, CSV)",
    panel="ExportPanel",
    view=False,
    unsaved={
        "folder": "where this machine writes files; a session opens on other machines",
        "screenshot": "an action: writes the view as a PNG",
        "export what is shown": "an action: writes the meshes and fields on screen",
    },
)
"""The Export section (drawn on every frame)."""
