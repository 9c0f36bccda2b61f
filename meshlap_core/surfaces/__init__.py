"""Parametric surfaces ``p(u, v)``: exact differential geometry and the bridge to the meshes.

Modules: :mod:`.catalogue` (:class:`ParametricSurface`, the shipped surfaces, :func:`get_surface`),
:mod:`.derivatives` (exact / complex-step / central derivatives), :mod:`.geometry` (fundamental
forms, curvature fields, normal curvature, classification, :func:`point_geometry`),
:mod:`.angles` (a direction's angle in the ``(u, v)`` plane and in the tangent plane),
:mod:`.meshing` (:func:`mesh_surface`), :mod:`.plot` (the ``κₙ(θ)`` figure) and :mod:`.singular`
(singular points: declared poles and ``|p_u × p_v|`` negligible against the surface's area
scale). Everything public is re-exported here. How the discrete estimators converge to the exact
values on these surfaces is measured above this package, in :mod:`meshlap_core.curvature`
(:mod:`~meshlap_core.curvature.convergence` and :mod:`~meshlap_core.curvature.study`).

A :class:`ParametricSurface` is a map ``p`` on a parameter rectangle ``[u0,u1] × [v0,v1]``.
At any ``(u, v)`` this module computes the partial derivatives, the unit normal
``n = (p_u × p_v) / |p_u × p_v|`` (always this orientation), the first fundamental form
``I = [[E, F], [F, G]]``, the second fundamental form ``II = [[e, f], [f, g]]`` with
``e = −p_uu · n, f = −p_uv · n, g = −p_vv · n``, the Gaussian curvature
``K = (eg − f²)/(EG − F²)``, the mean curvature ``H = (eG − 2fF + gE) / (2(EG − F²))``, the
principal curvatures ``κ₁ ≥ κ₂`` and directions, the normal curvature
``κₙ = II(w, w) / I(w, w)`` of a direction given by its angle ``θ`` in the tangent plane (from
the unit ``p_u``) or ``θ_uv`` in the parameter plane (``w = (cos θ_uv, sin θ_uv)``) and the
point classification.
It also triangulates the parameter rectangle (:func:`mesh_surface`).

Sign conventions (one convention for the whole project). The normal is
``n = p_u × p_v / |…|``, outward on every shipped closed surface, and ``II`` is measured so that
``κₙ > 0`` where the surface bends **away** from ``n``: ``e = −p_uu · n = p_u · n_u`` (do Carmo's
``II`` negated). The unit sphere has ``κ₁ = κ₂ = H = +1`` here, the same sign as the discrete
core's ``Δx = −2 H n`` (negative semidefinite Laplacian) with outward normals from
counter-clockwise faces, so the convergence studies compare ``H`` directly; ``K`` does not
depend on the sign. ``κ₁ ≥ κ₂`` always.

do Carmo's sign (the course's, where a student checks a hand calculation) is one argument away:
``signs="do-carmo"`` (:func:`point_geometry`, :func:`surface_curvature_fields`,
:func:`normal_curvature`, :func:`plot_normal_curvature`; ``meshlap surface --signs do-carmo``)
takes ``e = p_uu · n`` with the same ``n``: ``e, f, g``, the shape operator, ``H`` and ``κₙ``
change sign, ``κ₁, κ₂`` become ``−κ₂, −κ₁`` (still ``κ₁ ≥ κ₂``, so the principal directions
swap roles), and ``K``, ``n`` and the classification stay. On the helicoid ``f = −1/√(1+u²)``
and at its origin ``κₙ(θ) = −sin 2θ``, largest at ``θ = 3π/4`` (``docs/conventions.md``).

Derivatives. A surface may carry its exact derivatives; otherwise (and in the tests, to check
them) they are computed numerically: first derivatives by the complex step
``p_u ≈ Im p(u + ih, v) / h`` (exact to rounding, needs ``p`` written with numpy functions that
accept complex input and are analytic: no ``abs``, ``maximum``, ``real``), second derivatives by
a 6th-order central difference of the complex-step first derivatives. A ``p`` that does not
return complex values for complex input falls back to 6th-order central differences.

References
----------
M. do Carmo, *Differential Geometry of Curves and Surfaces*, 1976, ch. 3.
Squire & Trapp, "Using complex variables to estimate derivatives of real functions", SIAM
Review 40, 1998 (the complex step).
"""

from .angles import (
    PARAMETER_ANGLE_REFERENCE,
    TANGENT_ANGLE_REFERENCE,
    parameter_angle,
    tangent_angle,
    tangent_components,
)
from .catalogue import (
    EDGES,
    SURFACES,
    DerivativeMap,
    ParametricSurface,
    SurfaceMap,
    catenoid,
    check_uv,
    cylinder,
    ellipsoid,
    ellipsoid_curvature,
    get_surface,
    helicoid,
    monkey_saddle,
    saddle,
    sphere,
    torus,
)
from .derivatives import Derivatives, surface_derivatives
from .geometry import (
    CLASSIFICATIONS,
    CurvatureFields,
    PointGeometry,
    classify,
    normal_curvature,
    normal_curvature_curve,
    normal_curvature_from_forms,
    point_geometry,
    signs_factor,
    signs_note,
    surface_curvature_fields,
)
from .meshing import (
    MAX_CELLS,
    MAX_MESH_BYTES,
    MESH_BYTES_PER_CELL,
    STUDY_BYTES_PER_CELL,
    SurfaceMesh,
    check_mesh_res,
    estimate_mesh_bytes,
    mesh_surface,
)
from .plot import normal_curvature_figure, plot_normal_curvature
from .singular import SINGULAR_REL, is_singular, surface_scale

__all__ = [
    "CLASSIFICATIONS",
    "EDGES",
    "MAX_CELLS",
    "MAX_MESH_BYTES",
    "MESH_BYTES_PER_CELL",
    "PARAMETER_ANGLE_REFERENCE",
    "SINGULAR_REL",
    "STUDY_BYTES_PER_CELL",
    "SURFACES",
    "TANGENT_ANGLE_REFERENCE",
    "CurvatureFields",
    "DerivativeMap",
    "Derivatives",
    "ParametricSurface",
    "PointGeometry",
    "SurfaceMap",
    "SurfaceMesh",
    "catenoid",
    "check_mesh_res",
    "check_uv",
    "classify",
    "cylinder",
    "ellipsoid",
    "ellipsoid_curvature",
    "estimate_mesh_bytes",
    "get_surface",
    "helicoid",
    "is_singular",
    "mesh_surface",
    "monkey_saddle",
    "normal_curvature",
    "normal_curvature_curve",
    "normal_curvature_figure",
    "normal_curvature_from_forms",
    "parameter_angle",
    "plot_normal_curvature",
    "point_geometry",
    "saddle",
    "signs_factor",
    "signs_note",
    "sphere",
    "surface_curvature_fields",
    "surface_derivatives",
    "surface_scale",
    "tangent_angle",
    "tangent_components",
    "torus",
]
