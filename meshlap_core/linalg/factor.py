"""Sparse symmetric ``LDLᵀ`` factorizations with their inertia, and the shift-invert operator.

Sylvester's law of inertia: for ``PAPᵀ = LDLᵀ`` (no pivoting, ``D`` diagonal) the number of
negative eigenvalues of ``A`` is the number of negative entries of ``D``. Two back ends: QDLDL
(AMD ordering, the factorization of the OSQP solver) and SuperLU in symmetric mode without
pivoting as a fallback. Every factor is checked by a solve with a random right-hand side, so a
tiny pivot (a shift on an eigenvalue) is detected and the shift moved. :class:`SharedAnalysis`:
positive definite matrices of one pattern factorized from one symbolic analysis.

Mesh-free: matrices in, numbers out.
"""

from __future__ import annotations

import threading
import warnings
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .common import FloatArray, IntArray


class UnstableFactorization(Exception):
    """An LDLᵀ factorization that cannot be trusted (zero or tiny pivot)."""


class SymbolicOrdering:
    """The fill-reducing symmetric ordering shared by every ``LDLᵀ`` of one pencil.

    All shifted matrices ``A − σI`` have the same pattern, and SuperLU's minimum degree
    ordering depends on the pattern only, so it is computed once (on a fixed random
    relabelling: on the very regular numbering of subdivided meshes MMD takes 20× longer)
    and later factorizations skip it. Thread-safe.
    """

    def __init__(self, n: int) -> None:
        self.n = n
        self.perm: IntArray | None = None
        self.lock = threading.Lock()
        # CHOLMOD: a factor whose symbolic analysis (the METIS or AMD ordering and the
        # pattern of L) the other threads' first factorizations copy instead of redoing it
        self.cholmod: Any = None
        self.cholmod_pattern: tuple[IntArray, IntArray] | None = None


class SuperLUFactor:
    """SuperLU ``LDLᵀ`` of a symmetric matrix, with its inertia; see :func:`superlu_ldl_inertia`."""

    def __init__(self, lu: Any, perm: IntArray) -> None:
        self.lu, self.perm = lu, perm

    def solve(self, B: FloatArray) -> FloatArray:
        Y = self.lu.solve(np.ascontiguousarray(B[self.perm]))
        X = np.empty_like(Y)
        X[self.perm] = Y
        return X


