"""Pictures of meshes and fields for notebooks, drawn as the window draws them.

- :func:`show`: a mesh coloured by a field (an array or a curvature field's name), with its
  colour bar, isolines, arrows or principal-direction crosses, or a vertex's one-ring and
  inspector; a :class:`MeshPicture` that a notebook shows inline;
- :func:`show_side_by_side`: two fields (or two meshes) side by side, on one colour range;
- :func:`turntable`: a few frames of a turning camera as a GIF (:class:`Turntable`);
- :func:`open_viewer`: the real window (``meshlap view``) on a mesh, from a notebook cell
  (:class:`ViewerWindow`).

The viewer's headless EGL renderer draws them (the ``meshlap.pictures`` entry point; the
core never imports the viewer); matplotlib draws them where it cannot, and says why.
"""

from __future__ import annotations

from .picture import MeshPicture, show, show_side_by_side
from .turntable_gif import Turntable, turntable
from .window import ViewerWindow, open_viewer

__all__ = [
    "MeshPicture",
    "Turntable",
    "ViewerWindow",
    "open_viewer",
    "show",
    "show_side_by_side",
    "turntable",
]
