"""The shared vocabulary: every option name, its choices, its default, and every tolerance.

Each option and threshold is defined here once; modules import it from here and never restate
it. ``tests/project/test_options.py`` checks that no other module defines one of these names again.

Options
-------
AreaKind
    The lumped vertex area (the diagonal of the mass matrix M):

    - ``"barycentric"``: a third of every incident triangle (the course's choice);
    - ``"voronoi"``: the mixed Voronoi area of Meyer, Desbrun, Schröder & Barr, *Discrete
      differential-geometry operators for triangulated 2-manifolds* (2003); converges under
      refinement.
LaplacianKind
    ``"uniform"`` (graph Laplacian, weights 1/|N(i)|) or ``"cotan"`` (the cotangent
    Laplace–Beltrami operator, Pinkall & Polthier 1993).
BoundaryRule
    The angle a boundary vertex's angle sum is compared with in the angle-deficit Gaussian
    curvature ``K = (θ₀ − Σθ)/A``: ``"pi"`` (θ₀ = π, a flat boundary has K = 0), ``"2pi"``
    (θ₀ = 2π, as if the vertex were interior) or ``"zero"`` (K = 0 on the boundary).
CurvatureEstimator, PrincipalField
    The principal-curvature estimators side by side (``meshlap curvature --estimator``, see
    :mod:`meshlap_core.curvature.estimators`) and the scalar fields of their results.
CurvatureMethod, CurvatureField
    The per-vertex curvature estimators (``meshlap curvature --method``): ``"uniform"`` and
    ``"cotan"`` (mean curvature H from that Laplacian), ``"gaussian"`` (angle deficit K),
    ``"k1"``, ``"k2"`` (principal curvatures from cotan H and K). The fields add
    ``"difference"`` (H uniform − H cotan); :data:`CURVATURE_FIELD_LABELS` gives each field's
    label shown to users and whether it is signed.
SmoothingMethod
    ``"explicit"`` (``x′ = x + λLx``), ``"implicit"`` (``(I − λL)x′ = x``) or ``"taubin"``
    (a λ step and a ν step).
MassUpdate
    How a cotangent smoother treats the mass matrix between steps: ``"frozen"`` (computed once,
    the system factorized once) or ``"recompute"`` (recomputed from the current positions).
NoiseMode
    Direction of the synthetic noise: ``"isotropic"`` (every coordinate) or ``"normal"`` (along
    the vertex normal).
DerivativeMethod
    How a parametric surface's derivatives are obtained: ``"auto"`` (exact when the surface
    has them, else complex step), ``"exact"``, ``"complex-step"`` or ``"central"``.
Mesher
    How a convergence study meshes a parametric surface: ``"grid"`` (the (u, v) grid) or
    ``"icosphere"`` (the sphere only).
DirectionAngle
    A tangent direction of a parametric surface as an angle in the ``(u, v)`` plane (``"uv"``)
    or in the tangent plane from ``p_u`` (``"tangent"``).
SurfaceSigns
    The sign of a parametric surface's second fundamental form (``meshlap surface --signs``,
    :mod:`meshlap_core.surfaces`): ``"outward"`` (the project's one convention, ``e = −p_uu · n``,
    so ``H > 0`` on a sphere with its outward normal, as on meshes) or ``"do-carmo"`` (do Carmo's
    and the course's ``e = p_uu · n``: ``II``, the shape operator, ``H``, ``κ₁``, ``κ₂`` and
    ``κₙ`` change sign, the principal directions swap roles, ``K`` and ``n`` stay).
UpAxis
    The mesh's axis that points up on screen (``meshlap view --up``): ``"y"`` (the default,
    most scans and the course meshes), ``"z"`` (CAD and some scans, e.g. nefertiti),
    ``"x"``, or one of them negated.

Every choice is checked by :func:`check_choice`, which raises the one standard message
``unknown <what> <value>; choose one of a, b, c``.
"""

