"""Drag the mesh: Laplacian coordinates, k-harmonic displacement and as-rigid-as-possible.

Move a few vertices (the *handles*), hold a region (the *fixed* vertices), and let the rest
follow. Every method is an object built once per handle set (its linear system factorized
once), then one cheap call per drag: :meth:`Deformer.update` with the handles' targets.

Sign convention: ``C`` is the cotangent stiffness (``C_ij = ½(cot α + cot β)``, negative
semidefinite), ``K = −C``, ``M`` the lumped Voronoi mass, ``Δ = M⁻¹C``.

Modules
-------
``constraints``
    Handle and fixed sets checked; components holding neither stay at rest.
``regions``
    Seeds grown into geodesic discs (exact MMP on the disc's patch); the default fixed region.
``targets``
    The handles rotated about their centroid, then moved.
``system``
    ``Q_ff x_f = b_f − Q_fk x_k``: factorized once, solved per drag.
``harmonic``
    ``Δᵏd = 0`` for the displacement, k = 1, 2, 3 (libigl's ``harmonic``).
``laplacian_coordinates``
    Sorkine et al. 2004, soft or hard constraints.
``rotations``
    The closest rotations to 3×3 covariances, vectorized SVD with the reflection fix.
``arap_energy``, ``arap``
    Sorkine & Alexa 2007: the energy, and the local/global iterations.
``rigidity``
    Each vertex's deviation from a rotation of its one-ring.
``methods``
    :func:`make_deformer` by name, and the one-shot :func:`deform_mesh`.
"""

from .arap import ArapDeformer
from .arap_energy import ArapEnergy
from .base import Deformer
from .constraints import Constraints, check_targets, check_vertices, make_constraints
from .harmonic import HarmonicDeformer, k_harmonic_operator
from .laplacian_coordinates import LaplacianCoordinates
from .methods import deform_mesh, make_deformer
from .regions import HandleRegions, edge_graph, farthest_region, grow_handles
from .rigidity import rotation_error
from .rotations import fit_rotations, fit_rotations_igl
from .system import PinnedSystem, SystemStats
from .targets import rigid_targets, rotation_matrix

__all__ = [
    "ArapDeformer",
    "ArapEnergy",
    "Constraints",
    "Deformer",
    "HandleRegions",
    "HarmonicDeformer",
    "LaplacianCoordinates",
    "PinnedSystem",
    "SystemStats",
    "check_targets",
    "check_vertices",
    "deform_mesh",
    "edge_graph",
    "farthest_region",
    "fit_rotations",
    "fit_rotations_igl",
    "grow_handles",
    "k_harmonic_operator",
    "make_constraints",
    "make_deformer",
    "rigid_targets",
    "rotation_error",
    "rotation_matrix",
]
