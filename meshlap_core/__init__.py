"""meshlap core: headless discrete differential geometry of triangle meshes.

Pure numpy / scipy / libigl; this package never imports polyscope (the viewer lives in ``app``).
Modules are named by what they compute: ``io``, ``validate``, ``topology``, ``laplacian``,
``curvature``, ``spectral``, ``smoothing``, ``noise``, ``metrics``, ``surfaces``,
``primitives``.
"""

from ._version import __version__
from .errors import MeshError, MeshWarning

__all__ = ["MeshError", "MeshWarning", "__version__"]