from __future__ import annotations

from typing import Literal, get_args

from .errors import MeshError

AreaKind = Literal["barycentric", "voronoi"]
AREA_KINDS: tuple[str, ...] = get_args(AreaKind)
DEFAULT_AREA: AreaKind = "barycentric"
"""Default area of the curvature and Laplacian functions (the course's formulas)."""
CURVATURE_AREA: AreaKind = "voronoi"
"""Default area of the curvature estimators (``meshlap_core.curvature``, ``meshlap curvature``, the
Curvature panel): the mixed Voronoi area, with which the cotangent ``H`` and the angle-deficit
``K`` converge (L2 order 2); ``"barycentric"`` (the course's) is one argument away."""
MASS_AREA: AreaKind = "voronoi"
"""Default area of the mass matrix wherever a positive-definite M that converges under
refinement matters more than matching the course: spectral bases, smoothing, ``mass_matrix``."""

LaplacianKind = Literal["uniform", "cotan"]
LAPLACIAN_KINDS: tuple[str, ...] = get_args(LaplacianKind)

BoundaryRule = Literal["pi", "2pi", "zero"]
BOUNDARY_RULES: tuple[str, ...] = get_args(BoundaryRule)
DEFAULT_BOUNDARY: BoundaryRule = "pi"

CurvatureMethod = Literal["uniform", "cotan", "gaussian", "k1", "k2"]
CURVATURE_METHODS: tuple[str, ...] = get_args(CurvatureMethod)
CurvatureField = Literal[CurvatureMethod, "difference"]
CURVATURE_FIELDS: tuple[str, ...] = get_args(CurvatureField)
DEFAULT_CURVATURE_FIELD: CurvatureField = "cotan"
CURVATURE_FIELD_LABELS: dict[str, tuple[str, bool]] = {
    "uniform": ("mean curvature H (uniform Laplacian)", True),
    "cotan": ("mean curvature H (cotangent Laplace-Beltrami)", True),
    "gaussian": ("Gaussian curvature K (angle deficit)", True),
    "k1": ("principal curvature k1", True),
    "k2": ("principal curvature k2", True),
    "difference": ("H uniform - H cotangent", True),
}
"""Curvature field -> (the label shown to users, whether the field is signed)."""

UNITS: tuple[str, ...] = (
    "length",
    "1/length",
    "1/length^2",
    "length^2",
    "dimensionless",
    "mixed: length - 1/length",
)
"""The units a colour bar's title may give (``quantity [unit]``, :func:`titled`)."""
CURVATURE_FIELD_UNITS: dict[str, str] = {
    "uniform": "length",  # -½ (D⁻¹A − I)x · n: neighbours' mean minus x, not divided by an area
    "cotan": "1/length",
    "gaussian": "1/length^2",
    "k1": "1/length",
    "k2": "1/length",
    "difference": "mixed: length - 1/length",  # a length minus a curvature
}
"""Curvature field -> its unit: the uniform Laplacian is not divided by an area, so its H is a
length (it scales like the mesh), the cotangent H a curvature (it scales like 1/length)."""


def length_unit(power: int) -> str:
    """The unit ``length^power`` as :data:`UNITS` names it (0: ``dimensionless``)."""
    names = {-2: "1/length^2", -1: "1/length", 0: "dimensionless", 1: "length", 2: "length^2"}
    if power not in names:
        raise ValueError(f"no unit name for length^{power}")
    return names[power]


def titled(quantity: str, unit: str) -> str:
    """A colour bar's title: ``quantity [unit]`` (``unit`` one of :data:`UNITS`)."""
    if unit not in UNITS:
        raise ValueError(f"unit {unit!r} is not one of {', '.join(UNITS)}")
    return f"{quantity} [{unit}]"


