"""Flatten a surface: maps of a disk to the plane and what they distort.

A map to the plane is a pair of (nearly) harmonic functions; the conformal one is the lowest
eigenvector of a pencil, the same machinery as the spectral basis. Sign convention as
everywhere: ``C`` the cotangent stiffness (negative semidefinite), ``K = −C``.

Build once, map many: ``Flattener(V, F)`` opens the mesh into a disk and keeps its operators;
``.map(method, boundary)`` gives a :class:`UVMap` (``.uv``, ``.distortion()``, ``.summary()``);
``.arap()`` an :class:`ARAP` object stepped one iteration at a time. :func:`flatten` is the
one-shot version. Long calls take ``progress(fraction, message)`` and ``cancel`` (an event
or a callable) like the rest of the core, and raise
:class:`~meshlap_core.errors.Cancelled` between steps.

Orientation: the outer loop runs with the interior on its left, so every map keeps the
faces' orientation (positive signed areas in the plane); a face with a negative one is
*flipped*.

Modules
-------
``disk``
    Disk topology first: a disk as it is, holes left free, handles cut (libigl's
    ``cut_to_disk``), spheres slit, a user's seam (:func:`make_disk`, :class:`Disk`).
``cut``
    Cutting along edges (vertex splitting), the genus cut, the slit, seams.
``boundary``
    The outer loop on the unit circle or the square ``[−1, 1]²`` by arc length.
``fixed_boundary``
    Tutte's map (uniform weights) and the harmonic map (cotangent weights).
``conformal``
    The conformal energy ``L_C = diag(K, K) − Q_A`` and LSCM (two pinned vertices).
``spectral_conformal``
    The spectral conformal map (Mullen et al. 2008): a generalized eigenproblem on the
    boundary, solved by :func:`~meshlap_core.linalg.eigsolve.pencil_eigenpairs`.
``schur``
    The boundary's Schur complement of ``K`` (its Dirichlet-to-Neumann map) and the harmonic
    extension inside.
``arap``
    ARAP's local/global iterations (Liu et al. 2008).
``jacobian``
    Per-face isometric frames, Jacobians, singular values in closed form, closest rotations.
``distortion``
    Angle distortion ``σ₁/σ₂``, area distortion ``log σ₁σ₂``, flips, the clicked face's ellipse.
``flattener``
    :class:`Flattener`, :class:`UVMap`, :func:`flatten`, the distortion table.
"""

from .arap import ARAP
from .boundary import boundary_positions
from .disk import Disk, make_disk
from .distortion import Distortion, FaceEllipse, measure_distortion
from .flattener import (
    Flattener,
    UVMap,
    check_options,
    distortion_table,
    flatten,
    unit_square_uv,
)

__all__ = [
    "ARAP",
    "Disk",
    "Distortion",
    "FaceEllipse",
    "Flattener",
    "UVMap",
    "boundary_positions",
    "check_options",
    "distortion_table",
    "flatten",
    "make_disk",
    "measure_distortion",
    "unit_square_uv",
]
