"""meshlap core: headless discrete differential geometry of triangle meshes.

Pure numpy / scipy / libigl; this package never imports polyscope (the viewer is the separate
``meshlap_app`` package). The public API below is what scripts and notebooks use; every name is
importable from ``meshlap_core`` directly and is loaded on first use, so ``import meshlap_core``
stays cheap::

    from meshlap_core import load_mesh, curvature_field, SpectralBasis, Smoother

    mesh = load_mesh("bunny.obj")
    H = curvature_field(mesh.V, mesh.F, "cotan")
    basis = SpectralBasis(mesh.V, mesh.F, k=50)
    X = basis.reconstruct(20)

Sign convention: every Laplacian is negative semidefinite (``Δx = −2Hn``); eigenvalues shown
to users are the non-negative frequencies of ``−Δ``.
"""

from __future__ import annotations

import importlib
from typing import Any

from ._version import __version__
from .errors import MeshError, MeshWarning

# public name -> module that defines it (relative to this package), or (module, its name there)
_PUBLIC: dict[str, str | tuple[str, str]] = {
    # meshes: reading, writing, checking
    "Mesh": "mesh",
    "MeshReport": "mesh",
    "load_mesh": "io",
    "save_mesh": "io",
    "save_scalars": "io",
    "validate_mesh": "validate",
    "mesh_info": "describe",
    "inspect_vertex": "inspector",
    # generated meshes
    "icosphere": "primitives",
    "torus_mesh": "primitives",  # the triangle mesh; get_surface("torus") is the surface
    "grid": "primitives",
    "cube": "primitives",
    # topology
    "one_ring": "topology",
    "OneRing": "topology",
    "boundary_loops": "topology",
    "EdgeTable": "topology",
    # operators (Δ = M⁻¹C, negative semidefinite)
    "cotan_stiffness": "laplacian",
    "uniform_laplacian": "laplacian",
    "mass_matrix": "laplacian",
    "vertex_areas": "laplacian",
    "laplace_beltrami": "laplacian",
    # curvature
    "curvature_field": "curvature",
    "all_curvature_fields": "curvature",
    "vertex_normals": "curvature",
    # spectral
    "SpectralBasis": "spectral",
    # smoothing
    "Smoother": "smoothing",
    "smooth": "smoothing",
    "add_noise": "noise",
    "rmse": "metrics",
    # parametric surfaces
    "get_surface": "surfaces",
    "mesh_surface": "surfaces",
    "point_geometry": "surfaces",
}

__all__ = ["MeshError", "MeshWarning", "__version__", *_PUBLIC]


def __getattr__(name: str) -> Any:
    where = _PUBLIC.get(name)
    if where is None:
        raise AttributeError(f"module 'meshlap_core' has no attribute {name!r}")
    module, attr = (where, name) if isinstance(where, str) else where
    value = getattr(importlib.import_module(f".{module}", __name__), attr)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