def curvature_field_title(name: str, estimator: str | None = None) -> str:
    """The title of the curvature field ``name`` (its label, the estimator of k1 / k2 when
    not the cotangent one, its unit): the colour bar's, the histogram's axis."""
    label = CURVATURE_FIELD_LABELS[name][0]
    if estimator not in (None, "cotan") and name in ("k1", "k2"):
        label += f" ({estimator})"
    return titled(label, CURVATURE_FIELD_UNITS[name])


CurvatureEstimator = Literal["cotan", "quadric", "rusinkiewicz", "normal_cycle", "jet"]
CURVATURE_ESTIMATORS: tuple[str, ...] = get_args(CurvatureEstimator)
DEFAULT_CURVATURE_ESTIMATOR: CurvatureEstimator = "cotan"
CURVATURE_ESTIMATOR_LABELS: dict[str, str] = {
    "cotan": "cotangent H + angle-deficit K (Meyer et al. 2003)",
    "quadric": "libigl quadric fit over edge rings (Panozzo et al. 2010)",
    "rusinkiewicz": "per-face tensors averaged to vertices (Rusinkiewicz 2004)",
    "normal_cycle": "normal-cycle tensor over the Voronoi cell (Cohen-Steiner & Morvan 2003)",
    "jet": "jet fit over a world-radius ball (Cazals & Pouget 2003), robust to noise",
}
"""Principal-curvature estimator -> its label shown to users
(:mod:`meshlap_core.curvature.estimators`)."""
PrincipalField = Literal["k1", "k2", "H", "K", "abs_max"]
PRINCIPAL_FIELDS: tuple[str, ...] = get_args(PrincipalField)
"""Scalar fields of an estimator's result: ``k1 ≥ k2``, ``H = (k1+k2)/2``, ``K = k1 k2``,
``abs_max = max(|k1|, |k2|)``."""
PRINCIPAL_FIELD_UNITS: dict[str, str] = {
    "k1": "1/length",
    "k2": "1/length",
    "H": "1/length",
    "K": "1/length^2",
    "abs_max": "1/length",
}
"""Each field of :data:`PRINCIPAL_FIELDS` -> its unit (:data:`UNITS`)."""

LabSource = Literal["surface", "mesh"]
LAB_SOURCES: tuple[str, ...] = get_args(LabSource)
"""The curvature lab's mesh: a parametric surface's (exact values known) or the loaded one."""
LabShow = Literal["estimate", "error", "disagreement"]
LAB_SHOWS: tuple[str, ...] = get_args(LabShow)
"""What the curvature lab colours: the estimate, its error against the exact surface, or the
largest difference between the estimators (no exact values needed: scans)."""

SmoothingMethod = Literal["explicit", "implicit", "taubin"]
SMOOTHING_METHODS: tuple[str, ...] = get_args(SmoothingMethod)
DEFAULT_SMOOTHING_METHOD: SmoothingMethod = "explicit"
EULER_METHODS: tuple[SmoothingMethod, ...] = ("explicit", "implicit")
"""The forward and backward Euler steps of the heat flow (no Taubin ν step): the methods a
denoising sweep tries by default and the course's report compares."""

MassUpdate = Literal["frozen", "recompute"]
MASS_UPDATES: tuple[str, ...] = get_args(MassUpdate)
DEFAULT_MASS_UPDATE: MassUpdate = "frozen"

NoiseMode = Literal["isotropic", "normal"]
NOISE_MODES: tuple[str, ...] = get_args(NoiseMode)
DEFAULT_NOISE_MODE: NoiseMode = "isotropic"

DerivativeMethod = Literal["auto", "exact", "complex-step", "central"]
DERIVATIVE_METHODS: tuple[str, ...] = get_args(DerivativeMethod)

Mesher = Literal["grid", "icosphere"]
MESHERS: tuple[str, ...] = get_args(Mesher)

