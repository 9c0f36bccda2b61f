"""meshlap core: headless discrete differential geometry of triangle meshes.

Pure numpy / scipy / libigl; this package never imports polyscope (the viewer is the separate
``meshlap_app`` package). The public API below is what scripts and notebooks use; every name is
importable from ``meshlap_core`` directly and is loaded on first use, so ``import meshlap_core``
stays cheap. On a file, start with ``mesh = load_mesh("bunny.obj")`` and use ``mesh.V, mesh.F``;
here a generated unit sphere (``tests/project/test_doc_examples.py`` runs this example):

>>> from meshlap_core import Smoother, SpectralBasis, curvature_field, icosphere
>>> V, F = icosphere(2)
>>> H = curvature_field(V, F, "cotan", area="voronoi")  # Δx = −2Hn: H ≈ 1 on the unit sphere
>>> round(float(H.mean()), 2)
1.0
>>> basis = SpectralBasis.compute(V, F, 50, cache=False)  # −C u = λ M u, UᵀMU = I
>>> basis.reconstruct(20).shape  # U₂₀ U₂₀ᵀ M X
(162, 3)
>>> smoother = Smoother(V, F, method="implicit", lam=0.5)
>>> smoother.step().shape
(162, 3)

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
    "principal_curvature_quadric": "curvature",
    "estimate_curvature": "curvature.estimators",
    "PrincipalCurvatures": "curvature.principal",
    "jet_curvatures": "curvature.jet_fit",
    # spectral
    "SpectralBasis": "spectral",
    # smoothing
    "Smoother": "smoothing",
    "smooth": "smoothing",
    "add_noise": "noise",
    "rmse": "metrics",
    # heat, geodesic distance, spectral filters (meshlap_core.diffusion)
    "HeatDiffusion": "diffusion",
    "heat_spectral": "diffusion",
    "HeatGeodesic": "diffusion",
    "exact_distance": "diffusion",
    "SpectralFilter": "diffusion",
    "transfer_function": ("diffusion", "transfer"),
    "heat_kernel_signature": "diffusion",
    "isolines": "diffusion",
    "save_polylines": "diffusion",
    # deformation: handles dragged, the rest following (meshlap_core.deform)
    "make_deformer": "deform",
    "deform_mesh": "deform",
    "HarmonicDeformer": "deform",
    "LaplacianCoordinates": "deform",
    "ArapDeformer": "deform",
    "grow_handles": "deform",
    "rotation_error": "deform",
    # maps to the plane (meshlap_core.flatten; its one-shot is meshlap_core.flatten.flatten)
    "Flattener": "flatten",
    "UVMap": "flatten",
    "make_disk": "flatten",
    "measure_distortion": "flatten",
    # parametric surfaces
    "get_surface": "surfaces",
    "mesh_surface": "surfaces",
    "point_geometry": "surfaces",
    # pictures in notebooks, drawn by the viewer's EGL renderer (matplotlib without it)
    "show": "pictures",
    "show_side_by_side": "pictures",
    "turntable": "pictures",
    "open_viewer": "pictures",
    "MeshPicture": "pictures",
    "Turntable": "pictures",
    "ViewerWindow": "pictures",
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
