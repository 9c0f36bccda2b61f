"""Compare a student's answer with the reference at a tolerance that follows the mesh scale.

A quantity with units length^p on a mesh of mean edge length ``h`` passes when, at every vertex,
``|got − expected| ≤ EXERCISE_RTOL · max(max|expected|, h^p)`` (:mod:`meshlap_core.options`):
a copy of a mesh scaled by 250 is judged exactly like the original, and an all-zero answer (the
angle defect of a flat patch) is compared at the natural unit ``h^p`` instead of at zero.
Eigenvectors are compared without fixing their sign or their basis inside a repeated
eigenvalue's space: ``UᵀMU = I`` and the residual ``KU − MUΛ`` are checked instead.

An answer that cannot be compared value by value fails with a diagnosis key of its own
(``Comparison.key``): not numbers, complex numbers (never cast to real), the wrong shape, NaN or
inf (at a triangle of zero area: ``nan_on_degenerate``). An answer in single precision is
compared like any other, and marked (``low_precision``) for the diagnosis.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..options import DEGENERATE_REL, EXERCISE_EIGEN_RTOL, EXERCISE_RTOL, MASS_AREA
from .meshes import Case
from .plain import BadAnswer


@dataclass
class Comparison:
    """The outcome of one comparison.

    Attributes
    ----------
    ok : bool
    vertex : int or None
        The vertex (row) with the largest error.
    expected, got : Any
        That vertex's reference and student values (a row: ``[(column, value), ...]`` for a
        matrix, a number or a 3-vector, or a neighbour list).
    error, tol : float
        The largest error and the tolerance it was held to.
    difference : (n,) float or None
        Per-vertex student − reference (signed for a scalar, the row's largest magnitude
        otherwise): the difference map.
    message : str
        What is wrong when it is not a value (shape, type, NaN).
    """

    ok: bool
    vertex: int | None = None
    expected: Any = None
    got: Any = None
    error: float = 0.0
    tol: float = 0.0
    difference: np.ndarray | None = field(default=None, repr=False)
    message: str = ""
    structural: bool = False
    """The answer could not be compared value by value (type, shape, NaN)."""
    key: str | None = None
    """The diagnosis of a structural failure (:data:`.diagnose.DIAGNOSES`)."""
    low_precision: bool = False
    """The answer came in single (or half) precision."""


def _bad(message: str, vertex: int | None = None, key: str | None = None) -> Comparison:
    return Comparison(False, vertex, message=message, structural=True, key=key)


def _not_numbers(got: Any) -> Comparison | None:
    """The failure of an answer that is not real numbers, or None."""
    if isinstance(got, BadAnswer):
        return _bad(got.message, key=got.key)
    if isinstance(got, list):  # rings: integers, read one by one
        return None
    parts = got if isinstance(got, tuple) else (got,)
    if any(np.iscomplexobj(p.data if sp.issparse(p) else p) for p in parts if p is not None):
        return _bad(
            "complex numbers in the answer: it must be real (np.linalg.eig of a matrix taken "
            "as non-symmetric? a square root of a negative number?)",
            key="complex_values",
        )
    return None


def _single(*arrays: Any) -> bool:
    return any(getattr(a, "dtype", np.dtype(float)) in (np.float32, np.float16) for a in arrays)


def degenerate_vertices(case: Case) -> np.ndarray:
    """Vertices of the case's triangles of (numerically) zero area."""
    P = case.V[case.F]
    cross = np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    l2 = ((P - np.roll(P, 1, axis=1)) ** 2).sum(axis=(1, 2))
    return np.unique(case.F[cross <= DEGENERATE_REL * l2])


def _not_finite(case: Case, vertex: int) -> Comparison:
    if vertex in degenerate_vertices(case):
        return _bad(
            f"NaN or inf at vertex {vertex}, a corner of a triangle of zero area: such a "
            "triangle adds nothing (guard the division by its area)",
            vertex,
            "nan_on_degenerate",
        )
    return _bad("NaN or inf in the answer (a division by zero?)", vertex, "not_finite")


def _tolerance(ref_max: float, case: Case, power: int, rtol: float) -> float:
    return rtol * max(ref_max, case.scale**power)


def _shape(got_shape: tuple[int, ...], want: tuple[int, ...], case: Case) -> Comparison:
    text = f"shape {got_shape}, expected {want}"
    if len(case.F) and got_shape and got_shape[0] == int(case.F.max()) + 1 != len(case.V):
        text += " (sized by F.max()+1: vertices in no face still need their row; use len(V))"
        return _bad(text, key="sized_by_faces")
    if len(got_shape) == 2 and got_shape == want[::-1]:
        text += " (transposed)"
    return _bad(text, key="wrong_shape")


