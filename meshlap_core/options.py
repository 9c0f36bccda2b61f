"""The shared vocabulary: every option name, its choices, its default, and every tolerance.

Each option and threshold is defined here once; modules import it from here and never restate
it. ``tests/test_options.py`` checks that no other module defines one of these names again.

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
"""

from __future__ import annotations

from typing import Literal, get_args

AreaKind = Literal["barycentric", "voronoi"]
AREA_KINDS: tuple[str, ...] = get_args(AreaKind)
DEFAULT_AREA: AreaKind = "barycentric"
"""Default area of the curvature and Laplacian functions (the course's formulas)."""
MASS_AREA: AreaKind = "voronoi"
"""Default area of the mass matrix wherever a positive-definite M that converges under
refinement matters more than matching the course: spectral bases, smoothing, ``mass_matrix``."""

LaplacianKind = Literal["uniform", "cotan"]
LAPLACIAN_KINDS: tuple[str, ...] = get_args(LaplacianKind)

BoundaryRule = Literal["pi", "2pi", "zero"]
BOUNDARY_RULES: tuple[str, ...] = get_args(BoundaryRule)
DEFAULT_BOUNDARY: BoundaryRule = "pi"

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
