"""Discrete curvature of triangle meshes, and how well it converges to the exact curvature.

Modules, each named by what it computes:

- :mod:`.fields`: the per-vertex fields (angle-weighted normals, uniform and cotangent mean
  curvature ``H``, angle-deficit Gaussian curvature ``K``, ``κ₁,₂ = H ± √(H² − K)``, libigl's
  quadric fit); its public functions are re-exported here, so
  ``from meshlap_core.curvature import vertex_normals`` reads as before.
- :mod:`.principal`: :class:`~.principal.PrincipalCurvatures`, the result of every estimator,
  and the small linear algebra they share (tangent frames, 2×2 symmetric eigenpairs).
- :mod:`.estimators`: the principal-curvature estimators side by side
  (:func:`~.estimators.estimate_curvature`: cotan, quadric, Rusinkiewicz, normal cycle, jet).
- :mod:`.jet_fit`: the scale-aware estimator, an osculating jet fitted over a world-radius ball.
- :mod:`.topology`: :class:`~.topology.CurvatureTopology`, what the tensor estimators need from
  the faces alone, built once per mesh.
- :mod:`.refinement`: the one convergence machinery, meshes of a parametric surface under
  refinement with the exact curvature at their vertices, and the one order fit (observed
  orders between consecutive levels, the least-squares order over all of them).
- :mod:`.convergence`: the classical estimators' convergence tables
  (``meshlap surface --convergence``), and :mod:`.study`: every principal-curvature estimator
  against the exact surfaces (``meshlap curvature-study``, the curvature lab's error maps).

Sign convention (``docs/conventions.md``): Laplacians are negative semidefinite, ``Δx = −2Hn``,
so ``H > 0`` on a sphere with outward normals; ``κ₁ ≥ κ₂``.

Only :mod:`.fields` is loaded with the package (the estimators and the studies import the
parametric surfaces, the noise and scipy's trees: import them from their modules).
"""

from __future__ import annotations

from .fields import (
    all_curvature_fields,
    angle_deficit,
    corner_angles,
    curvature_field,
    gaussian_curvature,
    mean_curvature_cotan,
    mean_curvature_uniform,
    principal_curvature_quadric,
    principal_curvatures,
    principal_from_HK,
    vertex_normals,
)

__all__ = [
    "all_curvature_fields",
    "angle_deficit",
    "corner_angles",
    "curvature_field",
    "gaussian_curvature",
    "mean_curvature_cotan",
    "mean_curvature_uniform",
    "principal_curvature_quadric",
    "principal_curvatures",
    "principal_from_HK",
    "vertex_normals",
]
