"""The Mesh section's spec (``mesh_info``): the mesh on screen, a path field and the bundled,
shared and recent meshes. Its state is the app's own (:class:`~.mesh.MeshState`); it has no
settings of its own (the session keeps the mesh's path)."""

from __future__ import annotations

from ..panel_spec import PanelSpec

SPEC = PanelSpec(
    name="mesh_info",
    title="Mesh",
    summary="the mesh on screen (counts, topology, repairs); open a file by path, from the "
    "list or by dropping it on the window",
    panel="MeshPanel",
    view=False,
    unsaved={
        "path": "the session keeps the mesh it opened (its mesh), not the text typed",
        "Open": "an action: opens the typed path (the session keeps that mesh)",
        "bundled / shared": "an action: opens a listed mesh (the session keeps that mesh)",
    },
)
"""The Mesh section (drawn on every frame)."""
