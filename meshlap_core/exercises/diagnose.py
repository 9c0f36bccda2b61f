"""Name the likely mistake behind a wrong answer.

Every classic mistake is written as the wrong answer it produces (the task's own
:class:`~.tasks.Mistake` list, then the generic ones: sign flip, factor 2, factor ½).
A wrong answer is diagnosed as the first mistake whose wrong answer matches the student's on
*every* failing call (each mesh, each boundary rule): one mesh where two mistakes coincide (on a
single acute triangle clamping the cot weights changes nothing) cannot mislead the diagnosis.
Then, for an answer no classic mistake explains: a constant factor on every failing call
(``−2 ×`` the expected), and single precision (float32, or values that agree to a few digits
only). A student whose answer matches none gets no diagnosis, only the vertex, expected and got.

The checker's own verdicts have keys here too: a failed dependency, the sandbox's refusals, an
answer that is not numbers, the wrong shape, NaN at a triangle of zero area, a dense matrix on
the big mesh, a file that exits or writes on the checker's channel.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import scipy.sparse as sp

from . import references as refs
from .compare import COMPARE
from .meshes import Case
from .tasks import Args, Mistake, Task

Failure = tuple[Case, str, Args, Any]
"""One failing call: (mesh, label, arguments, the student's answer)."""
FEW_DIGITS_RTOL = 1e-4
"""An answer within this (relative to the answer's scale) but not within the task's tolerance
agrees to a few digits only: single precision somewhere, or a formula that loses digits."""
NICE_FACTORS = (-4.0, -3.0, -2.0, -0.5, -0.25, 0.25, 1 / 3, 3.0, 4.0, 2 * np.pi, 1 / (2 * np.pi))
DIAGNOSES: dict[str, str] = {
    "sign_flip": "sign flip: the answer is the negative of the expected one (our Laplacians are "
    "negative semidefinite, Δx = −2Hn, and the frequencies λ ≥ 0)",
    "factor_2": "factor 2: the answer is twice the expected one",
    "factor_half": "factor ½: the answer is half the expected one",
    "transposed": "transposed weights: row i must hold the weights of vertex i's neighbours",
    "cot_not_half": "cot instead of cot/2: the weight of edge ij is ½(cot α + cot β)",
    "row_normalised": "row-normalised weights: the cotangent stiffness is not divided by the "
    "row's weight sum (that is a different, non-symmetric operator)",
    "clamped_weights": "negative cot weights were clamped or made positive (abs): a non-Delaunay "
    "edge keeps its negative weight",
    "divided_by_area": "divided by the vertex area: this task asks for the integrated quantity "
    "(the stiffness C / the angle defect), not its pointwise density",
    "graph_not_normalised": "not normalised by the degree: L = D⁻¹A − I, not A − D",
    "voronoi_not_barycentric": "Voronoi (mixed) area instead of the barycentric ⅓ of each face",
    "barycentric_not_voronoi": "barycentric instead of Voronoi: the mass is the mixed Voronoi "
    "area of Meyer et al. 2003 (half/quarter of an obtuse triangle)",
    "not_divided_by_3": "face areas not divided by 3 (each vertex gets a third of each face)",
    "no_obtuse_rule": "pure circumcentric Voronoi cells: an obtuse triangle gives its obtuse "
    "corner half its area and the others a quarter (Meyer et al. 2003)",
    "missing_mass": "missing mass matrix: the pointwise Laplacian is M⁻¹C (and the implicit "
    "step solves (M − λC) x′ = M x)",
    "uniform_not_cotan": "uniform weights (the uniform Laplacian) used instead of the "
    "cotangent ones",
    "missing_boundary_term": "missing boundary term: a boundary vertex's angle sum is compared "
    "with π (rule 'pi'), not 2π",
    "wrong_boundary_rule": "the boundary rule argument was not applied (each rule gives another "
    "value at boundary vertices only)",
    "degrees": "degrees instead of radians",
    "wrong_orientation": "wrong orientation: the ring runs clockwise; (i, a, b) must be a face "
    "for consecutive neighbours a, b",
    "unordered": "the neighbours are not ordered around the vertex (sorted by index?)",
    "ordinary_eigenproblem": "ordinary instead of generalized eigenproblem: solve K u = λ M u "
    "(scipy eigsh(K, k, M=M, ...)), not K u = λ u",
    "not_m_orthonormal": "eigenvectors normalised in the Euclidean inner product: they must "
    "satisfy UᵀMU = I",
    "projection_without_mass": "Uᵀ X instead of Uᵀ M X: the basis is M-orthonormal, so the "
    "coefficients are Uᵀ M X",
    "explicit_not_implicit": "an explicit step: the implicit step solves (M − λC) x′ = M x",
    "mu_sign": "the μ step has the wrong sign: μ < 0 is given, step x + μ L x",
    "lambda_only": "only the λ step: Taubin applies a μ step after it",
    "not_sequential": "both steps from the old positions: the μ step applies L to the λ "
    "step's result",
    "gradient_not_normalised": "the heat gradient is not normalised: X = −∇u/|∇u| per face "
    "(a distance grows at unit speed, whatever the amount of heat)",
    "time_not_scaled": "the heat time is not scaled with the mesh: t = m·h² (h the mean edge "
    "length), not t = m; a mesh scaled by 250 must give 250 times the distance",
    "divergence_sign": "wrong sign of the divergence (or of X): the distance decreases away "
    "from the source; X = −∇u/|∇u| points away from it and K φ = Gᵀ A X",
    "not_shifted": "not shifted: the distance must be 0 at the source (subtract φ[source]); "
    "the Poisson solution is only defined up to a constant",
    "positions_not_displacement": "positions instead of the displacement: solve Δ²d = 0 for "
    "d = U − V (d given at the handles) and return V + d; solving for the positions smooths "
    "the surface's own details away",
    "biharmonic_without_mass": "no mass matrix between the two Laplacians: Δ² = M⁻¹C M⁻¹C, so "
    "the system is C M⁻¹ C d = 0 at the free vertices, not C C d = 0",
    "harmonic_not_biharmonic": "harmonic, not biharmonic: C d = 0 (Δd = 0) bends sharply at "
    "the handles; the task asks for Δ²d = 0 (C M⁻¹ C d = 0 at the free vertices)",
    "no_reflection_fix": "rotations without the reflection fix: where det(B Aᵀ) < 0 the best "
    "orthogonal fit is a reflection (a folded one-ring); negate the column of B of the "
    "smallest singular value, R = B diag(1, 1, det(B Aᵀ)) Aᵀ, so that det R = +1",
    "rotation_transposed": "the rotation is transposed: with S_i = Σ_j w_ij (p_i − p_j)(u_i − "
    "u_j)ᵀ = A Σ Bᵀ, R_i = B Aᵀ takes rest edges to current ones; A Bᵀ is its inverse",
    "rotation_not_averaged": "the right-hand side uses R_i alone: b_i = Σ_j (w_ij/2)(R_i + "
    "R_j)(p_i − p_j), each edge turned by the average of its two ends' rotations",
    "handles_not_placed": "the local step did not see the handles at their targets: set "
    "U[handles] = targets first, then fit the rotations",
    "boundary_by_index": "the boundary is spaced evenly by index (2πk/b): place loop[k] at the "
    "angle 2π s_k / L, s_k the loop's length from loop[0] to loop[k] (arc length)",
    "boundary_turned": "right up to a rotation or a mirror of the disk: loop[0] goes to (1, 0) "
    "and the loop runs counter-clockwise in the order given (a loop of your own that starts "
    "elsewhere, or runs backwards?)",
    "boundary_not_on_circle": "the boundary is not on the unit circle: every vertex of loop "
    "goes on the circle of radius 1 around the origin, by arc length",
    "no_area_term": "no area term: the Dirichlet energy alone, with both pins on the u axis, "
    "gives v = 0 everywhere (a map onto a line); LSCM minimizes E_D − A, L_C = diag(K, K) − Q_A",
    "area_sign": "the area term has the wrong sign (E_D + A): the map is mirrored, every face "
    "flipped; with the boundary half-edges' faces on their left, L_C = diag(K, K) − Q_A",
    "unpinned": "not pinned: the map collapses (the conformal energy is 0 for a map to a "
    "point) or the pins are not at pin_uv; fix both coordinates of both pins (4 unknowns) "
    "and solve for the others",
    "sized_by_faces": "the answer is sized by F.max()+1: a vertex in no face (the last one here) "
    "still has its row; use n = len(V)",
    "constant_factor": "a constant factor: the answer is {factor} × the expected one on every "
    "failing mesh (a ½ forgotten or doubled, a sign, a normalisation?)",
    "single_precision": "single precision: the answer is float32 (about 7 digits; the check "
    "needs float64's). Compute and return float64",
    "few_digits": "right to a few digits only (about 4–7): float32 somewhere in the "
    "computation, or a formula that loses digits on thin triangles (Heron's formula, "
    "arccos near 0 or π)",
    "wrong_shape": "the wrong shape (see the message): return the shape the template gives",
    "not_finite": "NaN or inf in the answer: a division by zero (an unguarded 1/area, 1/degree)",
    "nan_on_degenerate": "NaN or inf at a triangle of zero area (collinear corners): such a "
    "triangle adds nothing; guard the division by its area (np.divide(..., where=area > 0))",
    "complex_values": "complex numbers: the answer must be real (a symmetric solver — "
    "np.linalg.eigh, scipy eigsh —, not np.linalg.eig; no square root of a negative number)",
    "not_numbers": "not an array of numbers (see the message): return numpy arrays or "
    "scipy.sparse matrices",
    "no_answer": "no answer: the function returned nothing (a missing return?)",
    "dense_at_size": "a dense n×n array on the mesh of {n} vertices ({gigabytes:.1f} GB): out "
    "of memory or over the answer's size; build scipy.sparse matrices (COO triplets) and use "
    "sparse solvers",
    "failed_dependency": "your {dependency} fails, so {task} cannot pass: fix {dependency} first",
    "calls_exit": "your file calls sys.exit() or exit() ({what}): a check calls your functions "
    'and must not be ended; keep script code under `if __name__ == "__main__":`',
    "tampers": "your file wrote on the checker's own channel (its pipe to the checker): the "
    "rest of the file is not checked",
    "signals_process": "sends a signal to another process ({what}): a check runs your "
    "functions only",
    "uses_network": "uses the network ({what}): a check runs offline; compute from the "
    "arguments only",
    "native_calls": "calls C functions directly through ctypes ({what}): a check runs numpy, "
    "scipy and libigl code, not raw C calls",
    "imports_meshlap": "imports meshlap itself: the checker compares your answer with "
    "meshlap's, so calling it would check nothing; use numpy, scipy (and libigl)",
    "opens_window": "opens a window (polyscope, a GUI toolkit, an X/GL library): the checker "
    'runs without a screen; keep viewers and plots under `if __name__ == "__main__":`',
    "spawns_process": "starts a process (subprocess, os.system, multiprocessing, fork): a "
    "check runs your functions only",
    "outside_folder": "reads or writes outside your own folder: {what} (another submission, "
    "the reference, the system); a check reads and writes only beside your file",
    "hangs_at_import": "the file never finishes importing (a loop, a sleep or input() at "
    'module level?): put work inside the functions or under `if __name__ == "__main__":`',
    "too_slow": "far slower than the reference on this mesh (a time limit scaled to the "
    "reference's own time on the same mesh, on the same machine, was passed): a Python loop "
    "per entry, or dense matrices on a big mesh?",
    "slow_loop": "correct, but {seconds:.1f} s on {n} vertices, about {ratio:.0f}× the "
    "reference's time: a Python loop per vertex or per entry? build from arrays (np.bincount, "
    "COO triplets)",
}
"""Diagnosis key -> the sentence shown to the student."""


def _generic(task: Task) -> list[Mistake]:
    return [
        Mistake("sign_flip", lambda c, a: _scaled(task.reference(c, a), -1.0)),
        Mistake("factor_2", lambda c, a: _scaled(task.reference(c, a), 2.0)),
        Mistake("factor_half", lambda c, a: _scaled(task.reference(c, a), 0.5)),
    ]


def _scaled(x: Any, s: float) -> Any:
    return x * s


def candidates(task: Task) -> list[Mistake]:
    """The mistakes tried for ``task``, in order."""
    return list(task.mistakes) + (_generic(task) if task.generic else [])


def _same(task: Task, wrong: Any, expected: Any) -> bool:
    """The mistake makes no difference on this call (it cannot explain a failure there)."""
    if task.kind == "ring":
        return all(np.array_equal(w, e) for w, e in zip(wrong, expected, strict=True))
    if task.kind == "eigen":
        return np.allclose(wrong[0], expected[0]) and np.allclose(
            np.abs(wrong[1]), np.abs(expected[1])
        )
    if sp.issparse(wrong):
        return (abs(sp.csr_matrix(wrong) - expected)).max() == 0
    return np.array_equal(np.asarray(wrong), np.asarray(expected))


def _matches(task: Task, index: int, mistake: Mistake, failure: Failure) -> bool:
    case, label, args, got = failure
    wrong = refs.wrong(task, index, mistake, case, label, args)
    if wrong is None:
        return False
    expected = refs.expected(task, case, label, args)
    if _same(task, wrong, expected):
        return False
    if mistake.fits is not None:
        return mistake.fits(got, expected, case)
    if task.kind == "eigen":
        return _eigen_matches(mistake.key, got, wrong)
    return COMPARE[task.kind](got, wrong, case, task.power).ok


def _eigen_matches(key: str, got: Any, wrong: tuple[np.ndarray, np.ndarray]) -> bool:
    """Eigenvalues as the mistake gives them (and, for ``not_m_orthonormal``, columns of unit
    Euclidean length)."""
    try:
        lam, U = (np.asarray(x, dtype=np.float64) for x in got)
    except (TypeError, ValueError):
        return False
    lam_w = wrong[0]
    if lam.shape != lam_w.shape or U.ndim != 2 or U.shape[1] != len(lam_w):
        return False
    if not np.allclose(lam, lam_w, rtol=1e-5, atol=1e-8 * np.abs(lam_w).max()):
        return False
    if key == "not_m_orthonormal":
        return bool(np.allclose(np.linalg.norm(U, axis=0), 1.0, atol=1e-6))
    return True


def diagnose(task: Task, failures: Sequence[Failure]) -> str | None:
    """The key of the first mistake that explains every failing call, or None.

    Parameters
    ----------
    task : Task
    failures : sequence of (case, label, args, got)
        Every call the student failed (compared values, not crashes).
    """
    if not failures:
        return None
    for index, mistake in enumerate(candidates(task)):
        if all(_matches(task, index, mistake, f) for f in failures):
            return mistake.key
    return None


def _flat(x: Any) -> np.ndarray | None:
    try:
        a = x.toarray() if sp.issparse(x) else x
        return np.asarray(a, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        return None


def constant_factor(task: Task, failures: Sequence[Failure]) -> float | None:
    """The one factor ``c`` with ``got = c × expected`` on every failing call (within the
    task's tolerance), or None; a factor of 1 or 0 is no such mistake."""
    if task.kind not in ("matrix", "array") or not failures:
        return None
    factor = None
    for case, label, args, got in failures:
        e, g = _flat(refs.expected(task, case, label, args)), _flat(got)
        if e is None or g is None or e.shape != g.shape or not e.any():
            return None
        c = float(e @ g / (e @ e))
        nice = min(NICE_FACTORS, key=lambda f: abs(f - c))
        c = nice if abs(nice - c) <= 1e-9 * abs(c) else c
        if factor is not None and abs(c - factor) > 1e-6 * abs(factor):
            return None
        factor = c
        if not COMPARE[task.kind](got, _scaled(refs.expected(task, case, label, args), c),
                                  case, task.power).ok:  # fmt: skip
            return None
    return None if factor is None or abs(factor - 1.0) < 1e-6 or abs(factor) < 1e-12 else factor


def few_digits(task: Task, failures: Sequence[Failure]) -> bool:
    """Every failing call agrees with the reference to about :data:`FEW_DIGITS_RTOL`."""
    if task.kind not in ("matrix", "array") or not failures:
        return False
    for case, label, args, got in failures:
        e, g = _flat(refs.expected(task, case, label, args)), _flat(got)
        if e is None or g is None or e.shape != g.shape or not np.isfinite(g).all():
            return False
        finite = np.isfinite(e)
        scale = max(float(np.abs(e[finite]).max(initial=0.0)), case.scale**task.power)
        if np.abs(g[finite] - e[finite]).max(initial=0.0) > FEW_DIGITS_RTOL * scale:
            return False
    return True


def factor_text(c: float) -> str:
    """``−2``, ``½``, ``2π``... as the report writes a factor."""
    names = {0.5: "½", -0.5: "−½", 0.25: "¼", -0.25: "−¼", 1 / 3: "⅓", 2 * np.pi: "2π",
             1 / (2 * np.pi): "1/(2π)"}  # fmt: skip
    for value, name in names.items():
        if abs(c - value) <= 1e-12 * abs(value):
            return name
    return f"{c:.6g}".replace("-", "−")


def describe(key: str | None, **details: Any) -> str:
    """The sentence of diagnosis ``key`` (with ``details`` filled in), or ``""``."""
    if key is None:
        return ""
    text = DIAGNOSES[key]
    try:
        return text.format(**details) if "{" in text else text
    except (KeyError, IndexError, ValueError):
        return text.split(" ({")[0].split(" {")[0]
