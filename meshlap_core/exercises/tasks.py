"""The exercise table: every task declared once, here — the student's function and its stub
(the template's text), the meshes it is checked on, the reference, the classic mistakes (each
written as the wrong answer it produces, for :mod:`.diagnose`), and the tasks it builds on.

Everything else derives from this table: ``meshlap check --task`` and its choices, the template
(:mod:`.templates`), the Check panel's task list, the folder reports' columns, the speed line
(every task is timed on the ``large`` mesh), the docs' list. Adding a task is one
:class:`Task` entry in :func:`_table` (docs/exercises.md, "Adding a task").

The references and mistakes are in :mod:`.task_formulas` and :mod:`.geodesic_task`; the
conventions are the project's (Laplacians negative semidefinite, ``K = −C``, ``UᵀMU = I``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from . import deform_tasks as dt
from . import flatten_tasks as ft
from . import geodesic_task as geo
from . import task_formulas as tf
from .meshes import Case

Output = Any
Args = tuple[Any, ...]
OPERATOR_CASES = (
    "one_triangle",
    "tetrahedron",
    "obtuse_fan",
    "boundary_fan",
    "cube_corner",
    "non_delaunay_pair",
    "unreferenced",
    "degenerate",
    "slivers",
    "scaled",
    "large",
    "huge",
)
"""Cases of every per-vertex task (all but the eigenproblem's and the heat method's)."""
CLOSED_CASES = ("tetrahedron", "small_sphere", "scaled", "large")
"""The eigenproblem's meshes: closed, up to 2562 vertices (a dense solver for the k lowest
pairs is a fair way there; the speed line says what it costs)."""
STEP_CASES = (
    "tetrahedron", "obtuse_fan", "boundary_fan", "cube_corner", "degenerate", "slivers",
    "scaled", "large", "huge",
)  # fmt: skip
SPEED_CASE = "large"
"""Every task is timed on this mesh (its cases all include it), unless it names another
(:attr:`Task.speed_case`: the maps of a disk are timed on ``large_disk``)."""


@dataclass(frozen=True)
class Mistake:
    """A classic mistake: its diagnosis key (see :data:`.diagnose.DIAGNOSES`) and the wrong
    answer it gives, ``wrong(case, args)`` (``None`` where it makes no difference).

    ``fits(got, expected, case)``, when given, recognises a mistake whose wrong answer is a
    family (the distance up to an additive constant): ``wrong`` is then one member of it."""

    key: str
    wrong: Callable[[Case, Args], Output]
    fits: Callable[[Any, Output, Case], bool] | None = None


@dataclass(frozen=True)
class Task:
    """One exercise.

    Attributes
    ----------
    name : str
        The student's function name, and ``--task`` name.
    kind : {"matrix", "array", "ring", "eigen"}
        How outputs are compared (:mod:`.compare`) and carried back from the worker.
    power : int
        Units of the answer, length^power (scale of the tolerance).
    cases : tuple of str
        Battery cases it is checked on (they include :attr:`speed_case`).
    calls : callable
        ``calls(case) -> [(label, args)]``: the student is called ``f(*args)``.
    reference : callable
        ``reference(case, args) -> expected``.
    stub : str
        The function as the template gives it: signature, docstring (formula, shapes,
        reference), ``raise NotImplementedError``.
    mistakes : tuple of Mistake
        Task-specific mistakes, tried before the generic ones.
    generic : bool
        Also try the generic mistakes (sign, factor 2, factor ½, any constant factor).
    uses : tuple of str
        Tasks whose answer this one is built from (a failing one is named when this fails).
    not_judged : callable or None
        ``not_judged(case, args) -> reason or None``: a failing call that the mesh cannot
        judge (the reason is reported as a note, the call is not counted as failed).
    speed_case : str
        The case its speed is measured on (:data:`SPEED_CASE` unless the task needs a mesh
        the sphere is not: a disk).
    """

    name: str
    kind: str
    power: int
    cases: tuple[str, ...]
    calls: Callable[[Case], list[tuple[str, Args]]]
    reference: Callable[[Case, Args], Output]
    stub: str
    mistakes: tuple[Mistake, ...] = ()
    generic: bool = True
    uses: tuple[str, ...] = ()
    not_judged: Callable[[Case, Args], str | None] | None = None
    speed_case: str = SPEED_CASE


def _table() -> list[Task]:
    """Long because it is the table itself: one entry per exercise, read top to bottom."""
    M = Mistake
    return [
        Task(
            "uniform_laplacian", "matrix", 0, OPERATOR_CASES, tf.vf_calls, tf.uniform,
            '''
def uniform_laplacian(V, F):
    """Uniform (graph) Laplacian L = D⁻¹A − I.

    (L f)_i = (1/|N(i)|) Σ_{j∈N(i)} (f_j − f_i): A is the 0/1 adjacency (edges of F), D the
    degrees. Rows sum to 0; the row of a vertex in no face is zero.

    Returns L : (n,n), scipy.sparse.
    """
    raise NotImplementedError
''',
            (M("graph_not_normalised", tf.graph),
             M("transposed", lambda c, a: tf.uniform(c, a).T.tocsr())),
        ),
        Task(
            "cotan_laplacian", "matrix", 0, OPERATOR_CASES, tf.vf_calls, tf.cotan,
            '''
def cotan_laplacian(V, F):
    """Cotangent stiffness C (Pinkall & Polthier 1993), negative semidefinite.

    C_ij = ½ (cot α_ij + cot β_ij) for an edge ij (α, β the angles opposite it; a boundary edge
    has one), C_ii = −Σ_j C_ij. A weight may be negative (non-Delaunay edge): keep it. A
    triangle of zero area adds nothing.

    Returns C : (n,n) scipy.sparse, symmetric, rows summing to 0.
    """
    raise NotImplementedError
''',
            (
                M("cot_not_half", lambda c, a: 2.0 * tf.cotan(c, a)),
                M("row_normalised", tf.row_normalised),
                M("clamped_weights", tf.cotan_abs),
                M("clamped_weights", tf.cotan_corners_abs),
                M("clamped_weights", tf.cotan_clamped),
                M("divided_by_area", tf.divided_by_area),
            ),
        ),
        Task(
            "barycentric_areas", "array", 2, OPERATOR_CASES, tf.vf_calls, tf.areas("barycentric"),
            '''
def barycentric_areas(V, F):
    """Barycentric vertex areas: A_i = ⅓ Σ of the areas of the faces around i.

    Returns A : (n,), summing to the surface area; 0 for a vertex in no face.
    """
    raise NotImplementedError
''',
            (M("voronoi_not_barycentric", tf.areas("voronoi")),
             M("not_divided_by_3", lambda c, a: 3.0 * tf.areas("barycentric")(c, a))),
        ),
        Task(
            "voronoi_areas", "array", 2, OPERATOR_CASES, tf.vf_calls, tf.areas("voronoi"),
            '''
def voronoi_areas(V, F):
    """Mixed Voronoi areas (Meyer, Desbrun, Schröder & Barr 2003, "Discrete
    differential-geometry operators", Fig. 4).

    Non-obtuse triangle: corner i gets ⅛ (|e_ij|² cot θ_k + |e_ik|² cot θ_j). Obtuse triangle:
    the obtuse corner gets ½ of the triangle's area, the two others ¼ each.

    Returns A : (n,), summing to the surface area.
    """
    raise NotImplementedError
''',
            (M("barycentric_not_voronoi", tf.areas("barycentric")),
             M("no_obtuse_rule", tf.circumcentric_areas)),
        ),
        Task(
            "mass_matrix", "matrix", 2, OPERATOR_CASES, tf.vf_calls, tf.mass("voronoi"),
            '''
def mass_matrix(V, F):
    """Lumped mass matrix M = diag(mixed Voronoi areas) (see voronoi_areas).

    Returns M : (n,n) diagonal, scipy.sparse.
    """
    raise NotImplementedError
''',
            (M("barycentric_not_voronoi", tf.mass("barycentric")),),
            uses=("voronoi_areas",),
        ),
        Task(
            "mean_curvature_normal", "array", -1, OPERATOR_CASES, tf.vf_calls, tf.hn("voronoi"),
            '''
def mean_curvature_normal(V, F):
    """Mean curvature normal H n = −½ Δx with Δ = M⁻¹ C (C: cotan_laplacian, M: mass_matrix,
    mixed Voronoi). A vertex with zero area gets 0.

    Returns Hn : (n,3), pointing outwards on a sphere (units 1/length).
    """
    raise NotImplementedError
''',
            (M("barycentric_not_voronoi", tf.hn("barycentric")),
             M("missing_mass", tf.hn_without_mass),
             M("uniform_not_cotan", tf.hn_uniform)),
            uses=("cotan_laplacian", "voronoi_areas", "mass_matrix"),
        ),
        Task(
            "mean_curvature", "array", -1, OPERATOR_CASES, tf.vf_calls,
            tf.mean_curvature("voronoi"),
            '''
def mean_curvature(V, F):
    """Signed mean curvature H = −½ (Δx · n), Δ = M⁻¹C (mixed Voronoi M), n the unit
    angle-weighted vertex normal n_i ∝ Σ_f θ_i,f n_f (Thürmer & Wüthrich 1998).

    Returns H : (n,), ≈ 1/r on a sphere of radius r.
    """
    raise NotImplementedError
''',
            (M("barycentric_not_voronoi", tf.mean_curvature("barycentric")),),
            uses=("mean_curvature_normal",),
        ),
        Task(
            "angle_defect", "array", 0, OPERATOR_CASES, tf.defect_calls, tf.defect,
            '''
def angle_defect(V, F, boundary):
    """Angle defect (integrated Gaussian curvature) at every vertex.

    Interior vertex: 2π − Σθ (θ the corner angles at the vertex, radians). Boundary vertex,
    by rule: "pi": π − Σθ (Gauss–Bonnet with its boundary term), "2pi": 2π − Σθ, "zero": 0.
    A vertex in no face: 0.

    Returns d : (n,). Σ d = 2πχ on a closed surface.
    """
    raise NotImplementedError
''',
            (M("missing_boundary_term", tf.defect_rule("2pi")),
             M("wrong_boundary_rule", tf.defect_rule("pi")),
             M("wrong_boundary_rule", tf.defect_rule("zero")),
             M("degrees", tf.defect_degrees),
             M("divided_by_area", tf.defect_density)),
        ),
        Task(
            "one_ring", "ring", 0, OPERATOR_CASES, tf.ring_calls, tf.ring,
            '''
def one_ring(F, n):
    """Ordered one-ring of every vertex.

    ring[i] lists the neighbours of i counter-clockwise: for consecutive a, b, (i, a, b) is a
    face (in some rotation). Interior vertex: any starting neighbour. Boundary vertex: start at
    the boundary neighbour from which the fan proceeds counter-clockwise.

    Returns a list of n integer arrays (empty for a vertex in no face).
    """
    raise NotImplementedError
''',
            (M("wrong_orientation", tf.ring_cw), M("unordered", tf.ring_sorted)), generic=False,
        ),
        Task(
            "eigenbasis", "eigen", -2, CLOSED_CASES, tf.eig_calls, tf.eigen,
            '''
def eigenbasis(V, F, k):
    """The k lowest eigenpairs of the generalized problem K u = λ M u, K = −C (cotan_laplacian),
    M = mass_matrix (mixed Voronoi). Ascending λ ≥ 0; eigenvectors M-orthonormal: UᵀMU = I.

    Returns (lam, U) : (k,) and (n,k).
    """
    raise NotImplementedError
''',
            (M("ordinary_eigenproblem", tf.eigen_ordinary),
             M("barycentric_not_voronoi", tf.eigen_bary),
             M("sign_flip", tf.eigen_negative),
             M("not_m_orthonormal", tf.eigen_euclid)),
            generic=False, uses=("cotan_laplacian", "mass_matrix"),
        ),
        Task(
            "spectral_reconstruction", "array", 1, CLOSED_CASES, tf.recon_calls, tf.recon,
            '''
def spectral_reconstruction(X, U, M):
    """Project X on the span of the M-orthonormal basis U: X̂ = U (Uᵀ M X).

    X : (n,3), U : (n,k) with UᵀMU = I, M : (n,n) diagonal mass matrix (scipy.sparse).
    Returns X̂ : (n,3).
    """
    raise NotImplementedError
''',
            (M("projection_without_mass", tf.recon_without_mass),),
        ),
        Task(
            "explicit_step", "array", 1, STEP_CASES, tf.explicit_calls, tf.explicit(),
            '''
def explicit_step(V, F, lam):
    """One explicit (forward Euler) smoothing step with the uniform Laplacian:
    V′ = V + λ L V (L from uniform_laplacian).

    Returns V′ : (n,3).
    """
    raise NotImplementedError
''',
            (M("sign_flip", tf.explicit(-1.0)), M("transposed", tf.explicit(1.0, True))),
            generic=False, uses=("uniform_laplacian",),
        ),
        Task(
            "implicit_step", "array", 1, STEP_CASES, tf.implicit_calls, tf.implicit(),
            '''
def implicit_step(V, F, lam):
    """One implicit (backward Euler) step with the cotangent Laplacian (Desbrun et al. 1999):
    solve (M − λ C) V′ = M V, C = cotan_laplacian, M = mass_matrix (mixed Voronoi).

    Returns V′ : (n,3).
    """
    raise NotImplementedError
''',
            (M("sign_flip", tf.implicit(-1.0)),
             M("explicit_not_implicit", tf.implicit_as_explicit),
             M("missing_mass", tf.implicit(1.0, None)),
             M("barycentric_not_voronoi", tf.implicit(1.0, "barycentric"))),
            generic=False, uses=("cotan_laplacian", "mass_matrix"),
        ),
        Task(
            "taubin_step", "array", 1, STEP_CASES, tf.taubin_calls, tf.taubin(),
            '''
def taubin_step(V, F, lam, mu):
    """One Taubin step (Taubin 1995) with the uniform Laplacian L: V₁ = V + λ L V, then
    V′ = V₁ + μ L V₁ (μ < 0 is given).

    Returns V′ : (n,3).
    """
    raise NotImplementedError
''',
            (M("mu_sign", tf.taubin("mu_sign")), M("lambda_only", tf.taubin("lambda_only")),
             M("not_sequential", tf.taubin("not_sequential"))),
            generic=False, uses=("uniform_laplacian",),
        ),
        Task(
            "heat_geodesic", "array", 1, geo.HEAT_CASES, geo.heat_calls, geo.heat_reference,
            geo.STUB,
            (M("gradient_not_normalised", geo.heat_unnormalised),
             M("time_not_scaled", geo.heat_time_not_scaled),
             M("divergence_sign", geo.heat_negated, geo.fits_negated),
             M("not_shifted", geo.heat_unshifted, geo.fits_shifted)),
            uses=("cotan_laplacian", "mass_matrix"), not_judged=geo.heat_not_judged,
        ),
        Task(
            "biharmonic_displacement", "array", 1, dt.DEFORM_CASES, dt.biharmonic_calls,
            dt.biharmonic_reference, dt.BIHARMONIC_STUB,
            (M("positions_not_displacement", dt.bi_positions),
             M("uniform_not_cotan", dt.bi_uniform("uniform")),
             M("uniform_not_cotan", dt.bi_uniform("uniform-normalised")),
             M("biharmonic_without_mass", dt.bi_without_mass),
             M("harmonic_not_biharmonic", dt.bi_harmonic)),
            generic=False, uses=("cotan_laplacian", "mass_matrix"),
        ),
        Task(
            "arap_step", "array", 1, dt.DEFORM_CASES, dt.arap_calls, dt.arap_reference,
            dt.ARAP_STUB,
            (M("no_reflection_fix", dt.arap_mistake(reflection_fix=False)),
             M("uniform_not_cotan", dt.arap_mistake(weights="uniform")),
             M("rotation_transposed", dt.arap_mistake(transposed=True)),
             M("rotation_not_averaged", dt.arap_mistake(averaged=False)),
             M("handles_not_placed", dt.arap_mistake(place=False))),
            generic=False, uses=("cotan_laplacian",),
        ),
        Task(
            "tutte_map", "array", 0, ft.FLATTEN_CASES, ft.tutte_calls, ft.tutte_reference,
            ft.TUTTE_STUB,
            (M("uniform_not_cotan", ft.tutte_uniform),
             M("boundary_by_index", ft.tutte_by_index),
             M("boundary_turned", ft.tutte_turned, ft.fits_rotated),
             M("boundary_not_on_circle", ft.tutte_square, ft.fits_off_circle)),
            generic=False, uses=("cotan_laplacian",), speed_case=ft.FLATTEN_SPEED_CASE,
        ),
        Task(
            "lscm", "array", 1, ft.FLATTEN_CASES, ft.lscm_calls, ft.lscm_reference, ft.LSCM_STUB,
            (M("no_area_term", ft.lscm_no_area),
             M("area_sign", ft.lscm_area_sign),
             M("uniform_not_cotan", ft.lscm_uniform),
             M("unpinned", ft.lscm_collapsed, ft.fits_unpinned)),
            generic=False, uses=("cotan_laplacian",), speed_case=ft.FLATTEN_SPEED_CASE,
        ),
    ]  # fmt: skip


def _checked(tasks: list[Task]) -> dict[str, Task]:
    table = {t.name: t for t in tasks}
    for t in tasks:
        if len(table) != len(tasks) or t.speed_case not in t.cases:
            raise RuntimeError(f"task {t.name}: a name given twice, or {t.speed_case} not checked")
        if f"def {t.name}(" not in t.stub or any(u not in table for u in t.uses):
            raise RuntimeError(f"task {t.name}: its stub or what it uses names another task")
    return table


TASKS: dict[str, Task] = _checked(_table())
"""Every exercise by name, in the template's order."""
EXERCISE_TASKS: tuple[str, ...] = tuple(TASKS)
"""The task names (``meshlap check --task``), in the template's order."""