DirectionAngle = Literal["uv", "tangent"]
DIRECTION_ANGLES: tuple[str, ...] = get_args(DirectionAngle)
"""How a tangent direction of a parametric surface is given by one angle: ``"uv"``, the
parameter angle ``θ_uv`` (``p_u cos θ_uv + p_v sin θ_uv``) or ``"tangent"``, the true angle
``θ`` in the tangent plane from ``p_u / |p_u|`` (:mod:`meshlap_core.surfaces.angles`)."""

SurfaceSigns = Literal["outward", "do-carmo"]
SURFACE_SIGNS: tuple[str, ...] = get_args(SurfaceSigns)
DEFAULT_SURFACE_SIGNS: SurfaceSigns = "outward"
"""The project's one convention by default; ``"do-carmo"`` where a student checks a hand
calculation made with do Carmo's (the course's) ``e = p_uu · n`` (see ``docs/conventions.md``)."""

HeatBoundary = Literal["neumann", "dirichlet", "average"]
HEAT_BOUNDARIES: tuple[str, ...] = get_args(HeatBoundary)
DEFAULT_HEAT_BOUNDARY: HeatBoundary = "average"
"""Boundary condition of the heat step of the heat method (Crane, Weischedel & Wardetzky 2013,
sec. 3.2.4): zero flux (``"neumann"``), zero heat on the boundary (``"dirichlet"``), or the mean
of the two heat fields (``"average"``, the paper's recommendation and libigl's choice)."""

HeatMethod = Literal["euler", "spectral"]
HEAT_METHODS: tuple[str, ...] = get_args(HeatMethod)
"""How ``meshlap heat`` solves ``u_t = Δu``: backward Euler steps or the eigen-expansion."""

GeodesicMethod = Literal["heat", "igl-heat", "exact"]
GEODESIC_METHODS: tuple[str, ...] = get_args(GeodesicMethod)
"""Geodesic distance: this project's heat method, libigl's, or the exact polyhedral (MMP)
distance of ``igl.exact_geodesic``."""

FilterKind = Literal["low-pass", "band", "explicit", "implicit", "taubin"]
FILTER_KINDS: tuple[str, ...] = get_args(FilterKind)
"""Spectral transfer functions: an ideal low-pass, a band gain (exaggeration), and the transfer
functions of the three smoothing methods."""

DeformMethod = Literal["laplacian", "harmonic", "biharmonic", "triharmonic", "arap"]
DEFORM_METHODS: tuple[str, ...] = get_args(DeformMethod)
"""Shape deformation (:mod:`meshlap_core.deform`, ``meshlap deform --method``): Laplacian
coordinates (Sorkine et al. 2004), the k-harmonic displacement ``Δᵏd = 0`` for k = 1, 2, 3, and
as-rigid-as-possible (Sorkine & Alexa 2007)."""
HARMONIC_ORDERS: dict[str, int] = {"harmonic": 1, "biharmonic": 2, "triharmonic": 3}
"""The power k of each k-harmonic deformation method."""
ArapEnergyKind = Literal["spokes", "spokes-and-rims"]
ARAP_ENERGIES: tuple[str, ...] = get_args(ArapEnergyKind)
DEFAULT_ARAP_ENERGY: ArapEnergyKind = "spokes"
"""The edges each ARAP rotation fits: the one-ring's spokes (Sorkine & Alexa 2007) or the
spokes and the rim edges of every incident face (Chao et al. 2010; libigl's default for
triangle meshes in 3D)."""
RotationFit = Literal["exact", "igl"]
ROTATION_FITS: tuple[str, ...] = get_args(RotationFit)
"""How ARAP's local step fits rotations: this project's double-precision 3×3 SVD
(``"exact"``) or libigl's single-precision one (``"igl"``, what ``igl.arap_solve`` uses)."""
ConstraintKind = Literal["soft", "hard"]
CONSTRAINT_KINDS: tuple[str, ...] = get_args(ConstraintKind)
DEFAULT_CONSTRAINTS: ConstraintKind = "soft"
"""How Laplacian coordinates hold the handles and the fixed region: least-squares penalties
(``"soft"``, Sorkine et al. 2004) or exactly (``"hard"``)."""
HandleDistance = Literal["exact", "graph"]
HANDLE_DISTANCES: tuple[str, ...] = get_args(HandleDistance)
DEFAULT_HANDLE_DISTANCE: HandleDistance = "exact"
"""The distance that grows a handle vertex into a disc: exact polyhedral geodesic distance
(MMP on the disc's neighbourhood) or shortest paths along edges (instant, up to ~15 % long)."""