def as_matrix(x: Any) -> sp.csr_matrix:
    """A student's matrix as CSR float (sparse, dense, ``np.matrix`` or nested lists)."""
    if sp.issparse(x):
        return sp.csr_matrix(x, dtype=np.float64)
    a = np.asarray(x, dtype=np.float64)
    if a.ndim != 2:
        raise ValueError(f"a {a.ndim}-d array, expected a 2-d matrix")
    return sp.csr_matrix(a)


def _row(A: sp.csr_matrix, i: int, cols: np.ndarray) -> list[tuple[int, float]]:
    return [(int(j), float(A[i, j])) for j in cols]


def compare_matrix(got: Any, ref: sp.spmatrix, case: Case, power: int) -> Comparison:
    R = sp.csr_matrix(ref, dtype=np.float64)
    if (bad := _not_numbers(got)) is not None:
        return bad
    try:
        G = as_matrix(got)
    except (TypeError, ValueError) as exc:
        return _bad(f"returned {type(got).__name__}: {exc}", key="not_numbers")
    if G.shape != R.shape:
        return _shape(G.shape, R.shape, case)
    if not np.isfinite(G.data).all():
        rows = np.repeat(np.arange(G.shape[0]), np.diff(G.indptr))
        return _not_finite(case, int(rows[~np.isfinite(G.data)][0]))
    D = (G - R).tocsr()
    D.eliminate_zeros()
    rows = np.zeros(R.shape[0])
    if D.nnz:
        rows = np.asarray(abs(D).max(axis=1).toarray()).ravel()
    tol = _tolerance(float(abs(R).max()) if R.nnz else 0.0, case, power, EXERCISE_RTOL)
    i = int(np.argmax(rows)) if len(rows) else 0
    cols = np.union1d(R[i].indices, G[i].indices) if len(rows) else np.zeros(0, int)
    return Comparison(
        bool(rows.max(initial=0.0) <= tol), i, _row(R, i, cols), _row(G, i, cols),
        float(rows.max(initial=0.0)), tol, rows, low_precision=_single(got),
    )  # fmt: skip


