"""Check a student's file: run it sandboxed, compare every answer, diagnose every failure.

>>> from meshlap_core.exercises import check_file            # doctest: +SKIP
>>> result = check_file("exercises.py", ["cotan_laplacian"])  # doctest: +SKIP
>>> print(result.format_text())                               # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from ..laplacian import vertex_areas
from ..options import (
    EXERCISE_MEMORY_MB,
    EXERCISE_SLOW_MIN_SECONDS,
    EXERCISE_SLOW_RATIO,
    EXERCISE_TASKS,
    EXERCISE_TIMEOUT,
    MASS_AREA,
    check_choice,
)
from .compare import COMPARE, Comparison, aligned_columns, as_matrix
from .diagnose import describe, diagnose
from .meshes import Case, battery
from .result import CheckResult, TaskResult
from .sandbox import TaskRun, run_student
from .tasks import TASKS, Task

_STOPPED = {
    "missing": "no function of this name in the file",
    "not_implemented": "not implemented yet (the stub raises NotImplementedError)",
}


def _cases(extra: Sequence[Case]) -> dict[str, Case]:
    return {c.name: c for c in [*battery(), *extra]}


def evaluate(
    task: Task, run: TaskRun, cases: dict[str, Case], kept: dict[str, Any] | None = None
) -> TaskResult:
    """Turn the worker's report of one task into a :class:`TaskResult` (compare, diagnose);
    ``kept`` receives the reference answer of every call by mesh name (the viewer's mesh's is
    then not computed twice)."""
    if run.status != "ran":
        shows_traceback = ("error", "memory", "import_error", "refused")
        return TaskResult(
            task.name,
            run.status,
            case=run.case if run.status not in _STOPPED else "",
            label=run.label if run.status not in _STOPPED else "",
            diagnosis=run.diagnosis,
            diagnosis_text=describe(run.diagnosis),
            message=_STOPPED.get(run.status, run.message),
            traceback=run.message if run.status in shows_traceback else "",
        )
    failures: list[tuple[Case, Any, Any, Comparison, str]] = []
    first_fail: Comparison | None = None
    notes: list[str] = []
    for case_name, label, answer, _seconds in run.calls:
        case = cases[case_name]
        args = dict(task.calls(case))[label]
        ref = task.reference(case, args)
        if kept is not None:
            kept[case_name] = ref
        cmp = COMPARE[task.kind](answer, ref, case, task.power)
        reason = None if cmp.ok or task.not_judged is None else task.not_judged(case, args)
        if reason is not None:
            notes.append(reason)
        elif not cmp.ok:
            failures.append((case, args, answer, cmp, label))
            first_fail = first_fail or cmp
    if failures:
        case, args, answer, cmp, label = failures[0]
        valued = [(c, a, g) for c, a, g, cm, _ in failures if not cm.structural]
        key = diagnose(task, valued) if len(valued) == len(failures) else None
        if key is None and any("F.max()+1" in f[3].message for f in failures):
            key = "sized_by_faces"
        return TaskResult(
            task.name, "failed", case.name, label, cmp.vertex, cmp.expected, cmp.got,
            cmp.error, cmp.tol, key, describe(key), cmp.message,
            n_failed=len(failures), n_calls=len(run.calls), difference=cmp.difference,
            picture=_picture(failures, task), note="; ".join(notes),
        )  # fmt: skip
    ratio, seconds, n = _speed(task, run, cases)
    if ratio is not None and ratio >= EXERCISE_SLOW_RATIO and seconds >= EXERCISE_SLOW_MIN_SECONDS:
        return TaskResult(
            task.name, "failed", "large", diagnosis="slow_loop",
            diagnosis_text=describe("slow_loop", ratio=ratio, n=n, seconds=seconds),
            n_calls=len(run.calls), speed_ratio=ratio, note="; ".join(notes),
        )  # fmt: skip
    return TaskResult(
        task.name, "passed", n_calls=len(run.calls), speed_ratio=ratio, note="; ".join(notes)
    )


def _picture(failures: list[tuple[Case, Any, Any, Comparison, str]], task: Task) -> tuple | None:
    """(V, F, difference, mesh name, signed) of the largest failing mesh with a difference
    map (``signed``: a scalar per vertex, student − reference)."""
    shown = [(c, cm) for c, _, _, cm, _ in failures if cm.difference is not None]
    if not shown:
        return None
    case, cmp = max(shown, key=lambda s: len(s[0].V))
    signed = task.kind == "array" and np.ndim(cmp.expected) == 0
    return case.V, case.F, cmp.difference, case.name, signed


def _speed(task: Task, run: TaskRun, cases: dict[str, Case]) -> tuple[float | None, float, int]:
    """(student time / reference time, student seconds, vertices) on the speed case."""
    if not task.speed or run.speed is None:
        return None, 0.0, 0
    mine, ref = run.speed
    n = next((len(c.V) for c in cases.values() if "speed" in c.tags), 0)
    return mine / max(ref, 1e-9), mine, n


def check_file(
    path: str | os.PathLike,
    tasks: Sequence[str] | None = None,
    *,
    extra: Sequence[Case] = (),
    timeout: float = EXERCISE_TIMEOUT,
    memory_mb: int = EXERCISE_MEMORY_MB,
) -> CheckResult:
    """Check the student file ``path`` on ``tasks`` (all by default).

    The file runs in a spawned worker process with ``timeout`` seconds per task and
    ``memory_mb`` MiB of address space (:mod:`.sandbox`); this process only compares.

    Parameters
    ----------
    path : str or PathLike
        The student's Python file (``meshlap exercises init`` writes the template).
    tasks : sequence of str, optional
        Names from :data:`~meshlap_core.options.EXERCISE_TASKS`.
    extra : sequence of Case
        More meshes to check on (the viewer's).
    timeout : float
    memory_mb : int

    Returns
    -------
    CheckResult

    Raises
    ------
    MeshError
        The file does not exist, or an unknown task name.
    """
    names = list(EXERCISE_TASKS) if not tasks else [str(t) for t in tasks]
    for name in names:
        check_choice(name, EXERCISE_TASKS, "exercise", "--task")
    if not os.path.isfile(path):
        raise MeshError("no such file", os.fspath(path))
    runs = run_student(path, names, list(extra), timeout=timeout, memory_mb=memory_mb)
    cases = _cases(extra)
    results = [evaluate(TASKS[n], runs[n], cases) for n in names]
    return CheckResult(os.fspath(path), results)


@dataclass
class MeshCheck:
    """A task checked on the battery and on one more mesh (the viewer's), with the student's
    and the reference's whole answers on that mesh.

    Attributes
    ----------
    result : CheckResult
        The verdict (battery and this mesh).
    expected, got : Any
        Reference and student answers on the mesh (``got`` is None when the student's call
        failed there).
    difference : (n,) float or None
        Per vertex: student − reference (signed for a scalar per vertex, the largest magnitude
        of the row otherwise).
    signed : bool
    """

    result: CheckResult
    expected: Any
    got: Any
    difference: np.ndarray | None
    signed: bool

    def rows(self, vertex: int) -> list[tuple[str, str, str]]:
        """``(term, student, reference)`` for every entry of the vertex's row."""
        return vertex_rows(self.expected, self.got, vertex)


def _cell(value: Any) -> str:
    return "—" if value is None else f"{value:.6g}"


def _eigen_rows(expected: Any, got: Any, i: int) -> list[tuple[str, str, str]]:
    """Per eigenpair ``j``: ``λ_j`` and ``u_j[i]``, student beside reference."""
    lam_r, U_r = expected
    lam_g = U_g = None
    with contextlib.suppress(TypeError, ValueError):
        lam_g, U_g = (np.asarray(x, dtype=float) for x in got)
    if lam_g is None or U_g is None or lam_g.shape != lam_r.shape or U_g.shape != U_r.shape:
        lam_g = U_g = None
    out = []
    for j in range(len(lam_r)):
        out.append((f"λ{j}", _cell(None if lam_g is None else lam_g[j]), _cell(lam_r[j])))
        out.append((f"u{j}[{i}]", _cell(None if U_g is None else U_g[i, j]), _cell(U_r[i, j])))
    return out


def vertex_rows(expected: Any, got: Any, i: int) -> list[tuple[str, str, str]]:
    """The terms of vertex ``i``'s row: matrix entries ``[i,j]`` (the union of both rows'
    non-zeros), vector components, ring positions, or each eigenpair's ``λ_j`` and ``u_j[i]``."""
    if isinstance(expected, tuple):  # an eigenbasis (λ, U)
        return _eigen_rows(expected, got, i)
    if sp.issparse(expected):
        E = sp.csr_matrix(expected)
        G = None
        with contextlib.suppress(TypeError, ValueError):
            G = as_matrix(got) if got is not None else None
        if G is not None and G.shape != E.shape:
            G = None
        cols = E[i].indices if G is None else np.union1d(E[i].indices, G[i].indices)
        return [
            (f"[{i},{j}]", _cell(None if G is None else G[i, j]), _cell(E[i, j]))
            for j in sorted(int(c) for c in cols)
        ]
    if isinstance(expected, list):  # a ring
        mine = None
        with contextlib.suppress(TypeError, ValueError, IndexError):
            mine = [int(x) for x in np.asarray(got[i]).ravel()] if got is not None else None
        return [("ring", str(mine if mine is not None else "—"), str(expected[i].tolist()))]
    e = np.asarray(expected, dtype=float)
    g = None
    with contextlib.suppress(TypeError, ValueError):
        g = np.asarray(got, dtype=float).reshape(e.shape) if got is not None else None
    if e.ndim == 1:
        return [("value", _cell(None if g is None else g[i]), _cell(e[i]))]
    return [
        (
            "xyz"[c] if e.shape[1] == 3 else str(c),
            _cell(None if g is None else g[i, c]),
            _cell(e[i, c]),
        )
        for c in range(e.shape[1])
    ]


def check_on_mesh(
    path: str | os.PathLike,
    task: str,
    V: np.ndarray,
    F: np.ndarray,
    *,
    timeout: float = EXERCISE_TIMEOUT,
    memory_mb: int = EXERCISE_MEMORY_MB,
    cancel: Any = None,
) -> MeshCheck:
    """Check ``task`` of the student file on the battery and on the mesh ``(V, F)``; keep both
    whole answers on that mesh for the viewer's difference map and row inspector (``cancel``:
    an event or callable that stops the worker and raises ``Cancelled``)."""
    check_choice(task, EXERCISE_TASKS, "exercise", "task")
    if not os.path.isfile(path):
        raise MeshError("no such file", os.fspath(path))
    case = Case("your_mesh", np.asarray(V, float), np.asarray(F, np.int64), "the mesh on screen")
    t = TASKS[task]
    runs = run_student(path, [task], [case], timeout=timeout, memory_mb=memory_mb, cancel=cancel)
    kept: dict[str, Any] = {}
    result = CheckResult(os.fspath(path), [evaluate(t, runs[task], _cases([case]), kept)])
    (_, args), *_ = t.calls(case)
    expected = kept[case.name] if case.name in kept else t.reference(case, args)
    got = next((a for c, _, a, _ in runs[task].calls if c == case.name), None)
    difference, signed = None, False
    if got is not None:
        cmp = COMPARE[t.kind](got, expected, case, t.power)
        difference = cmp.difference
        signed = t.kind == "array" and np.ndim(expected) == 1
        if t.kind == "eigen":
            got = _aligned_eigen(got, expected, case)
    return MeshCheck(result, expected, got, difference, signed)


def _aligned_eigen(got: Any, expected: tuple[np.ndarray, np.ndarray], case: Case) -> Any:
    """The student's ``(λ, U)`` with U turned towards the reference's basis (signs, and
    rotations inside repeated eigenvalues: :func:`~.compare.aligned_columns`), so that the rows
    differ only where the vectors do; unchanged when it is not such a pair."""
    try:
        lam, U = (np.asarray(x, dtype=float) for x in got)
    except (TypeError, ValueError):
        return got
    if U.shape != expected[1].shape:
        return got
    m = vertex_areas(case.V, case.F, MASS_AREA)
    return lam, aligned_columns(U, expected[1], m, expected[0])