FlattenMethod = Literal["tutte", "harmonic", "lscm", "scp", "arap"]
FLATTEN_METHODS: tuple[str, ...] = get_args(FlattenMethod)
"""Maps of a disk to the plane (:mod:`meshlap_core.flatten`): Tutte's (uniform weights) and the
harmonic one (cotangent weights) with a fixed boundary, the least-squares conformal map (two
pinned vertices), the spectral conformal map (Mullen et al. 2008) and ARAP (Liu et al. 2008)."""
FlattenBoundary = Literal["circle", "square", "free"]
FLATTEN_BOUNDARIES: tuple[str, ...] = get_args(FlattenBoundary)
"""Where a map puts the outer boundary: on the unit circle or the unit square (by arc length),
or nowhere in particular (``"free"``: the map's natural boundary)."""
FLATTEN_METHOD_BOUNDARIES: dict[str, tuple[str, ...]] = {
    "tutte": ("circle", "square"),
    "harmonic": ("circle", "square"),
    "lscm": ("free",),
    "scp": ("free",),
    "arap": ("free", "circle", "square"),
}
"""The boundaries each map accepts, its default first: a fixed-boundary map has no natural
boundary (a harmonic map with a free boundary is constant), the conformal maps have only theirs."""
DEFAULT_ARAP_ITERS = 50
"""ARAP local/global iterations of ``meshlap flatten --method arap`` when ``--iters`` is not
given."""
MAX_FLATTEN_ITERS = 100_000
"""Most ARAP iterations one call runs (``--iters``; about 1.5 hours at 43k vertices)."""


def check_choice(value: str, choices: tuple[str, ...], what: str, where: str | None = None) -> str:
    """Return ``value`` if it is one of ``choices``, else raise the one standard error.

    Parameters
    ----------
    value : str
        What the caller (or user) gave.
    choices : tuple of str
        The allowed values, e.g. :data:`AREA_KINDS`.
    what : str
        What the value is, in words: ``"area"``, ``"boundary rule"``, ``"Laplacian"``.
    where : str, optional
        The argument the error is attributed to (its :attr:`MeshError.source`); ``what`` when
        not given.

    Raises
    ------
    MeshError
        ``<where>: unknown <what> <value!r>; choose one of a, b, c``.

    Examples
    --------
    >>> check_choice("voronoi", AREA_KINDS, "area")
    'voronoi'
    >>> check_choice("mixed", AREA_KINDS, "area")
    Traceback (most recent call last):
    ...
    meshlap_core.errors.MeshError: area: unknown area 'mixed'; choose one of barycentric, voronoi
    """
    if value not in choices:
        raise MeshError(
            f"unknown {what} {value!r}; choose one of {', '.join(choices)}",
            what if where is None else where,
        )
    return value


UpAxis = Literal["y", "z", "x", "-y", "-z", "-x"]
UP_AXES: tuple[str, ...] = get_args(UpAxis)
DEFAULT_UP: UpAxis = "y"


# ------------------------------------------------------------------------------ tolerances

MAX_COORDINATE = 1e75
"""|coordinate| above this is refused: the cotangent code forms products of squared edge lengths
(l⁴); with |x| ≤ 1e75 every edge is below ~3.5e75 and l⁴ stays below ~1.5e302."""

