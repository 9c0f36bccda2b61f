"""Check a student's file: run it sandboxed, compare every answer, diagnose every failure.

>>> from meshlap_core.exercises import check_file            # doctest: +SKIP
>>> result = check_file("exercises.py", ["cotan_laplacian"])  # doctest: +SKIP
>>> print(result.format_text())                               # doctest: +SKIP
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

from ..errors import MeshError
from ..options import (
    EXERCISE_MEMORY_MB,
    EXERCISE_SLOW_MIN_SECONDS,
    EXERCISE_SLOW_RATIO,
    EXERCISE_TASKS,
    EXERCISE_TIMEOUT,
    check_choice,
)
from .compare import COMPARE, Comparison
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


def evaluate(task: Task, run: TaskRun, cases: dict[str, Case]) -> TaskResult:
    """Turn the worker's report of one task into a :class:`TaskResult` (compare, diagnose)."""
    if run.status != "ran":
        return TaskResult(
            task.name,
            run.status,
            case=run.case if run.status not in _STOPPED else "",
            label=run.label if run.status not in _STOPPED else "",
            message=_STOPPED.get(run.status, run.message),
            traceback=run.message if run.status in ("error", "memory", "import_error") else "",
        )
    failures: list[tuple[Case, Any, Any, Comparison, str]] = []
    first_fail: Comparison | None = None
    for case_name, label, answer, _seconds in run.calls:
        case = cases[case_name]
        args = dict(task.calls(case))[label]
        ref = task.reference(case, args)
        cmp = COMPARE[task.kind](answer, ref, case, task.power)
        if not cmp.ok:
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
        )  # fmt: skip
    ratio, seconds, n = _speed(task, run, cases)
    if ratio is not None and ratio >= EXERCISE_SLOW_RATIO and seconds >= EXERCISE_SLOW_MIN_SECONDS:
        return TaskResult(
            task.name, "failed", "large", diagnosis="slow_loop",
            diagnosis_text=describe("slow_loop", ratio=ratio, n=n), n_calls=len(run.calls),
            speed_ratio=ratio,
        )  # fmt: skip
    return TaskResult(task.name, "passed", n_calls=len(run.calls), speed_ratio=ratio)


def _speed(task: Task, run: TaskRun, cases: dict[str, Case]) -> tuple[float | None, float, int]:
    """(student time / reference time, student seconds, vertices) on the speed case."""
    if not task.speed or not run.ref_seconds:
        return None, 0.0, 0
    for case_name, _label, _answer, seconds in run.calls:
        if "speed" in cases[case_name].tags:
            return seconds / max(run.ref_seconds, 1e-9), seconds, len(cases[case_name].V)
    return None, 0.0, 0


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
