"""Viewer state as plain objects, tested headless (no polyscope import anywhere in this package).

One module per concern: :mod:`.app` (``AppState``, the one owner of every state object and
setting), :mod:`.watch` (``Watch``, the one invalidation rule), :mod:`.display`,
:mod:`.mesh` (``MeshState``, the mesh list),
:mod:`.curvature` (``CurvatureState``, ``robust_range``), :mod:`.settings` (the typed settings
schema), and one module per registered panel (named as the panel in :mod:`meshlap_app.registry`:
:mod:`.onering`, :mod:`.spectral`, :mod:`.smoothing`, :mod:`.surfaces`, ...) declaring its spec
(:class:`meshlap_app.panel_spec.PanelSpec`: its settings, from which its section of a saved
session, :mod:`.session`, comes; its checks; its animation, :mod:`.animation`) and its state
slice when it has one. The shared classes are re-exported here
lazily, so importing the names for the CLI's argument parser does not import numpy, scipy or
libigl.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "ASSETS_DIR",
    "AppState",
    "CurvatureState",
    "MeshState",
    "default_mesh_path",
    "list_meshes",
    "robust_range",
]


def __getattr__(name: str) -> Any:
    """The shared state classes, imported on first use (a panel's own state class is imported
    from its module, ``meshlap_app.state.<panel>``)."""
    if name == "AppState":
        from . import app as module
    elif name in ("CurvatureState", "robust_range"):
        from . import curvature as module
    elif name in ("MeshState", "list_meshes", "default_mesh_path", "ASSETS_DIR"):
        from . import mesh as module
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(module, name)