def superlu_ldl_inertia(
    A: sp.csr_matrix, rng: np.random.Generator, ordering: SymbolicOrdering
) -> tuple[SuperLUFactor, int]:
    """SuperLU ``LDLᵀ`` of a symmetric matrix and the number of its negative eigenvalues.

    SuperLU in symmetric mode with ``diag_pivot_thresh=0`` permutes rows and columns alike
    and does not pivot, so ``PAPᵀ = L U`` with ``U = D Lᵀ`` and Sylvester's law of inertia
    gives ``#{λ(A) < 0} = #{U_ii < 0}``. A solve with a random right-hand side checks that no
    small pivot spoiled the factor.
    """
    n = A.shape[0]

    def factor(p: IntArray, spec: str) -> Any:
        try:
            return spla.splu(
                A[p][:, p].tocsc(),
                permc_spec=spec,
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError as exc:  # exactly singular
            raise UnstableFactorization(str(exc)) from None

    lu = None
    with ordering.lock:  # the first factorization orders; the others wait for its ordering
        perm = ordering.perm
        if perm is None:
            p0 = np.random.default_rng(12345).permutation(n)
            lu = factor(p0, "MMD_AT_PLUS_A")
            if not np.array_equal(lu.perm_r, lu.perm_c):
                raise UnstableFactorization("SuperLU pivoted")
            ordering.perm = p0[np.argsort(lu.perm_c)]
            ldl = SuperLUFactor(lu, p0)  # lu.solve applies SuperLU's own permutation
    if lu is None:
        assert perm is not None
        lu = factor(perm, "NATURAL")
        if not (np.array_equal(lu.perm_r, lu.perm_c) and np.array_equal(lu.perm_c, np.arange(n))):
            raise UnstableFactorization("SuperLU pivoted")
        ldl = SuperLUFactor(lu, perm)
    return ldl, checked_inertia(A, ldl, lu.U.diagonal(), rng)


def checked_inertia(A: sp.csr_matrix, ldl: Any, piv: FloatArray, rng: np.random.Generator) -> int:
    """The number of negative pivots of an ``LDLᵀ`` of ``A`` (its negative eigenvalues, by
    Sylvester's law of inertia), after checking the factor: no zero or non-finite pivot, and a
    solve with a random right-hand side accurate to ``1e-10`` (a tiny pivot spoils it).

    Raises
    ------
    UnstableFactorization
    """
    piv = np.asarray(piv)
    if not np.all(np.isfinite(piv)) or np.any(piv == 0):
        raise UnstableFactorization("zero pivot")
    b = rng.standard_normal(A.shape[0])
    x = ldl.solve(b)
    scale = abs(A).sum(axis=1).max() * np.abs(x).max() + np.abs(b).max()
    if not np.all(np.isfinite(x)) or np.abs(A @ x - b).max() > 1e-10 * scale:
        raise UnstableFactorization("inaccurate solve")
    return int(np.count_nonzero(piv < 0))


class QDLDLFactor:
    """``LDLᵀ`` of a symmetric matrix by QDLDL (AMD ordering, no pivoting), with its inertia.

    QDLDL (the factorization of the OSQP solver) factors ``PAPᵀ = LDLᵀ`` with ``D`` diagonal
    and no pivoting, so Sylvester's law of inertia gives ``#{λ(A) < 0} = #{D_ii < 0}``. It
    computes its own AMD ordering, factors 2–4× faster than SuperLU's ``LU`` (which does the
    work twice: ``L`` and ``U = DLᵀ``) and its solves release the GIL.
    """

    def __init__(self, solver: Any, pattern: tuple[IntArray, IntArray]) -> None:
        self.solver = solver
        self.pattern = pattern  # (indptr, indices) of the factored upper triangle

    def solve(self, B: FloatArray) -> FloatArray:
        if B.ndim == 1:
            return np.asarray(self.solver.solve(np.ascontiguousarray(B)))
        X = np.empty(B.shape, order="F")
        for c in range(B.shape[1]):
            X[:, c] = self.solver.solve(np.ascontiguousarray(B[:, c]))
        return X


def qdldl_inertia(
    A: sp.csr_matrix, rng: np.random.Generator, reuse: QDLDLFactor | None = None
) -> tuple[QDLDLFactor, int]:
    """QDLDL ``LDLᵀ`` of a symmetric matrix and the number of its negative eigenvalues; a
    solve with a random right-hand side checks that no small pivot spoiled the factor.

    ``reuse``: a factorization no longer needed of a matrix with the same pattern (another
    shift): refactored in place, skipping the AMD ordering and symbolic analysis (0.04 s
    instead of 0.1 s at 40k vertices).

    Raises
    ------
    ImportError
        ``qdldl`` is not installed (the caller falls back to SuperLU).
    UnstableFactorization
        A zero, tiny or non-finite pivot.
    """
    import qdldl

    U = sp.triu(A, format="csc")
    pattern = (U.indptr, U.indices)
    try:
        if (
            reuse is not None
            and np.array_equal(reuse.pattern[0], U.indptr)
            and np.array_equal(reuse.pattern[1], U.indices)
        ):
            solver = reuse.solver
            solver.update(U, upper=True)
        else:
            solver = qdldl.Solver(U, upper=True)
        _, D, _ = solver.factors()
    except (ValueError, RuntimeError) as exc:  # zero pivot
        raise UnstableFactorization(str(exc)) from None
    ldl = QDLDLFactor(solver, pattern)
    return ldl, checked_inertia(A, ldl, D, rng)


METIS_MIN_N = 150_000
"""From this many unknowns :func:`cholmod_inertia` orders with METIS's nested dissection
instead of CHOLMOD's default (AMD on meshes): its analysis costs more (12–16 s against
4–5 s at 692k vertices) but the factor has 27 % fewer entries (25.4M against 34.7M) and
each numeric factorization takes about half the time (11–16 s against 26–30 s, the same
run on a busy machine), which pays off from the second factorization of the pencil on
(the inertia check above ``λ_k`` reuses the analysis). On small meshes AMD is faster
(0.10 + 0.12 s against 0.55 + 0.19 s at 43k)."""


def ldl_backend(n: int) -> str:
    """The ``LDLᵀ`` back end :class:`ShiftInvert` tries first for ``n`` unknowns, with its
    ordering: ``"CHOLMOD (METIS)"``, ``"CHOLMOD (AMD)"`` or ``"QDLDL (AMD)"`` (SuperLU only if
    QDLDL fails)."""
    from .spd import eigen_backend

    if eigen_backend() == "cholmod":
        return f"CHOLMOD ({'METIS' if n >= METIS_MIN_N else 'AMD'})"
    return "QDLDL (AMD)"


class CholmodLDLFactor:
    """CHOLMOD's simplicial ``LDLᵀ`` (scikit-sparse) of a symmetric matrix, with its inertia;
    see :func:`cholmod_inertia`. Solves a block of right-hand sides in one call."""

    def __init__(self, factor: Any, pattern: tuple[IntArray, IntArray]) -> None:
        self.factor = factor
        self.pattern = pattern  # (indptr, indices) of the factored matrix

    def solve(self, B: FloatArray) -> FloatArray:
        return np.asarray(self.factor.solve_A(np.asarray(B, dtype=np.float64)))


def cholmod_inertia(
    A: sp.csr_matrix,
    rng: np.random.Generator,
    reuse: CholmodLDLFactor | None = None,
    ordering: SymbolicOrdering | None = None,
) -> tuple[CholmodLDLFactor, int]:
    """CHOLMOD simplicial ``LDLᵀ`` (no pivoting; AMD ordering, METIS from :data:`METIS_MIN_N`
    unknowns) of a symmetric matrix and the
    number of its negative eigenvalues (negative entries of ``D``, Sylvester), checked like
    :func:`qdldl_inertia`. Measured at 43k vertices: factorization 2× and 4-column solves
    3× faster than QDLDL's (which solves one column at a time).

    ``reuse``: a factor no longer needed of a matrix with the same pattern, refactorized in
    place (the symbolic analysis kept). ``ordering``: shared by the threads factoring shifts
    of one pencil; a thread without a factor to reuse starts from the analysis of the first
    one (``Factor.cholesky``: a new numeric factor, the symbolic one copied), so the
    analysis is done once per pencil (6 s of CPU with METIS at 692k, 0.1 s with AMD at 43k).

    Raises
    ------
    ImportError
        scikit-sparse is not installed, ``MESHLAP_SOLVER=fallback``, or
        :func:`~meshlap_core.linalg.spd.prefer_gil_free` is on (the caller falls back to
        QDLDL). CHOLMOD holds the GIL while it factors and solves.
    UnstableFactorization
        A zero, tiny or non-finite pivot.
    """
    from .spd import eigen_backend

    if eigen_backend() != "cholmod":
        raise ImportError("CHOLMOD (scikit-sparse) is not in use (or prefer_gil_free is on)")
    from sksparse.cholmod import CholmodError, CholmodWarning, analyze

    csc = sp.csc_matrix((A.data, A.indices, A.indptr), shape=A.shape)  # symmetric: A itself
    pattern = (A.indptr, A.indices)
    same = (
        reuse is not None
        and np.array_equal(reuse.pattern[0], A.indptr)
        and np.array_equal(reuse.pattern[1], A.indices)
    )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", CholmodWarning)
            if same:
                factor = reuse.factor  # type: ignore[union-attr]
                factor.cholesky_inplace(csc)
            elif (base := _shared_analysis(ordering, pattern)) is not None:
                factor = base.cholesky(csc)
            else:
                order = "metis" if A.shape[0] >= METIS_MIN_N else "default"
                factor = analyze(csc, mode="simplicial", ordering_method=order)
                factor.cholesky_inplace(csc)
                if ordering is not None:
                    with ordering.lock:
                        if ordering.cholmod is None:
                            ordering.cholmod, ordering.cholmod_pattern = factor, pattern
            D = factor.D()
    except (CholmodError, CholmodWarning) as exc:
        raise UnstableFactorization(str(exc)) from None
    ldl = CholmodLDLFactor(factor, pattern)
    return ldl, checked_inertia(A, ldl, D, rng)


def _shared_analysis(ordering: SymbolicOrdering | None, pattern: tuple[IntArray, IntArray]) -> Any:
    """The CHOLMOD factor of ``ordering`` whose analysis fits ``pattern``, else ``None``."""
    if ordering is None:
        return None
    with ordering.lock:
        base, known = ordering.cholmod, ordering.cholmod_pattern
    if base is None or known is None:
        return None
    if np.array_equal(known[0], pattern[0]) and np.array_equal(known[1], pattern[1]):
        return base
    return None


class ShiftInvert:
    """``Op(Y) = (A − σI)⁻¹ Y`` for the scaled pencil ``A = M^-½ K M^-½`` (symmetric, same
    eigenvalues ``λ`` as ``K u = λ M u`` with ``y = M^½ u``); ``Op`` has eigenvalues
    ``θ = 1/(λ − σ)``.

    ``LDLᵀ`` without pivoting (CHOLMOD when scikit-sparse is in use, else QDLDL, else SuperLU
    in symmetric mode) with its inertia:
    ``n_below`` is the number of eigenvalues ``λ < σ``. A shift that lands (numerically) on an
    eigenvalue (zero or tiny pivot, inaccurate solve) is moved by a small fraction of
    ``spacing``: a singular matrix is never used.
    """

    def __init__(
        self,
        A: sp.csr_matrix,
        sigma: float,
        *,
        rng: np.random.Generator,
        spacing: float,
        ordering: SymbolicOrdering | None = None,
        reuse: Any | None = None,
    ) -> None:
        n = A.shape[0]
        eye = sp.identity(n, format="csr")
        if ordering is None:
            ordering = SymbolicOrdering(n)
        for attempt in range(6):
            s = sigma + (0.0 if attempt == 0 else (-1) ** attempt * 1e-3 * attempt * spacing)
            S = (A - s * eye).tocsr()
            try:
                r, reuse = reuse, None
                try:
                    c = r if isinstance(r, CholmodLDLFactor) else None
                    self.factor, self.n_below = cholmod_inertia(S, rng, c, ordering)
                except ImportError:  # (an unstable CHOLMOD factor moves the shift)
                    try:
                        q = r if isinstance(r, QDLDLFactor) else None
                        self.factor, self.n_below = qdldl_inertia(S, rng, q)
                    except (ImportError, UnstableFactorization):
                        self.factor, self.n_below = superlu_ldl_inertia(S, rng, ordering)
                sigma = s
                break
            except UnstableFactorization:
                continue
        else:
            raise RuntimeError(f"could not factor A - sigma I near sigma = {sigma:.6g}")
        self.sigma = float(sigma)

    def __call__(self, Y: FloatArray, out: FloatArray) -> None:
        out[...] = self.factor.solve(Y)


class SharedAnalysis:
    """Cholesky factors of several symmetric positive definite matrices with one sparsity
    pattern, from one symbolic analysis.

    With CHOLMOD (scikit-sparse) the fill-reducing ordering and the pattern of ``L``
    (``analyze``, a third to a half of a factorization) are computed once, on the first
    :meth:`factor`, and each factor starts from a copy of that analysis
    (``Factor.cholesky``): only the numeric factorization is repeated. A matrix with rows
    and columns pinned to the identity keeps the pattern when its removed entries are stored
    as explicit zeros (see :func:`pinned_data`). Other back ends (cholespy, SuperLU) factorize
    each matrix with :class:`~meshlap_core.linalg.spd.SPDSolver`.

    Parameters
    ----------
    indptr, indices : (n+1,) int, (nnz,) int
        The CSR pattern of the symmetric matrices (both triangles, sorted, each entry once;
        read as CSC it is the same matrix).
    backend : {"cholmod", "cholespy", "superlu"}, optional
        Default :func:`~meshlap_core.linalg.spd.solver_backend`.
    mode : {"supernodal", "simplicial"}
        CHOLMOD's factorization (supernodal ``LLᵀ`` or simplicial ``LDLᵀ``).
    """

    def __init__(
        self,
        indptr: IntArray,
        indices: IntArray,
        backend: str | None = None,
        mode: str = "supernodal",
    ) -> None:
        from .spd import solver_backend

        self.n = len(indptr) - 1
        self.indptr, self.indices = indptr, indices
        self.backend = solver_backend() if backend is None else backend
        self.mode = mode
        self._base: Any = None  # the analysed, never factored, CHOLMOD factor
        self.lock = threading.Lock()

    def matrix(self, data: FloatArray) -> sp.csr_matrix:
        """The CSR matrix of this pattern with the values ``data`` ``(nnz,)`` (no copy)."""
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))

    def factor(self, data: FloatArray) -> Any:
        """A solver (``.solve(B)``, ``.backend``) for the matrix of this pattern with the
        values ``data``: CHOLMOD from the shared analysis; if CHOLMOD refuses the matrix or
        another back end is in use, :class:`~meshlap_core.linalg.spd.SPDSolver`.

        Raises
        ------
        numpy.linalg.LinAlgError
            The matrix is not numerically positive definite (as ``SPDSolver`` raises it).
        """
        from .spd import SPDSolver

        A = self.matrix(data)
        if self.backend == "cholmod":
            factor = self._cholmod(A)
            if factor is not None:
                return CholmodSPDFactor(factor)
        return SPDSolver(A, self.backend)

    def _cholmod(self, A: sp.csr_matrix) -> Any:
        """CHOLMOD's factor of ``A`` from the shared analysis, or ``None`` when refused."""
        from sksparse.cholmod import CholmodError, CholmodWarning, analyze

        from .spd import pivots_sound

        csc = sp.csc_matrix((A.data, A.indices, A.indptr), shape=A.shape)  # symmetric
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", CholmodWarning)
                with self.lock:
                    if self._base is None:
                        self._base = analyze(csc, mode=self.mode)
                    base = self._base
                factor = base.cholesky(csc)
        except (CholmodError, CholmodWarning):
            return None
        return factor if pivots_sound(A, factor) else None  # the rule SPDSolver applies


