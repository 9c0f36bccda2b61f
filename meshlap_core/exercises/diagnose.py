"""Name the likely mistake behind a wrong answer.

Every classic mistake is written as the wrong answer it produces (the task's own
:class:`~.tasks.Mistake` list, then the generic ones: sign flip, factor 2, factor ½).
A wrong answer is diagnosed as the first mistake whose wrong answer matches the student's on
*every* failing call (each mesh, each boundary rule): one mesh where two mistakes coincide (on a
single acute triangle clamping the cot weights changes nothing) cannot mislead the diagnosis.
A student whose answer matches none gets no diagnosis, only the vertex, expected and got.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import scipy.sparse as sp

from .compare import COMPARE
from .meshes import Case
from .tasks import Args, Mistake, Task

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
    "uniform_not_cotan": "uniform Laplacian used instead of the cotangent one",
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
    "sized_by_faces": "the answer is sized by F.max()+1: a vertex in no face (the last one here) "
    "still has its row; use n = len(V)",
    "opens_window": "opens a window (polyscope, a GUI toolkit, an X/GL library): the checker "
    'runs without a screen; keep viewers and plots under `if __name__ == "__main__":`',
    "spawns_process": "starts a process (subprocess, os.system, multiprocessing, fork): a "
    "check runs your functions only",
    "outside_folder": "opens a file outside the exercises file's folder (another submission, "
    "the reference, the system): a check reads and writes only beside your file",
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
    out = [
        Mistake("sign_flip", lambda c, a: _scaled(task.reference(c, a), -1.0)),
        Mistake("factor_2", lambda c, a: _scaled(task.reference(c, a), 2.0)),
        Mistake("factor_half", lambda c, a: _scaled(task.reference(c, a), 0.5)),
    ]
    return out


def _scaled(x: Any, s: float) -> Any:
    return x * s


def candidates(task: Task) -> list[Mistake]:
    """The mistakes tried for ``task``, in order."""
    return list(task.mistakes) + (_generic(task) if task.generic else [])


def _matches(task: Task, mistake: Mistake, case: Case, args: Args, got: Any) -> bool:
    wrong = mistake.wrong(case, args)
    if wrong is None:
        return False
    expected = task.reference(case, args)
    if task.kind == "ring":
        same = all(np.array_equal(w, e) for w, e in zip(wrong, expected, strict=True))
    elif task.kind == "eigen":
        same = np.allclose(wrong[0], expected[0]) and np.allclose(
            np.abs(wrong[1]), np.abs(expected[1])
        )
    elif sp.issparse(wrong):
        same = (abs(sp.csr_matrix(wrong) - expected)).max() == 0
    else:
        same = np.array_equal(np.asarray(wrong), np.asarray(expected))
    if same:  # the mistake makes no difference on this call: it cannot explain a failure
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


def diagnose(task: Task, failures: Sequence[tuple[Case, Args, Any]]) -> str | None:
    """The key of the first mistake that explains every failing call, or None.

    Parameters
    ----------
    task : Task
    failures : sequence of (case, args, got)
        Every call the student failed (compared values, not crashes).
    """
    if not failures:
        return None
    for mistake in candidates(task):
        if all(_matches(task, mistake, c, a, g) for c, a, g in failures):
            return mistake.key
    return None


def describe(key: str | None, **details: Any) -> str:
    """The sentence of diagnosis ``key`` (with ``details`` filled in), or ``""``."""
    if key is None:
        return ""
    return DIAGNOSES[key].format(**details) if details else DIAGNOSES[key]
