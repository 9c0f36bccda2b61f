"""The implicit step's linear solves: which factorization answers, and why.

One implicit step solves ``(W − λK)_ff x′ = W_f x_f + r`` (free rows; ``r = λK_fp x_p`` pulls
towards the pinned vertices). Two factorizations are at hand and neither wins twice:

* CHOLMOD through scikit-sparse (supernodal, on the system's OpenBLAS) *factorizes* fastest:
  at 692k unknowns 2–3× faster than cholespy (README, "Fast solver");
* cholespy *solves* fastest: its three-column back-substitution takes 0.10–0.12 s at 692k
  against 0.19–0.27 s for CHOLMOD's (same answer to 5e-15; ``benchmarks/
  bench_scan_smoothing.py`` measures both). CHOLMOD's other solve modes were measured too
  and do not close the gap: its simplicial ``LDLᵀ`` (also by converting the supernodal factor
  in place, 0.3 s) solves in 1.25–1.35× cholespy's time, one BLAS thread or three one-column
  solves change nothing, and a METIS ordering brings the simplicial solve to cholespy's
  only after a 10 s longer analysis.

So with CHOLMOD in use (scans of :data:`~meshlap_core.linalg.spd.CHOLMOD_MIN_N` unknowns and
more) the first step is answered from CHOLMOD's factor, and a cholespy factorization of the
same system is built meanwhile in a helper process
(:class:`~meshlap_core.linalg.remote_cholesky.RemoteCholesky`: both libraries hold the GIL
while they factorize, so a thread would stop the steps); once it is ready it answers every
later step and CHOLMOD's factor is dropped. The helper works on the symmetric scaling
``A′ = D A D``, ``D = W_f^-½``, iterating ``z ← A′⁻¹(z + D r)`` with ``x = D z``: the same
solution, and consecutive steps need no product with ``W`` in between, so the helper can
start the next step's solve the moment it has answered one (``then`` of
:meth:`ImplicitSolver.solve`, :meth:`ImplicitSolver.prefetch`) while the caller measures,
draws or publishes the last.

When the number of steps is known (``meshlap smooth --iters N``, :meth:`Smoother.run`), the
helper is started only if the steps left after the first would last longer than its
factorization (:data:`HANDOVER_RATIO` times CHOLMOD's); a run that ends first is answered by
CHOLMOD alone. An open-ended run (the window's *play*, a script calling ``step``) hands over.
:meth:`ImplicitSolver.report` says which factorization answers, since which step and why.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..linalg.blas import blas_threads, thread_controller
from ..linalg.common import FloatArray
from ..linalg.remote_cholesky import HelperError, RemoteCholesky
from ..linalg.spd import CHOLMOD_MIN_N, SPDSolver, solver_backend

SOLVER_CHOICES = ("auto", "direct", "handover")
"""``auto``: :func:`plan`'s choice; ``direct``: one factorization in this process, never a
helper; ``handover``: a cholespy helper takes over whenever it can start (any back end, any
size; for tests and comparisons)."""

HANDOVER_RATIO = 2.5
"""cholespy's factorization time over CHOLMOD's on the same system (22.5 against 9.8 s,
16.7 against 6.8 s at 692k, measured side by side): how long the helper is expected to take,
in units of the CHOLMOD factorization just measured."""

NAMES = {"cholmod": "CHOLMOD", "cholespy": "cholespy", "superlu": "SuperLU"}


def plan(
    backend: str, n: int, steps_left: int | None, choice: str = "auto"
) -> tuple[bool | None, str]:
    """Whether a cholespy helper should take over the solves of a system of ``n`` unknowns
    factorized by ``backend`` in this process, before any timing is known.

    Parameters
    ----------
    backend : {"cholmod", "cholespy", "superlu"}
        The in-process factorization's back end.
    n : int
    steps_left : int or None
        Steps still to take with this system (``None``: open-ended).
    choice : {"auto", "direct", "handover"}

    Returns
    -------
    handover : bool or None
        ``True``: start the helper now; ``False``: never; ``None``: decide after the first
        solve (:func:`worth_handover`, with the measured times).
    reason : str
    """
    if choice == "direct":
        return False, "one factorization in this process (asked for)"
    if choice == "handover":
        return True, "the helper takes over as soon as it is ready (asked for)"
    name = NAMES.get(backend, backend)
    if backend != "cholmod":
        if backend == "cholespy":
            return False, "cholespy's factorization answers every step (its solves are fastest)"
        return False, f"{name} (neither CHOLMOD nor cholespy is installed)"
    if n < CHOLMOD_MIN_N:
        return False, "CHOLMOD at every size (MESHLAP_SOLVER=cholmod)"
    if steps_left is not None and steps_left <= 1:
        return False, "CHOLMOD: one step asked for (its factorization is the fastest)"
    if steps_left is None:
        return True, (
            "CHOLMOD factorizes fastest and answers first; cholespy solves fastest and takes "
            "over once its factorization (in a helper process) is ready"
        )
    return None, "decided after the first step"


def worth_handover(steps_left: int, factor_s: float, solve_s: float) -> tuple[bool, str]:
    """Whether the helper is worth starting for ``steps_left`` more steps, given CHOLMOD's
    measured factorization (``factor_s``) and solve (``solve_s``) times: only if those steps
    would last longer than the helper's expected factorization
    (:data:`HANDOVER_RATIO` × ``factor_s``)."""
    busy = steps_left * solve_s
    needs = HANDOVER_RATIO * factor_s
    if busy > needs:
        return True, (
            f"{steps_left} more steps (about {busy:.1f} s with CHOLMOD's solves) outlast "
            f"cholespy's factorization (about {needs:.1f} s): it takes over once ready"
        )
    return False, (
        f"CHOLMOD answers all: the {steps_left} steps left end (about {busy:.2g} s) before "
        f"cholespy's factorization would be ready (about {needs:.2g} s)"
    )


class ImplicitSolver:
    """The factorization(s) of one implicit system and its solves (see the module docstring).

    Parameters
    ----------
    A : (f,f) scipy.sparse CSR
        ``W_f − λK_ff``, symmetric positive definite.
    w : (f,) float
        ``W_f`` (positive).
    r : (f,3) float, optional
        The constant pull of the pinned vertices (``None``: nothing pinned).
    steps_left : int or None
        Steps the caller means to take with this system (``None``: open-ended).
    choice : {"auto", "direct", "handover"}
    reuse : SPDSolver, optional
        A spent in-process factor of the same pattern (see
        :class:`~meshlap_core.linalg.spd.SPDSolver`).

    Raises
    ------
    numpy.linalg.LinAlgError
        The in-process factorization refuses ``A``.
    """

    def __init__(
        self,
        A: sp.csr_matrix,
        w: FloatArray,
        r: FloatArray | None = None,
        *,
        steps_left: int | None = None,
        choice: str = "auto",
        reuse: SPDSolver | None = None,
    ) -> None:
        self.A, self.w, self.r = A, w, r
        self.n = A.shape[0]
        t = time.perf_counter()
        self.direct: SPDSolver | None = SPDSolver(A, solver_backend(self.n), reuse=reuse)
        self.factor_s = time.perf_counter() - t
        self.backend = self.direct.backend
        self.helper: RemoteCholesky | None = None
        self.handover_at: int | None = None  # the first iteration the helper answered
        self.direct_solve_s: list[float] = []
        self.hidden_s = 0.0  # of the last solve, the time it ran before it was asked for
        self._steps_left = steps_left
        self._prefetched: Any = None  # the token of the solve the helper is working on
        self._d = 1.0 / np.sqrt(w)
        self._start, self.reason = plan(self.backend, self.n, steps_left, choice)
        self._blas: Any = None  # a cached thread controller (CHOLMOD's solves beside a helper)

    # ------------------------------------------------------------------ what answers
    @property
    def answering(self) -> str:
        """``"cholespy (helper)"`` once the helper has taken over, else the in-process back
        end (``"cholmod"``, ``"cholespy"``, ``"superlu"``)."""
        return "cholespy (helper)" if self.direct is None else self.backend

    def report(self) -> dict[str, Any]:
        """Which factorization answers, since when, why, and the measured times.

        Returns
        -------
        dict
            ``answering`` (:attr:`answering`), ``first`` (the in-process back end, which
            answered the first step), ``helper`` (``None``, ``"factorizing"``, ``"ready"``,
            ``"failed"``), ``handover_iteration`` (the first step the helper answered, or
            ``None``), ``reason``, ``factor_s`` (in-process), ``helper_factor_s``,
            ``solve_ms`` (median in-process solve, median helper solve, either ``None``),
            ``helper_solve_cpu_ms`` (the helper's median solve in CPU time).
        """
        h = self.helper
        helper_solves = h.solve_s if h is not None else []
        helper_cpu = h.solve_cpu_s if h is not None else []
        return {
            "answering": self.answering,
            "first": self.backend,
            "helper": None if h is None else h.state,
            "handover_iteration": self.handover_at,
            "reason": self.reason,
            "factor_s": self.factor_s,
            "helper_factor_s": None if h is None else h.factor_s,
            "solve_ms": {
                self.backend: _median_ms(self.direct_solve_s),
                "cholespy (helper)": _median_ms(helper_solves),
            },
            "helper_solve_cpu_ms": _median_ms(helper_cpu),
        }

    def line(self) -> str:
        """The report in one line (the Smoothing panel's solver line)."""
        rep = self.report()
        ms = rep["solve_ms"]
        first = NAMES.get(self.backend, self.backend)
        if self.direct is None:
            mine = ms["cholespy (helper)"]
            return (
                f"cholespy (helper process) since step {self.handover_at}: solve "
                + (f"{mine:.0f} ms" if mine is not None else "(timing)")
                + (f" vs {first} {ms[self.backend]:.0f} ms" if ms[self.backend] else "")
                + f" ({first} answered first: factorized in {self.factor_s:.1f} s)"
            )
        if rep["helper"] == "factorizing":
            return (
                f"{first} answers (factorized in {self.factor_s:.1f} s); cholespy is "
                "factorizing in a helper process and takes over when ready (faster solves)"
            )
        return f"{first}: {self.reason}"

    # ------------------------------------------------------------------ solves
    def solve(self, x: FloatArray, token: Any = None, then: Any = None) -> FloatArray:
        """The free rows after one step from the free rows ``x`` ``(f,3)``: ``A⁻¹(W_f x + r)``
        (a new array).

        ``token`` names this step (see :meth:`prefetch`); ``then``, the next step's, when it
        will start from this answer unchanged: the helper then starts that solve at once,
        before this answer is even copied out."""
        self._poll(token)
        if self.direct is None:
            try:
                return self._helper_solve(x, token, then)
            except HelperError as exc:  # the helper ended after taking over: factor again
                self._lost(str(exc))
        self._prefetched = None
        self.hidden_s = 0.0
        t = time.perf_counter()
        rhs = self.w[:, None] * x
        if self.r is not None:
            rhs += self.r
        assert self.direct is not None
        if self.helper is not None and self.backend == "cholmod":
            # the helper factorizes on one core: CHOLMOD's solve keeps to one BLAS thread
            # (its three-column solve gains nothing from a second, which would only contend)
            if self._blas is None:
                self._blas = thread_controller()
            with blas_threads(1, self._blas):
                out = self.direct.solve(rhs)
        else:
            out = self.direct.solve(rhs)
        self.direct_solve_s = [*self.direct_solve_s[-63:], time.perf_counter() - t]
        if self._start is None and self._steps_left is not None:  # decided now, measured
            self._start, self.reason = worth_handover(
                self._steps_left - 1, self.factor_s, self.direct_solve_s[-1]
            )
        self.warm()  # after the first answer: the helper never delays it
        return out

    def warm(self) -> None:
        """Start the helper now if the plan is to hand over (the first :meth:`solve` does it
        otherwise, once it has answered): a caller that builds the solver ahead of its first
        step (the window's stepper) calls it then."""
        if self._start and self.helper is None:
            self._start = False  # once
            self._start_helper()

    def prefetch(self, x: FloatArray, token: Any) -> None:
        """Start the next step's solve in the helper now (once it has taken over), from the
        free rows ``x`` ``(f,3)`` a step made and then changed (a volume-preserving rescale);
        the next :meth:`solve` with the same ``token`` takes it, any other discards it."""
        h = self.helper
        if self.direct is not None or h is None:
            return
        try:
            h.discard()
            h.submit(x / self._d[:, None], add=self.r is not None)
        except HelperError:
            return
        self._prefetched = token

    def discard(self) -> None:
        """Drop a solve started ahead (the step it was started from was discarded)."""
        if self.helper is not None and self._prefetched is not None:
            self.helper.discard()
        self._prefetched = None

    def _helper_solve(self, x: FloatArray, token: Any, then: Any) -> FloatArray:
        h = self.helper
        assert h is not None
        ahead = h.pending and token is not None and self._prefetched == token
        if not ahead:  # (a solve started ahead from other positions is dropped)
            h.discard()
            h.submit(x / self._d[:, None], add=self.r is not None)
        self._prefetched = None
        z = h.result()
        # a solve started ahead ran partly before this call: counted whole in the step's time
        self.hidden_s = max(0.0, h.solve_s[-1] - h.waited_s) if ahead and h.solve_s else 0.0
        if then is not None:  # the next solve starts now, from this answer as it is
            h.submit(None, add=self.r is not None)
            self._prefetched = then
        return self._d[:, None] * z

    def _poll(self, token: Any) -> None:
        """Hand over when the helper is ready; note a helper that failed."""
        h = self.helper
        if h is None or self.direct is None:
            return
        if h.ready():
            self.direct = None  # CHOLMOD's factor (hundreds of MB on a scan) goes
            self.handover_at = (token[-1] + 1) if isinstance(token, tuple) else None
        elif h.state == "failed":
            self.reason = f"{NAMES.get(self.backend, self.backend)} answers: {h.error}"
            h.close()
            self.helper = None

    def _lost(self, message: str) -> None:
        """The helper died after taking over: factorize in this process again."""
        if self.helper is not None:
            self.helper.close()
            self.helper = None
        t = time.perf_counter()
        self.direct = SPDSolver(self.A, self.backend)
        self.factor_s = time.perf_counter() - t
        self.reason = f"factorized again in this process: {message}"

    def _start_helper(self) -> None:
        try:
            shift = None if self.r is None else self._d[:, None] * self.r
            self.helper = RemoteCholesky(self.A, 3, shift, scale=self._d)
        except HelperError as exc:
            self.reason = f"{NAMES.get(self.backend, self.backend)} answers: {exc}"
            self.helper = None

    def wait_handover(self, timeout: float | None = None) -> bool:
        """Wait until the helper's factorization is ready (tests, benchmarks); the next
        :meth:`solve` then hands over. False when there is no helper or it failed."""
        return self.helper is not None and self.helper.wait_ready(timeout)

    def close(self) -> None:
        """End the helper (also in the middle of its factorization)."""
        if self.helper is not None:
            self.helper.close()
            self.helper = None
        self._prefetched = None


def _median_ms(times: list[float]) -> float | None:
    return float(np.median(times) * 1e3) if times else None
