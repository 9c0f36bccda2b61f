"""The smoothing stepper :class:`Smoother` (explicit, implicit and Taubin steps) and the
one-shot :func:`smooth`.

Sign convention: ``L = W⁻¹K`` negative semidefinite; explicit ``x′ = x + λLx``, implicit
``(W − λK) x′ = W x``, Taubin an explicit ``λ`` step then an explicit ``ν < −λ`` step (see
:mod:`meshlap_core.smoothing` for the formulas and references).
"""

from __future__ import annotations

import math
import time
import warnings
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError, MeshWarning, check_cancel
from ..laplacian import vertex_areas
from ..linalg.common import ProgressCallback
from ..linalg.spd import solver_backend
from ..metrics import n_boundary_edges, signed_volume_unchecked
from ..noise import bbox_diagonal
from ..options import (
    AREA_KINDS,
    DEFAULT_MASS_UPDATE,
    LAPLACIAN_KINDS,
    MASS_AREA,
    MASS_UPDATES,
    SMOOTHING_METHODS,
    AreaKind,
    LaplacianKind,
    MassUpdate,
    SmoothingMethod,
    check_choice,
)
from ..topology import boundary_vertex_mask
from ..types import FloatArray, IntArray, as_mesh, as_vertices
from .history import check_history_options, displacement_sums, keep, step_entry
from .implicit_solver import SOLVER_CHOICES, ImplicitSolver
from .params import (
    DEFAULT_PASS_BAND,
    check_iters,
    check_lam,
    resolve_nu,
    taubin_mu,
)
from .stability import (
    Stability,
    diagonal_scale,
    gershgorin_mu_min,
    ill_conditioning,
    most_negative_eigenvalue,
    operator_parts,
    stability_from_mu,
)


class DivergenceError(MeshError):
    """Explicit or Taubin smoothing blew up (``λ`` above the stable limit); a :class:`MeshError`
    whose message gives the iteration and the largest stable ``λ``."""