class CholmodSPDFactor:
    """A CHOLMOD factor of a positive definite matrix made by :class:`SharedAnalysis`."""

    backend = "cholmod"

    def __init__(self, factor: Any) -> None:
        self.factor = factor

    def solve(self, B: FloatArray) -> FloatArray:
        """``X = A⁻¹ B`` for ``B`` of shape ``(n,)`` or ``(n,k)`` (``B`` is not modified)."""
        return np.asarray(self.factor.solve_A(np.ascontiguousarray(B, dtype=np.float64)))


def pinned_data(
    indptr: IntArray, indices: IntArray, data: FloatArray, pinned: IntArray
) -> FloatArray:
    """The values of a symmetric CSR matrix with the rows and columns ``pinned`` decoupled:
    their off-diagonal entries set to explicit zeros (the pattern kept, so one
    :class:`SharedAnalysis` serves both), their diagonal entries kept. A solve with a
    right-hand side that is 0 at ``pinned`` is 0 there and, elsewhere, the solve of the
    matrix restricted to the other rows and columns (a Dirichlet condition).

    Parameters
    ----------
    indptr, indices, data : the CSR arrays (sorted, the diagonal stored)
    pinned : (p,) int

    Returns
    -------
    data : (nnz,) float
        A new array.
    """
    n = len(indptr) - 1
    mask = np.zeros(n, bool)
    mask[pinned] = True
    rows = np.repeat(np.arange(n), np.diff(indptr))
    out = np.array(data, dtype=np.float64)
    out[(mask[rows] | mask[indices]) & (rows != indices)] = 0.0
    return out
