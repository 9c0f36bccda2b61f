"""Laplacian smoothing: explicit, implicit and Taubin steppers, stability, denoising sweeps.

Sign convention (the whole project uses it): every Laplacian is **negative semidefinite**. Here
a Laplacian is always written ``L = W⁻¹ K`` with ``W`` a positive diagonal "mass" and ``K`` a
symmetric negative semidefinite "stiffness":

* ``uniform``: ``W = D`` (vertex degrees), ``K = A − D`` (adjacency minus degrees), so
  ``L = D⁻¹A − I`` (:func:`meshlap_core.laplacian.uniform_laplacian`, the course formula);
* ``cotan``: ``W = M`` (lumped Voronoi or barycentric areas), ``K = C`` (cotangent stiffness),
  so ``L = M⁻¹C`` is the Laplace–Beltrami operator (``Lx = −2Hn``).

Its eigenvalues ``μ`` are real and ``≤ 0`` (the frequencies shown to users are ``−μ ≥ 0``).

Methods (one iteration each):

* explicit (diffusion flow, forward Euler): ``x′ = x + λ L x``; amplification per mode
  ``g(μ) = 1 + λμ``, stable iff ``λ ≤ 2 / |μ_min|``;
* implicit (backward Euler, Desbrun et al. 1999): ``(I − λL) x′ = x``, solved in the symmetric
  positive definite form ``(W − λK) x′ = W x``; for the uniform Laplacian that is
  ``((1+λ)D − λA) x′ = D x``. ``g(μ) = 1 / (1 − λμ)``: unconditionally stable;
* Taubin λ|μ (Taubin 1995): an explicit step with ``λ > 0`` then one with ``ν < −λ``
  (``1/λ + 1/ν = k_PB``, the pass-band frequency); ``g(μ) = (1 + λμ)(1 + νμ)``. It barely
  shrinks, because ``g ≈ 1`` at low frequencies.

:class:`Smoother` is the stepper (the implicit system is factorized once with a sparse Cholesky
factorization and reused for every step while ``λ`` and the operator are unchanged);
:func:`smooth` is the one-shot wrapper, :func:`stability` and :func:`amplification_curve` give
the stability numbers, :func:`denoise_sweep` the evaluation table.

Modules
-------
``params``
    Argument checks (the method, Laplacian and mass-update names are in
    :mod:`meshlap_core.options`).
``stability``
    ``W`` and ``K``, the most negative eigenvalue, amplification curves, stable ``λ``.
``stepper``
    :class:`Smoother`.
``oneshot``
    :func:`smooth`.
``denoise``
    :func:`denoise_sweep` and :func:`best_rows`.

The implicit system is solved by :class:`meshlap_core.linalg.spd.SPDSolver` (mesh-free).

References
----------
Desbrun, Meyer, Schröder & Barr, "Implicit fairing of irregular meshes using diffusion and
curvature flow", SIGGRAPH 1999.
Taubin, "A signal processing approach to fair surface design", SIGGRAPH 1995.
Kazhdan, Solomon & Ben-Chen, "Can mean-curvature flow be modified to be non-singular?",
SGP 2012 (stiffness frozen, mass recomputed).
"""

from ..linalg.quiet import quiet_c_stdout
from .denoise import best_rows, denoise_sweep
from .oneshot import smooth
from .params import (
    DEFAULT_PASS_BAND,
    MAX_ITERS,
    check_iters,
    check_lam,
    taubin_mu,
)
from .stability import (
    ILL_CONDITIONED,
    Stability,
    amplification_curve,
    most_negative_eigenvalue,
    operator_parts,
    stability,
)
from .stepper import DivergenceError, Smoother

__all__ = [
    "DEFAULT_PASS_BAND",
    "ILL_CONDITIONED",
    "MAX_ITERS",
    "DivergenceError",
    "Smoother",
    "Stability",
    "amplification_curve",
    "best_rows",
    "check_iters",
    "check_lam",
    "denoise_sweep",
    "most_negative_eigenvalue",
    "operator_parts",
    "quiet_c_stdout",
    "smooth",
    "stability",
    "taubin_mu",
]