class Smoother:
    """Laplacian smoothing stepper: build once, then ``step()`` (cheap) as often as needed.

    Parameters
    ----------
    V : (n,3) float
        Initial positions (copied; never modified).
    F : (m,3) int
    method : {"explicit", "implicit", "taubin"}
        See the module docstring for the update formulas.
    laplacian : {"uniform", "cotan"}
        ``L = W⁻¹K`` negative semidefinite: uniform ``D⁻¹A − I`` or cotangent Laplace–Beltrami
        ``M⁻¹C``. ``λ`` is dimensionless for ``uniform`` (stable explicit ``λ <= 1`` always) but has
        units of length² for ``cotan`` (see :attr:`stability` for the limit on this mesh).
    lam : float
        Step ``λ > 0``.
    taubin_nu : float, optional
        Taubin's second (negative) factor; default from ``pass_band``.
    pass_band : float
        Taubin's pass band relative to the mesh (default 0.1): ``k_PB = pass_band × mean_i(−L_ii)``,
        which is exactly ``pass_band`` for the uniform Laplacian (diagonal −1) and scales with
        the inverse squared edge length for the cotan one (see :attr:`k_pb`).
    fix_boundary : bool
        Keep boundary vertices where they are.
    preserve_volume : bool
        After each step, scale about the vertex centroid so the enclosed volume stays that of the
        input (closed meshes only).
    mass_update : {"frozen", "recompute"}
        ``frozen``: ``W`` and ``K`` from the input mesh, the implicit system factorized once.
        ``recompute``: ``W`` (the areas) recomputed from the current positions every step with
        ``K`` frozen (Kazhdan et al. 2012); the implicit system is then refactorized every step.
        No effect for the uniform Laplacian (``W = D`` depends on connectivity only).
    area : {"voronoi", "barycentric"}
        Lumped area of the cotan mass.
    reference : (n,3) float, optional
        Clean positions; the history then also records ``rmse`` against them.
    track_history : bool
        Record a metrics dict per iteration in :attr:`history` (cheap: O(n + m)).
    history_limit : int, optional
        Keep at most this many entries: the input's (``history[0]``) and the latest
        ``history_limit − 1`` iterations (each entry carries its ``iteration``). An interactive
        stepper that runs without end should set it (about 0.5 kB per entry); ``None`` (the
        default) keeps every entry.
    history_samples : int, optional
        Keep at most this many entries (``>= 4``) spread over the whole run: the input's, every
        :attr:`history_stride`-th iteration and always the latest one; when the list is full the
        stride doubles and every other sample is dropped, so a run of any length keeps between
        ``history_samples / 2`` and ``history_samples`` entries. Cannot be combined with
        ``history_limit``.
    warn : bool
        Emit a :class:`MeshWarning` when an explicit or Taubin ``λ`` is unstable on this mesh.
    steps : int, optional
        Steps the caller means to take (``None``: open-ended, e.g. *play*; :meth:`run` says
        it for its own): on a scan CHOLMOD answers the first implicit step and, for a run
        long enough, a cholespy factorization built meanwhile in a helper process the later
        ones (:mod:`~.implicit_solver`; :meth:`solver_report` says which and why).
    implicit_solver : {"auto", "direct", "handover"}
        ``auto`` as just said; ``direct``: never a helper; ``handover``: a helper takes over
        whenever it can start (tests, comparisons).

    Attributes
    ----------
    iteration : int
        Iterations done since construction or :meth:`reset`.
    history : list of dict
        ``history[k]`` describes the mesh after ``k`` iterations (``history[0]`` the input;
        with ``history_limit`` only the latest iterations are kept, so use ``iteration``):
        ``iteration``, ``time_ms`` (the step alone; a solve the helper started ahead, while
        the caller was busy, is counted whole), ``step_rms``/``step_max`` (displacement of
        this step), ``drift_rms`` (from the input), ``volume`` and ``volume_change_pct`` (both
        ``None`` on open meshes, see :attr:`volume_note`), and ``rmse`` with a reference.
    history_stride : int
        With ``history_samples``: the spacing of the kept iterations (1 until the list first
        fills up, then a power of 2).
    diverged : bool
        ``True`` once a step blew up: a non-finite coordinate, or an RMS displacement from the
        input above :attr:`divergence_limit`. That step is discarded and later steps do nothing
        until :meth:`reset` or :meth:`set_lam`; :meth:`divergence_message` says what happened
        and gives the largest stable ``λ``.
    divergence_limit : float
        Explicit: the input's bounding-box diagonal (a convergent explicit flow contracts the
        mesh towards a weighted centroid inside its bounding box and never moves it that far).
        Taubin and implicit: 1000 diagonals. Taubin amplifies its pass band on purpose (spectral
        radius slightly above 1, e.g. 1.0007 per step), so a long stable Taubin run inflates
        slowly (2.5× its size after 5,000 steps on a sphere) and only a blow-up counts; an
        implicit step cannot diverge, so only a numerical failure trips it.
    diagonal : float
        The input's bounding-box diagonal (the unit of :attr:`divergence_limit`).
    closed : bool
    volume_note : str or None
        Why the volume is undefined (open mesh), else ``None``.
    n_factorizations : int
        How many times a linear system was factorized (1 for a frozen implicit smoother; the
        helper's factorization of the same system is not counted).

    Notes
    -----
    Memory: the smoother holds two per-vertex position arrays, the input ``V0`` and the
    current ``V`` (plus ``reference`` when given, and the per-vertex areas), never a history
    of positions: a step replaces ``V``. :attr:`history` holds scalars only (about 0.5 kB per
    entry), bounded by ``history_limit`` or ``history_samples`` (the CLI keeps at most
    :data:`~meshlap_core.cli.smooth.HISTORY_SAMPLES`, the window 1,000); only the default
    (``None``, for scripts) keeps one entry per iteration.

    Examples
    --------
    >>> from meshlap_core import Smoother
    >>> from meshlap_core.primitives import bumpy_sphere
    >>> V, F = bumpy_sphere(3)
    >>> s = Smoother(V, F, "implicit", "uniform", lam=1.0)
    >>> s.run(5).shape
    (642, 3)
    >>> s.iteration, s.n_factorizations  # factorized once, stepped five times
    (5, 1)
    >>> s.history[5]["volume"] < s.history[0]["volume"]  # Laplacian smoothing shrinks
    True
    """

    def __init__(
        self,
        V: FloatArray,
        F: IntArray,
        method: SmoothingMethod = "explicit",
        laplacian: LaplacianKind = "uniform",
        lam: float = 0.5,
        *,
        taubin_nu: float | None = None,
        pass_band: float = DEFAULT_PASS_BAND,
        fix_boundary: bool = False,
        preserve_volume: bool = False,
        mass_update: MassUpdate = DEFAULT_MASS_UPDATE,
        area: AreaKind = MASS_AREA,
        reference: FloatArray | None = None,
        track_history: bool = True,
        history_limit: int | None = None,
        history_samples: int | None = None,
        warn: bool = True,
        steps: int | None = None,
        implicit_solver: str = "auto",
    ) -> None:
        self.V0, self.F = as_mesh(V, F)
        self.implicit_solver = check_choice(implicit_solver, SOLVER_CHOICES, "implicit_solver")
        self._planned = None if steps is None else check_iters(steps, "steps")
        self._init_history(history_limit, history_samples)
        self.n = len(self.V0)
        self.method = check_choice(method, SMOOTHING_METHODS, "method")
        self.laplacian = check_choice(laplacian, LAPLACIAN_KINDS, "laplacian")
        self.mass_update = check_choice(mass_update, MASS_UPDATES, "mass_update")
        self.area = check_choice(area, AREA_KINDS, "area")
        self.pass_band = check_lam(pass_band, "pass_band")
        self.lam = check_lam(lam)
        self._nu_given = taubin_nu
        self.track_history = bool(track_history)
        self.reference = None if reference is None else as_vertices(reference, "reference")
        if self.reference is not None and self.reference.shape != self.V0.shape:
            raise MeshError(
                f"has {len(self.reference)} vertices but the mesh has {self.n}", "reference"
            )

        self._init_volume(bool(preserve_volume))
        self._init_operator(bool(fix_boundary))

        if warn and self.method != "implicit":
            self._warn_if_unstable()
        if warn and self.method == "implicit":
            self._warn_if_ill_conditioned()
        self.reset()

    def _init_history(self, limit: int | None, samples: int | None) -> None:
        """Check and store ``history_limit`` / ``history_samples``."""
        self.history_limit, self.history_samples = check_history_options(limit, samples)
        self.history_stride = 1

    def _init_volume(self, preserve_volume: bool) -> None:
        """Closedness, the input's enclosed volume and the volume-preservation check."""
        nb = n_boundary_edges(self.F) if len(self.F) else 0
        self.closed = len(self.F) > 0 and nb == 0
        if self.closed:
            self.volume_note: str | None = None
        elif len(self.F) == 0:
            self.volume_note = "undefined: the mesh has no faces"
        else:
            self.volume_note = f"undefined: the mesh is open ({nb} boundary edges)"
        self.preserve_volume = preserve_volume
        self._FT = np.ascontiguousarray(self.F.T)
        self.volume0 = signed_volume_unchecked(self.V0, self.F) if self.closed else None
        if self.preserve_volume:
            if not self.closed:
                raise MeshError(
                    f"needs a closed mesh; the enclosed volume is {self.volume_note}",
                    "preserve_volume",
                )
            if self.volume0 == 0.0 or not math.isfinite(self.volume0 or 0.0):
                raise MeshError("the mesh encloses zero volume", "preserve_volume")

    def _init_operator(self, fix_boundary: bool) -> None:
        """``W``, ``K``, Taubin's factors, the pinned vertices, the free/fixed blocks of ``K``."""
        self.fix_boundary = fix_boundary
        self.diagonal = bbox_diagonal(self.V0)
        self.divergence_limit = self.diagonal * (1.0 if self.method == "explicit" else 1e3)
        W, K = operator_parts(self.V0, self.F, self.laplacian, self.area)
        self._W0, self._K = W, K
        self.k_pb = self.pass_band * diagonal_scale(W, K)
        self.taubin_nu = self._nu_for(self.lam)
        fixed = (
            boundary_vertex_mask(self.F, self.n)
            if self.fix_boundary
            else np.zeros(self.n, dtype=bool)
        )
        self.pinned = fixed | ~(W > 0)  # fixed boundary, plus vertices with no faces / zero area
        self._free = np.flatnonzero(~self.pinned)
        self._fixed = np.flatnonzero(self.pinned)
        if len(self._fixed):
            self._K_free_rows = K[self._free].tocsr()  # rows of free vertices, all columns
            self._K_ff = self._K_free_rows[:, self._free].tocsr()
            self._K_fp = self._K_free_rows[:, self._fixed].tocsr()
        else:  # nothing pinned: the blocks are K itself (no copies of a large matrix)
            self._K_free_rows = self._K_ff = K
            self._K_fp = K[:, :0].tocsr()
        self._recompute_mass = self.mass_update == "recompute" and self.laplacian == "cotan"
        self._stability: Stability | None = None
        self._mu_min: tuple[float, bool] | None = None  # W and K are frozen: kept across λ
        self.n_factorizations = 0
        self._solver: ImplicitSolver | None = None
        self._solver_key: tuple[float, int] | None = None
        self._generation = 0  # bumped by reset: a prefetched solve of an older run is stale
        self._rhs_fixed: FloatArray | None = None
        self._explicit_cache: dict[float, sp.csr_matrix] = {}

    # ---------------------------------------------------------------- public state

    @property
    def V(self) -> FloatArray:
        """Current positions ``(n,3)`` (a read-only view; copy it to keep it)."""
        view = self._V.view()
        view.flags.writeable = False
        return view

    @property
    def stability(self) -> Stability:
        """Stability figures of this smoother on the input mesh (computed once, on first use)."""
        if self._stability is None:
            if self._mu_min is None:  # one eigensolve per stepper, whatever λ becomes
                self._mu_min = most_negative_eigenvalue(self._W0, self._K)
            mu_min, exact = self._mu_min
            self._stability = stability_from_mu(
                self.method,
                self.laplacian,
                self.lam,
                self.taubin_nu,
                mu_min,
                exact,
                self.k_pb,
            )
        return self._stability

    def prepare(self) -> None:
        """Do now the one-time work of the next step: the implicit system's factorization
        (nothing for the explicit and Taubin steppers, or when it is current), and start the
        helper that will take the solves over (:meth:`solver_report`), if planned. A caller
        that builds the stepper in a job calls it there, so that the first :meth:`step` on
        the window's thread is as cheap as the others."""
        if self.method == "implicit" and len(self._free) and not self.diverged:
            self._factorize(self._V)
            assert self._solver is not None
            self._solver.warm()  # an open-ended run's helper starts now

    def solver_report(self) -> dict[str, Any]:
        """Which factorization answers the implicit steps, since which step, and why
        (:meth:`ImplicitSolver.report`; ``answering`` is ``None`` with no linear system)."""
        if self._solver is None:
            why = "not factorized yet" if self.method == "implicit" else "no linear system"
            return {"answering": None, "reason": why, "handover_iteration": None}
        return self._solver.report()

    def solver_line(self) -> str:
        """:meth:`solver_report` in one line (the Smoothing panel's solver line)."""
        return self._solver.line() if self._solver else self.solver_report()["reason"]

    def wait_handover(self, timeout: float | None = None) -> bool:
        """Wait until the helper's factorization is ready (tests, benchmarks); False when no
        helper is at work. The next implicit step is then answered by it."""
        return self._solver is not None and self._solver.wait_handover(timeout)

    def close(self) -> None:
        """End the implicit solves' helper process, if any (also while it factorizes)."""
        if self._solver is not None:
            self._solver.close()
            self._solver, self._solver_key = None, None

    def set_lam(self, lam: float) -> None:
        """Change ``λ`` (and Taubin's ``ν`` if it was derived from it) without losing the state.

        The current positions, the iteration count and the history are kept; the next step
        starts from the current positions with the new ``λ``. The implicit system is
        refactorized on the next step; nothing else is recomputed. A diverged smoother resumes
        from its last good positions (the discarded step is not replayed). A bad ``λ`` raises
        :class:`MeshError` and changes nothing.
        """
        lam = check_lam(lam)
        if lam == self.lam:
            self.diverged = False
            return
        nu = self._nu_for(lam)
        self.lam = lam
        self.taubin_nu = nu
        self._stability = None
        self.diverged = False

    def divergence_message(self) -> str | None:
        """Why stepping stopped (``None`` unless :attr:`diverged`), with the largest stable ``λ``.

        Computing the largest stable ``λ`` may need an eigensolve (see :attr:`stability`).
        """
        if not self.diverged:
            return None
        limit = self.stability.max_stable_lam
        return (
            f"{self.method} smoothing diverged at iteration {self.iteration + 1}: the vertices "
            f"moved farther (RMS) than {self._limit_words()} or became "
            "non-finite (largest stable lam for this mesh: "
            + ("none found" if limit is None else f"{limit:.4g}")
            + f", lam is {self.lam:g})"
        )

    def reset(self) -> None:
        """Back to the input positions: iteration 0, history with the input's entry only.

        A frozen implicit factorization is kept.
        """
        self._V = self.V0.copy()
        self._W = self._W0
        self._generation = getattr(self, "_generation", 0) + 1
        self.iteration = 0
        self.diverged = False
        self.history_stride = 1
        self.history: list[dict[str, Any]] = []
        if self.track_history:
            self.history.append(self._entry(self._V, None, 0.0))

    def rewind(self, V: FloatArray, iteration: int) -> None:
        """Go back to the positions ``V (n,3)`` this smoother had at ``iteration`` (kept by the
        caller: a viewer stepping back); the history after it is dropped, ``λ`` and a frozen
        factorization kept, a divergence forgotten. ``rewind(V0, 0)`` is :meth:`reset`.

        Raises
        ------
        MeshError
            ``V`` is not ``(n,3)`` finite, or ``iteration`` is not an integer in
            ``[0, self.iteration]``; nothing changes.
        """
        whole = isinstance(iteration, (int, np.integer)) and not isinstance(iteration, bool)
        if not (whole and 0 <= int(iteration) <= self.iteration):
            problem = f"must be an integer in [0, {self.iteration}], got {iteration!r}"
            raise MeshError(problem, "iteration")
        V = as_vertices(V, "V")  # (a new array: the caller's is never kept)
        if V.shape != self.V0.shape:
            raise MeshError(f"has {len(V)} vertices but the mesh has {self.n}", "V")
        self._V, self.iteration, self.diverged = V, int(iteration), False
        if self.iteration == 0:
            self._W = self._W0  # (a recomputed mass starts again from the input's)
        if self.track_history:
            self.history = [e for e in self.history if e["iteration"] <= self.iteration]

    # ---------------------------------------------------------------- stepping

    def step(self) -> FloatArray:
        """Do one iteration and return the current positions (see :attr:`V`)."""
        if self.diverged:
            return self.V
        t0 = time.perf_counter()
        x = self._V
        if self._recompute_mass and self.iteration > 0:
            self._W = vertex_areas(x, self.F, self.area)  # type: ignore[arg-type]
        if self.method == "explicit":
            new = self._explicit(x, self.lam)
        elif self.method == "taubin":
            nu = self.taubin_nu if self.taubin_nu is not None else taubin_mu(self.lam, self.k_pb)
            new = self._explicit(self._explicit(x, self.lam), nu)
        else:
            new = self._implicit(x)
        if self.preserve_volume:
            new = self._rescale_volume(new)
        elapsed = time.perf_counter() - t0
        if self.method == "implicit" and self._solver is not None:
            elapsed += self._solver.hidden_s  # a solve the helper started ahead, counted whole
        start = self._V if self.track_history else None
        sums = displacement_sums(new, self.V0, start, self.reference)
        drift = math.sqrt(sums[0] / max(self.n, 1))
        if not drift <= self.divergence_limit:  # also catches NaN and inf
            self.diverged = True
            if self._solver is not None:
                self._solver.discard()  # a solve started from the discarded step
            return self.V
        old = self._V
        self._V = new
        self.iteration += 1
        if self.preserve_volume and self.method == "implicit" and self._solver is not None:
            # the next step's solve starts in the helper (once it has taken over) while this
            # step's figures are measured and the caller draws or publishes
            self._solver.prefetch(new[self._free], (self._generation, self.iteration))
        if self.track_history:
            self.history_stride = keep(
                self.history,
                self._entry(new, old, elapsed, sums),
                self.history_limit,
                self.history_samples,
                self.history_stride,
            )
        return self.V

    def run(
        self,
        n: int,
        *,
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> FloatArray:
        """Do ``n`` iterations (stops early if the iteration diverges); return the positions.

        ``n`` is at most :data:`~meshlap_core.smoothing.params.MAX_ITERS` per call.

        Parameters
        ----------
        n : int
        progress : callable, optional
            ``progress(fraction, message)`` before every iteration (``fraction`` = iterations
            done / ``n``); the message says when the implicit system is being factorized.
        cancel : threading.Event or callable, optional
            Checked before every iteration: once set (or returning ``True``) the run stops
            with :class:`~meshlap_core.errors.Cancelled`, keeping the iterations done.
        """
        n = check_iters(n, "n")
        planned, self._planned = self._planned, self.iteration + n
        try:
            for i in range(n):
                check_cancel(cancel, "smoothing")
                if progress is not None:
                    progress(i / n, self._progress_message(i, n))
                self.step()
                if self.diverged:
                    break
        finally:
            self._planned = planned
        if progress is not None:
            progress(1.0, f"smoothing: {self.iteration} iterations")
        return self.V

    def _progress_message(self, i: int, n: int) -> str:
        key = (self.lam, self.iteration if self._recompute_mass else -1)
        if self.method == "implicit" and (self._solver is None or self._solver_key != key):
            return (
                f"smoothing: factorizing W - lam K ({len(self._free):,} unknowns, "
                f"{solver_backend()})"
            )
        return f"smoothing: iteration {i + 1} of {n}"

    # ---------------------------------------------------------------- internals

    def _limit_words(self) -> str:
        """:attr:`divergence_limit` in words."""
        if self.method == "explicit":
            return f"the bounding-box diagonal {self.diagonal:.4g}"
        return f"1000 bounding-box diagonals ({self.divergence_limit:.4g})"

    def _nu_for(self, lam: float) -> float | None:
        """Taubin's ``ν`` for ``λ`` (``None`` for the other methods), with a useful message."""
        try:
            return resolve_nu(self.method, lam, self._nu_given, self.k_pb)
        except MeshError as exc:
            if exc.source != "pass_band":
                raise
            raise MeshError(
                f"Taubin's pass band k_PB = pass_band x mean(-L_ii) = {self.pass_band:g} x "
                f"{self.k_pb / self.pass_band:.3g} = {self.k_pb:.3g} must be below 1/lam = "
                f"{1.0 / lam:.3g}; use lam below {1.0 / self.k_pb:.3g} or a smaller pass band",
                "pass_band",
            ) from None

    def is_stable(self) -> bool:
        """Whether this smoother is stable (:attr:`stability`), from the cheap Gershgorin bound
        on ``μ_min`` when that settles it, so that no eigensolve is needed in the common case."""
        if self.method == "implicit":
            return True
        bound = gershgorin_mu_min(self._W0, self._K, self._W0 > 0)
        quick = stability_from_mu(
            self.method, self.laplacian, self.lam, self.taubin_nu, bound, False, self.k_pb
        )
        return True if quick.stable else self.stability.stable

    def _warn_if_unstable(self) -> None:
        """Warn about an unstable explicit/Taubin λ; cheap (Gershgorin) unless near the limit."""
        if self.is_stable():
            return
        msg = self.stability.message()
        if msg:
            warnings.warn(MeshWarning(msg), stacklevel=3)

    def _warn_if_ill_conditioned(self) -> None:
        """Warn when ``λ · max_i(−L_ii)`` exceeds :data:`~.stability.ILL_CONDITIONED`
        (:func:`~.stability.ill_conditioning`)."""
        if len(self._free):
            stiff = float(np.max(-self._K_ff.diagonal() / self._W0[self._free]))
            message = ill_conditioning(self.lam, stiff)
            if message:
                warnings.warn(MeshWarning(message), stacklevel=3)

    def _explicit_operator(self, lam: float) -> sp.csr_matrix:
        """``S = I + λ P W⁻¹K`` (``P`` zeroes pinned rows) for the frozen mass, cached per λ."""
        S = self._explicit_cache.get(lam)
        if S is None:
            scale = np.zeros(self.n)
            scale[self._free] = lam / self._W0[self._free]
            S = (sp.identity(self.n, format="csr") + sp.diags(scale) @ self._K).tocsr()
            S.sort_indices()
            if len(self._explicit_cache) >= 4:
                self._explicit_cache.clear()
            self._explicit_cache[lam] = S
        return S

    def _explicit(self, x: FloatArray, lam: float) -> FloatArray:
        if not self._recompute_mass:
            return self._explicit_operator(lam) @ x  # one sparse product per step
        new = x.copy()
        if len(self._free):
            Kx = self._K_free_rows @ x
            new[self._free] += (lam / self._W[self._free])[:, None] * Kx
        return new

    def _implicit(self, x: FloatArray) -> FloatArray:
        free = self._free
        if len(free) == 0:
            return x.copy()
        self._factorize(x)
        solver = self._solver
        assert solver is not None
        token = (self._generation, self.iteration)
        # the next step starts from this answer unchanged unless the volume is rescaled
        then = None if self.preserve_volume else (token[0], token[1] + 1)
        if len(self._fixed) == 0:  # nothing pinned: no gathers or scatters
            return solver.solve(x, token, then)
        new = x.copy()
        new[free] = solver.solve(x[free], token, then)
        return new

    def _factorize(self, x: FloatArray) -> None:
        """Factorize ``W − λK`` (free block) unless the current factor is for this ``λ`` (and,
        recomputing the mass, this iteration); ``x`` gives the pinned vertices' pull."""
        free = self._free
        key = (self.lam, self.iteration if self._recompute_mass else -1)
        if self._solver is not None and self._solver_key == key:
            return
        Wf = self._W[free]
        A = self._K_ff.copy()  # W − λK in place: K stores its diagonal, no new entries
        A.data *= -self.lam
        A.setdiag(A.diagonal() + Wf)
        spent, self._solver = self._solver, None  # refactorized in place (same pattern)
        reuse = None
        if spent is not None:
            spent.close()  # its helper ends (also in the middle of its factorization)
            reuse = spent.direct
        self._rhs_fixed = self.lam * (self._K_fp @ x[self._fixed]) if len(self._fixed) else None
        steps_left = None if self._planned is None else max(self._planned - self.iteration, 1)
        choice = "direct" if self._recompute_mass else self.implicit_solver
        try:
            self._solver = ImplicitSolver(
                A, Wf, self._rhs_fixed, steps_left=steps_left, choice=choice, reuse=reuse
            )
        except np.linalg.LinAlgError:
            stiff = float(np.max(-self._K_ff.diagonal() / Wf)) if len(free) else 0.0
            raise MeshError(
                f"the implicit system W - lam K cannot be factorized: lam = {self.lam:g} "
                f"times the stiffest vertex's -L_ii = {stiff:.3g} is {self.lam * stiff:.3g}, "
                "beyond double precision (use a smaller lam, or rescale the mesh; the cotan "
                "lam is in units of length²)",
                "lam",
            ) from None
        self._solver_key = key
        self.n_factorizations += 1

    def _rescale_volume(self, x: FloatArray) -> FloatArray:
        vol = signed_volume_unchecked(x, self.F, self._FT)
        v0 = self.volume0 or 0.0  # preserve_volume requires a closed mesh with volume != 0
        if vol == 0.0 or not math.isfinite(vol) or (vol > 0) != (v0 > 0):
            return x  # an inverted or flat mesh cannot be rescaled; leave it
        s = (v0 / vol) ** (1.0 / 3.0)
        free = self._free
        c = x[free].mean(axis=0)
        out = x.copy()
        out[free] = c + s * (x[free] - c)
        return out

    def _entry(
        self, x: FloatArray, old: FloatArray | None, elapsed: float, sums: Any = None
    ) -> dict[str, Any]:
        """The history entry of positions ``x`` (``old``: the step's start; ``sums``: their
        :func:`~.history.displacement_sums`, when :meth:`step` measured them)."""
        if sums is None:
            sums = displacement_sums(x, self.V0, old, self.reference)
        faces = (self.F, self._FT) if self.closed else None
        return step_entry(
            self.iteration,
            elapsed,
            x,
            sums,
            stepped=old is not None,
            faces=faces,
            volume0=self.volume0,
            reference=self.reference is not None,
        )