def compare_array(got: Any, ref: np.ndarray, case: Case, power: int) -> Comparison:
    ref = np.asarray(ref, dtype=np.float64)
    if (bad := _not_numbers(got)) is not None:
        return bad
    try:
        g = np.asarray(got.toarray() if sp.issparse(got) else got, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        return _bad(f"returned {type(got).__name__}: {exc}", key="not_numbers")
    if g.shape != ref.shape and g.size == ref.size and ref.ndim == 1:
        g = g.reshape(ref.shape)  # an (n,1) column is the same answer
    if g.shape != ref.shape:
        return _shape(g.shape, ref.shape, case)
    finite = np.isfinite(ref)  # inf: a distance no path reaches (another component)
    if not np.isfinite(g[finite]).all():
        bad_g = np.where(finite, g, 0.0).reshape(len(g), -1)
        return _not_finite(case, int(np.flatnonzero(~np.isfinite(bad_g).all(axis=1))[0]))
    d = np.where(finite, g - np.where(finite, ref, 0.0), np.where(g == ref, 0.0, np.inf))
    d = d.reshape(len(ref), -1)
    rows = np.abs(d).max(axis=1) if d.size else np.zeros(len(ref))
    top = float(np.abs(ref[finite]).max(initial=0.0))
    tol = _tolerance(top, case, power, EXERCISE_RTOL)
    i = int(np.argmax(rows)) if len(rows) else 0
    diff = d[:, 0] if ref.ndim == 1 else rows
    diff = np.where(np.isfinite(diff), diff, top)  # the map shows an unmatched inf as the top
    show = (lambda a: float(a[i])) if ref.ndim == 1 else (lambda a: [float(x) for x in a[i]])
    ok = bool(rows.max(initial=0.0) <= tol)
    err = float(rows.max(initial=0.0))
    return Comparison(ok, i, show(ref), show(g), err, tol, diff, low_precision=_single(got))


def _same_ring(got: list[int], ref: list[int], closed: bool) -> bool:
    if len(got) != len(ref):
        return False
    if not closed or not ref:
        return got == ref
    k = got.index(ref[0]) if ref[0] in got else -1
    return k >= 0 and got[k:] + got[:k] == ref


def compare_ring(got: Any, ref: list[np.ndarray], case: Case, power: int) -> Comparison:
    from ..topology.rings import one_ring

    if (bad := _not_numbers(got)) is not None:
        return bad
    try:
        rings = [[int(j) for j in np.asarray(r).ravel()] for r in got]
    except (TypeError, ValueError, OverflowError) as exc:
        return _bad(f"returned {type(got).__name__}: {exc}", key="not_numbers")
    if len(rings) != len(ref):
        return _shape((len(rings),), (len(ref),), case)
    closed = ~one_ring(case.F, len(case.V)).boundary
    bad = [i for i in range(len(ref)) if not _same_ring(rings[i], ref[i].tolist(), bool(closed[i]))]
    diff = np.zeros(len(ref))
    diff[bad] = 1.0
    if not bad:
        return Comparison(True, difference=diff)
    i = bad[0]
    return Comparison(False, i, ref[i].tolist(), rings[i], float(len(bad)), 0.0, diff)


def compare_eigen(
    got: Any, ref: tuple[np.ndarray, np.ndarray], case: Case, power: int
) -> Comparison:
    from ..laplacian import cotan_stiffness, vertex_areas

    lam_ref, _ = ref
    if (bad := _not_numbers(got)) is not None:
        return bad
    try:
        lam, U = (np.asarray(x, dtype=np.float64) for x in got)
    except (TypeError, ValueError) as exc:
        return _bad(f"expected (lam, U), got {type(got).__name__}: {exc}", key="not_numbers")
    n, k = len(case.V), len(lam_ref)
    if lam.shape != (k,) or U.shape != (n, k):
        why = f"shapes {lam.shape}, {U.shape}; expected ({k},), ({n}, {k})"
        return _bad(why, key="wrong_shape")
    if not (np.isfinite(lam).all() and np.isfinite(U).all()):
        return _bad("NaN or inf in the answer", key="not_finite")
    tol = _tolerance(float(np.abs(lam_ref).max()), case, power, EXERCISE_EIGEN_RTOL)
    m = vertex_areas(case.V, case.F, MASS_AREA)
    if np.abs(lam - lam_ref).max() > tol:
        j = int(np.argmax(np.abs(lam - lam_ref)))
        err = float(np.abs(lam - lam_ref).max())
        diff = eigen_difference(U, ref[1], m, lam_ref)
        return Comparison(False, None, lam_ref.tolist(), lam.tolist(), err, tol, diff,
                          message=f"eigenvalue {j} differs")  # fmt: skip
    G = U.T @ (m[:, None] * U)
    ortho = float(np.abs(G - np.eye(k)).max())
    if ortho > 1e-5:
        got = f"max |UᵀMU − I| = {ortho:.3g}"
        why = "eigenvectors not M-orthonormal"
        diff = eigen_difference(U, ref[1], m, lam_ref)
        return Comparison(False, None, "UᵀMU = I", got, ortho, 1e-5, diff, message=why)
    K = -cotan_stiffness(case.V, case.F)
    R = (K @ U) - m[:, None] * U * lam_ref
    # K is dimensionless (cot weights), U has units 1/length: the residual is relative to |K||U|
    rows = np.abs(R).max(axis=1) / (abs(K).max() * np.abs(U).max())
    rtol = EXERCISE_EIGEN_RTOL * 10
    i = int(np.argmax(rows))
    ok = bool(rows[i] <= rtol)
    why = "" if ok else "the columns of U are not eigenvectors (K u ≠ λ M u)"
    return Comparison(ok, i, 0.0, float(rows[i]), float(rows[i]), rtol, rows, why)


def aligned_columns(
    U: np.ndarray, U_ref: np.ndarray, m: np.ndarray, lam_ref: np.ndarray | None = None
) -> np.ndarray:
    """``U`` turned towards the reference's basis: an eigenvector is defined up to its sign, and
    inside a repeated eigenvalue's space (``lam_ref`` equal within ``EXERCISE_EIGEN_RTOL``) up
    to a rotation, so each group of columns is multiplied by the orthogonal ``Q`` closest to
    ``U_gᵀ M U_ref,g`` (its polar factor, orthogonal Procrustes); a single column gets the sign
    of ``u_jᵀ M u_ref,j``. Neither choice is then shown as a mistake."""
    k = U.shape[1]
    lam = np.arange(k, dtype=float) if lam_ref is None else np.asarray(lam_ref, dtype=float)
    gap = EXERCISE_EIGEN_RTOL * max(float(np.abs(lam).max(initial=0.0)), 1.0) * 10
    out = np.array(U, dtype=float)
    start = 0
    for j in range(1, k + 1):
        if j < k and abs(lam[j] - lam[j - 1]) <= gap:
            continue
        g = slice(start, j)
        P, _, Wt = np.linalg.svd(U[:, g].T @ (m[:, None] * U_ref[:, g]))
        out[:, g] = U[:, g] @ (P @ Wt)
        start = j
    return out


def eigen_difference(
    U: np.ndarray, U_ref: np.ndarray, m: np.ndarray, lam_ref: np.ndarray | None = None
) -> np.ndarray:
    """Per vertex, the largest ``|u_j − u_ref,j|`` over the columns after
    :func:`aligned_columns`: the difference map of a wrong eigenbasis."""
    return np.abs(aligned_columns(U, U_ref, m, lam_ref) - U_ref).max(axis=1)


COMPARE = {
    "matrix": compare_matrix,
    "array": compare_array,
    "ring": compare_ring,
    "eigen": compare_eigen,
}
"""Task kind -> ``compare(got, ref, case, power) -> Comparison``."""
