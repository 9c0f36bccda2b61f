"""Viewer state as plain objects, tested headless (no polyscope import anywhere in this package).

One module per concern: :mod:`.names` (``PANELS``, ``FIELDS``, ``FIELD_LABELS``: the single
definition the CLI imports), :mod:`.mesh` (``MeshState``, the mesh list), :mod:`.curvature`
(``CurvatureState``, ``robust_range``), :mod:`.onering` (``OneRingState``), :mod:`.spectral`,
:mod:`.smoothing` and :mod:`.surface`. The classes are re-exported here lazily, so importing the
names for the CLI's argument parser does not import numpy, scipy or libigl.
"""

from __future__ import annotations

import importlib
from typing import Any

from .names import FIELD_LABELS, FIELDS, PANELS

_LAZY = {
    "MeshState": "mesh",
    "list_meshes": "mesh",
    "default_mesh_path": "mesh",
    "ASSETS_DIR": "mesh",
    "CurvatureState": "curvature",
    "robust_range": "curvature",
    "OneRingState": "onering",
    "SpectralState": "spectral",
    "SmoothingState": "smoothing",
    "METHODS": "smoothing",
    "SurfaceState": "surface",
}

__all__ = ["FIELDS", "FIELD_LABELS", "PANELS", *_LAZY]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{module}", __name__), name)