MIN_EXTENT = 1e-60
"""A mesh whose bounding-box diagonal is below this (but not 0) is refused: squared lengths and
their products underflow into subnormal numbers and the cotangent weights lose their accuracy
(at 1e-80 the mean curvature is already 0.2 % off)."""

SLIVER_ANGLE = 1e-4
"""A face whose smallest corner angle is below this (radians, about 0.006°) is reported as a
needle or a cap: its cotangent weights exceed 1e4."""

DEGENERATE_REL = 0.5e-12
"""A face is degenerate (collinear up to round-off) when
``|(b−a)×(c−a)| ≤ DEGENERATE_REL · (l₀² + l₁² + l₂²)``. The validator removes such faces and the
cotangent code gives them zero weights; in the squared form the Laplacian uses,
``16 A² ≤ (2·DEGENERATE_REL)² (Σ l²)²``, so both select exactly the same faces."""

# ---- exercises (meshlap check) ---------------------------------------------------------------

# The task names are declared with the tasks themselves: meshlap_core.exercises.tasks
# (EXERCISE_TASKS there), one declaration per task.
EXERCISE_RTOL = 1e-7
"""A student's value passes when ``|got − expected| ≤ EXERCISE_RTOL · max(max|expected|, h^p)``
on every vertex, ``h`` the mesh's mean edge length and ``p`` the quantity's units (length^p):
the tolerance follows the mesh scale, so a copy scaled by 250 is judged alike."""
EXERCISE_EIGEN_RTOL = 1e-6
"""The same for eigenvalues and the eigen-residual (an iterative solver's accuracy)."""
EXERCISE_SLOW_RATIO = 100.0
"""A correct answer that takes this many times the reference's time on the large mesh is
reported as a slow Python loop (and fails)."""
EXERCISE_SLOW_MIN_SECONDS = 0.5
"""...and only when that call takes at least this long on the large mesh (2562 vertices). A
plain Python loop over the faces takes 0.01–0.2 s there, yet 50–150× a library's C++ (libigl's
mass matrix): it is not what "100× slower than it should be" means, so it passes; a loop
writing a sparse matrix entry by entry, or calling numpy per vertex, takes seconds. Both times
come from the round most favourable to the student of several side-by-side rounds (a busy
machine must not fail a right answer)."""
EXERCISE_TIMEOUT = 60.0
"""Seconds one task of a student file may run before it is stopped (``meshlap check --timeout``)."""
EXERCISE_MEMORY_MB = 2048
"""Address space a student file may add to the checker's worker, in MiB (``--memory``)."""
MAX_FIT_PAIRS = 200_000_000
"""Largest number of (vertex, neighbour) pairs a local fit may visit, summed over the vertices:
the jet's ball of world radius and libigl's quadric over edge rings. libigl fits about 5e6
pairs/s, the jet 1e6 (bunny, 2 cores under load): this is a minute or more of work. A larger
radius is refused before any work, naming the largest that fits."""

MAX_HEAT_STEPS = 1000
"""Most backward Euler steps of one heat flow (``heat --steps``; the Diffusion panel's limit
too): each is a solve, and each mode's damping ``(1 + λt/N)^−N`` is then within
``max_x |e^−x − (1 + x/N)^−N| = 2.7e-4`` of the exact ``e^−λt`` (2.7e-3 at N = 100), below
the 1/256 a colour map shows."""

MAX_ISOLINES = 1000
"""Most level curves of one field (``--isolines``, :func:`~meshlap_core.diffusion.isolines`):
more than a window can tell apart (a 4K screen is 2160 pixels tall), and each level can cross
every face: 100000 curves of a 162-vertex sphere wrote 229 MB."""

MAX_STIFFNESS_RATIO = 1e14
"""Largest ``τ · max_i K_ii / m_i`` (about ``τ λ_max``) of a backward Euler heat step
``(M + τK) u' = M u``: beyond it the mass is round-off of ``τK`` and the total heat (the
constant mode) is lost, so the step is refused."""
