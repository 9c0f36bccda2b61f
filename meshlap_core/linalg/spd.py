"""Symmetric positive definite sparse systems: factorize once, solve many right-hand sides.

``A = LLᵀ`` by CHOLMOD's supernodal Cholesky, reused for every ``solve``. Three back ends,
the first available one is used (:func:`solver_backend` names it):

* ``"cholmod"``: scikit-sparse (``sksparse.cholmod``) on the system's SuiteSparse with an
  optimised BLAS; the fastest factorization measured (2–3× cholespy's at 692k vertices; see
  ``docs/benchmarks.md``). Optional: ``pip install -e '.[fast]'`` after
  ``apt-get install libsuitesparse-dev libopenblas0-pthread gcc python3-dev`` (it builds
  against the system's SuiteSparse; :data:`FAST_SOLVER_HINT`).
* ``"cholespy"``: CHOLMOD bundled in a wheel with its reference BLAS (a dependency: always
  there).
* ``"superlu"``: SciPy's SuperLU, when neither is importable.

``MESHLAP_SOLVER=fallback`` in the environment skips scikit-sparse (the tests run both).
Used by implicit smoothing, whose system ``W − λK`` is factorized once per ``λ`` and solved
once per step.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import warnings
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .quiet import quiet_c_stdout

#: environment variable: ``fallback`` forces the pure-wheel back end (cholespy / SuperLU)
SOLVER_ENV = "MESHLAP_SOLVER"
CHOLMOD_MIN_N = 200_000
"""Below this many unknowns :class:`SPDSolver` keeps the bundled cholespy even when CHOLMOD
(scikit-sparse) is installed, unless ``MESHLAP_SOLVER=cholmod``: CHOLMOD's supernodal
factorization wins on scans (9.8 s against 22.5 s at 692k), but its solves for a few
right-hand sides are 2–4× slower (17–24 ms against 4–7 ms at 43k; 0.59 s against 0.19 s at
692k), and below this size the factorization takes about a second either way, so the live
smoother's steps decide (measured by ``benchmarks/bench_scale.py`` and ``bench_viewer.py``).
Above it, implicit smoothing answers the first step from CHOLMOD's factor and hands the later
ones to a cholespy factorization of the same system built in a helper process
(:mod:`meshlap_core.smoothing.implicit_solver`). Those solve times are CHOLMOD's
*supernodal* factor's; the heat method's own factors
(:mod:`meshlap_core.diffusion.geodesic`) call CHOLMOD directly and pick its *simplicial*
mode below 200k vertices (a click at 43k: 12–13 ms against libigl's 13–15 ms)."""
#: how to get the fast back end (README, "Fast solver")
FAST_SOLVER_HINT = (
    "apt-get install libsuitesparse-dev libopenblas0-pthread gcc python3-dev && "
    "pip install -e '.[fast]'"
)


#: smallest ratio ``D_k / A_kk`` (pivot over its diagonal entry) a CHOLMOD factor may have
PIVOT_RATIO = 64 * np.finfo(float).eps


_GIL_FREE = {"eigen": False}


def prefer_gil_free(on: bool = True) -> None:
    """Keep the eigensolver off CHOLMOD (scikit-sparse), whose factorizations and solves hold
    the GIL (about 0.3 s per factorization at 43k vertices, 10 s at 692k), for a process whose
    other threads must keep running meanwhile, such as a window computing an eigenbasis in a
    worker thread: the shift-invert factors then use QDLDL, which releases it. The
    implicit smoother's one factorization holds the GIL on every back end (cholespy too).

    Parameters
    ----------
    on : bool
        ``False`` restores the default (CHOLMOD whenever :func:`solver_backend` says so).
    """
    _GIL_FREE["eigen"] = bool(on)


def eigen_backend() -> str:
    """The ``LDLᵀ`` back end of the eigensolver: ``"cholmod"`` when :func:`solver_backend` is
    ``"cholmod"`` and :func:`prefer_gil_free` is off, else ``"qdldl"`` (SuperLU when that is
    missing)."""
    if solver_backend() == "cholmod" and not _GIL_FREE["eigen"]:
        return "cholmod"
    return "qdldl"


def solver_backend(n: int | None = None) -> str:
    """The sparse Cholesky back end :class:`SPDSolver` uses now (for ``n`` unknowns).

    Parameters
    ----------
    n : int, optional
        The system's size: below :data:`CHOLMOD_MIN_N` the bundled cholespy is used unless
        ``MESHLAP_SOLVER=cholmod``. ``None``: the back end of a large system.

    Returns
    -------
    name : {"cholmod", "cholespy", "superlu"}
        ``"cholmod"`` when scikit-sparse is installed, ``MESHLAP_SOLVER`` is not
        ``fallback`` and the system is large enough (or ``MESHLAP_SOLVER=cholmod``); else
        ``"cholespy"`` when importable; else ``"superlu"``.
    """
    choice = os.environ.get(SOLVER_ENV, "").strip().lower()
    if choice != "fallback" and importlib.util.find_spec("sksparse") is not None:
        if choice == "cholmod" or n is None or n >= CHOLMOD_MIN_N:
            return "cholmod"
    return "cholespy" if importlib.util.find_spec("cholespy") is not None else "superlu"


def solver_info() -> dict[str, Any]:
    """What ``meshlap info`` says about the solver: ``backend``, ``fast`` and ``hint``.

    Returns
    -------
    info : dict
        ``backend`` (:func:`solver_backend`), ``eigen_backend`` (:func:`eigen_backend`),
        ``fast`` (``True`` for CHOLMOD through scikit-sparse) and ``hint`` (how to install
        the fast one; ``None`` when active).
    """
    backend = solver_backend()
    fast = backend == "cholmod"
    return {
        "backend": backend,
        "eigen_backend": eigen_backend(),
        "fast": fast,
        "hint": None if fast else FAST_SOLVER_HINT,
    }


def surely_positive_definite(A: sp.csr_matrix, margin: float = 1e-8) -> bool:
    """True when the Jacobi-scaled ``D^-1/2 A D^-1/2`` is diagonally dominant by ``margin``.

    Then all its eigenvalues are at least ``margin`` (Gershgorin) and a Cholesky factorization
    cannot fail; ``False`` means "not proven" (the factorization may still succeed).

    Parameters
    ----------
    A : (n,n) scipy.sparse matrix
        Symmetric.
    margin : float

    Returns
    -------
    bool
    """
    d = A.diagonal()
    if len(d) == 0:
        return True
    if not np.all(d > 0):
        return False
    s = 1.0 / np.sqrt(d)
    B = sp.csr_matrix(A)
    B = sp.csr_matrix((np.abs(B.data), B.indices, B.indptr), shape=B.shape)
    off = s * (B @ s) - 1.0  # row sums of |D^-1/2 A D^-1/2| without its diagonal: one SpMV
    return bool(np.all(off <= 1.0 - margin))


class SPDSolver:
    """Sparse Cholesky factorization of a symmetric positive definite matrix, reused per solve.

    The back end is :func:`solver_backend`'s (CHOLMOD through scikit-sparse, else cholespy's
    CHOLMOD, else SciPy's SuperLU); ``self.backend`` names it. With cholespy, a matrix that is
    not provably positive definite (:func:`surely_positive_definite`) is factorized with the
    C standard output silenced (:func:`~meshlap_core.linalg.quiet.quiet_c_stdout`), so
    CHOLMOD's complaint never reaches the user's output.

    Parameters
    ----------
    A : (n,n) scipy.sparse matrix
        Symmetric positive definite (both triangles stored).
    backend : {"cholmod", "cholespy", "superlu"}, optional
        Default :func:`solver_backend`.
    reuse : SPDSolver, optional
        A solver no longer needed, of a matrix with the same sparsity pattern (another ``λ``,
        new areas): with CHOLMOD its factor is refactorized in place, keeping the symbolic
        analysis (the fill-reducing ordering, about a third of a factorization), so ``reuse``
        must not be used afterwards (whether this succeeds or raises).

    Raises
    ------
    numpy.linalg.LinAlgError
        When the factorization finds ``A`` not numerically positive definite (with CHOLMOD
        through scikit-sparse: when cholespy does too; ``self.backend`` then says which one
        factored).
    """

    def __init__(
        self, A: sp.spmatrix, backend: str | None = None, *, reuse: SPDSolver | None = None
    ) -> None:
        A = sp.csr_matrix(A)
        A.sum_duplicates()
        A.sort_indices()
        self.n = A.shape[0]
        self.backend = solver_backend(self.n) if backend is None else backend
        self._lu: Any = None
        self._chol: Any = None
        self._cholmod: Any = None  # a sksparse.cholmod.Factor
        self._pattern = (A.indptr, A.indices)
        if self.backend == "cholmod":
            same = (
                reuse is not None
                and reuse._cholmod is not None
                and np.array_equal(reuse._pattern[0], A.indptr)
                and np.array_equal(reuse._pattern[1], A.indices)
            )
            old = reuse._cholmod if same else None  # type: ignore[union-attr]
            if reuse is not None:
                reuse._cholmod = None  # spent, whatever happens below
            try:
                self._cholmod = _cholmod_factor(A, old)
                return
            except np.linalg.LinAlgError:
                # at the edge of double precision, whether a pivot comes out positive depends
                # on rounding: the bundled CHOLMOD is asked too before the matrix is refused,
                # so nothing the fallback factors is refused here
                self.backend = "cholespy"
        if self.backend == "superlu":
            self._lu = sla.splu(A.tocsc())
            return
        from cholespy import CholeskySolverD, MatrixType

        quiet = contextlib.nullcontext() if surely_positive_definite(A) else quiet_c_stdout()
        try:
            with quiet:
                self._chol = CholeskySolverD(
                    self.n,
                    np.ascontiguousarray(A.indptr, dtype=np.int32),
                    np.ascontiguousarray(A.indices, dtype=np.int32),
                    np.ascontiguousarray(A.data, dtype=np.float64),
                    MatrixType.CSR,
                )
        except ValueError:
            raise np.linalg.LinAlgError("the matrix is not numerically positive definite") from None

    def solve(self, B: np.ndarray) -> np.ndarray:
        """``X = A⁻¹ B`` for ``B`` of shape ``(n,)`` or ``(n,k)`` (``B`` is not modified)."""
        B = np.ascontiguousarray(B, dtype=np.float64)
        if self._cholmod is not None:
            return np.asarray(self._cholmod.solve_A(B))
        if self._chol is None:
            return self._lu.solve(B)
        X = np.empty_like(B)
        self._chol.solve(B, X)
        return X


def _cholmod_factor(A: sp.csr_matrix, reuse: Any = None) -> Any:
    """scikit-sparse's supernodal CHOLMOD ``LLᵀ`` of the symmetric ``A`` (its CSR arrays read
    as CSC: the same matrix, no copy): a ``sksparse.cholmod.Factor``; ``reuse``, a factor of
    the same pattern, is refactorized in place (its symbolic analysis kept)."""
    from sksparse.cholmod import CholmodError, CholmodWarning, analyze

    refused = np.linalg.LinAlgError("the matrix is not numerically positive definite")
    csc = sp.csc_matrix((A.data, A.indices, A.indptr), shape=A.shape)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", CholmodWarning)  # e.g. not positive definite
            # supernodal LLᵀ: fails unless definite
            factor = analyze(csc, mode="supernodal") if reuse is None else reuse
            factor.cholesky_inplace(csc)
    except (CholmodError, CholmodWarning):
        raise refused from None
    if not pivots_sound(A, factor):
        raise refused
    return factor


def pivots_sound(A: sp.csr_matrix, factor: Any) -> bool:
    """Whether a CHOLMOD ``factor`` of ``A`` may be trusted as positive definite: ``A`` is
    surely so (:func:`surely_positive_definite`), or every pivot is finite and above
    :data:`PIVOT_RATIO` times its own diagonal entry.

    The pivots are ``D`` (``diag(L)²`` for ``LLᵀ``): CHOLMOD only stops at a pivot ``≤ 0``
    (and simplicial ``LDLᵀ`` not even there), so a pivot that cancelled to round-off of its
    own diagonal entry (``W − λK`` with ``λ`` beyond double precision, where cholespy's
    reference BLAS happens to meet a negative one) is refused; relative to its own row, so
    components of very different scales are not refused. The pivots are read first (a
    diagonal's worth of work); the Gershgorin proof, a product with the whole matrix, only
    when one is small."""
    D = factor.D()  # in the factor's order P: pivot k eliminates row P[k]
    if np.all(np.isfinite(D)) and np.all(D > PIVOT_RATIO * A.diagonal()[factor.P()]):
        return True
    return surely_positive_definite(A)
