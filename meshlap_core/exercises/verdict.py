"""From what the sandbox collected to a verdict: compare every answer with the reference (in
the checker's process), name the mistake, the speed line, a failed dependency.

A task passes only on answers it gave: every planned call must have one that matches. A task
whose calls were never answered has failed (``no_answer``), whatever the worker said.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any

import numpy as np

from . import references as refs
from .compare import COMPARE, Comparison
from .copies import parse_source
from .diagnose import constant_factor, describe, diagnose, factor_text, few_digits
from .meshes import Case
from .result import TaskResult
from .sandbox import TaskRun
from .speed import hot_loop, measure
from .tasks import TASKS, Task

_STOPPED = {
    "missing": "no function of this name in the file",
    "not_implemented": "not implemented yet (the stub raises NotImplementedError)",
}
DENSE_AT = 5000
"""A mesh this large or more: running out of memory there (and nowhere smaller) is a dense
n×n array."""


def _stopped(task: Task, run: TaskRun, cases: dict[str, Case]) -> TaskResult:
    """The verdict of a task the sandbox stopped (or never started)."""
    shows_traceback = ("error", "memory", "import_error", "refused")
    key, details = run.diagnosis, {"what": run.what or "?"}
    case = cases.get(run.case)
    if run.status == "memory" and case is not None and len(case.V) >= DENSE_AT:
        key, details = "dense_at_size", _dense_details(len(case.V))
    return TaskResult(
        task.name, run.status,
        case=run.case if run.status not in _STOPPED else "",
        label=run.label if run.status not in _STOPPED else "",
        diagnosis=key, diagnosis_text=describe(key, **details),
        message=_STOPPED.get(run.status, run.message),
        traceback=run.message if run.status in shows_traceback else "",
    )  # fmt: skip


def _dense_details(n: int) -> dict[str, Any]:
    return {"n": n, "gigabytes": n * n * 8 / 1e9}


def _missing_answers(run: TaskRun) -> list[tuple[str, str]]:
    answered = {(c, label) for c, label, _, _ in run.calls}
    return [p for p in run.planned if p not in answered]


def _no_answer(task: Task, run: TaskRun, lost: list[tuple[str, str]]) -> TaskResult:
    case, label = lost[0]
    text = describe("no_answer")
    why = f"no answer on mesh {case}: the task was not run to the end"
    return TaskResult(task.name, "failed", case, label, diagnosis="no_answer",
                      diagnosis_text=text, message=why, n_failed=len(lost),
                      n_calls=len(run.calls))  # fmt: skip


def _key_of(task: Task, failures: list, comparisons: list[Comparison]) -> tuple[str | None, dict]:
    """The diagnosis of the failing calls, and the details its sentence needs: the one
    structural key they all share, else the mistake that explains every failing value."""
    if all(c.structural for c in comparisons):
        keys = {c.key for c in comparisons}
        if len(keys) == 1 and None not in keys:
            key = keys.pop()
            return key, (_dense_details(len(failures[0][0].V)) if key == "dense_at_size" else {})
        return None, {}
    valued = [f for f, c in zip(failures, comparisons, strict=True) if not c.structural]
    key = diagnose(task, valued)
    if key is not None:
        return key, {}
    factor = constant_factor(task, valued)
    if factor is not None:
        return "constant_factor", {"factor": factor_text(factor)}
    if any(c.low_precision for c in comparisons):
        return "single_precision", {}
    if few_digits(task, valued):
        return "few_digits", {}
    return None, {}


def _also(comparisons: list[Comparison], cases: list[Case]) -> list[str]:
    """The structural failures beside a diagnosed wrong value: one line each, by mesh."""
    seen, out = set(), []
    for cmp, case in zip(comparisons, cases, strict=True):
        if cmp.structural and (cmp.key, case.name) not in seen:
            seen.add((cmp.key, case.name))
            out.append(f"also on mesh {case.name}: {cmp.message}")
    return out


def evaluate(
    task: Task,
    run: TaskRun,
    cases: dict[str, Case],
    kept: dict[str, Any] | None = None,
    *,
    require_speed: bool = False,
    source: Path | None = None,
) -> TaskResult:
    """Turn the sandbox's report of one task into a :class:`TaskResult`.

    Parameters
    ----------
    task : Task
    run : TaskRun
    cases : dict
        Mesh name -> Case (the battery and the extra meshes).
    kept : dict, optional
        Receives the reference answer of every call by mesh name (the viewer's mesh's is then
        not computed twice).
    require_speed : bool
        A slow right answer fails (``slow_loop``).
    source : Path, optional
        The student's folder (the slow loop is named from its files, parsed, never run).
    """
    if run.status != "ran":
        return _stopped(task, run, cases)
    failures, comparisons, notes = [], [], []
    for case_name, label, answer, _seconds in run.calls:
        case = cases[case_name]
        args = dict(refs.calls(task, case))[label]
        ref = refs.expected(task, case, label, args)
        if kept is not None:
            kept[case_name] = ref
        cmp = COMPARE[task.kind](answer, ref, case, task.power)
        reason = None if cmp.ok or task.not_judged is None else task.not_judged(case, args)
        if reason is not None:
            notes.append(reason)
        elif not cmp.ok:
            failures.append((case, label, args, answer))
            comparisons.append(cmp)
    if failures:
        return _failed(task, run, failures, comparisons, notes)
    lost = _missing_answers(run)
    if lost:
        return _no_answer(task, run, lost)
    return _passed(task, run, cases, notes, require_speed, source)


def _failed(task: Task, run: TaskRun, failures: list, comparisons: list, notes: list) -> TaskResult:
    key, details = _key_of(task, failures, comparisons)
    first = 0
    if key is not None and not all(c.structural for c in comparisons):
        first = next(i for i, c in enumerate(comparisons) if not c.structural)
        notes = notes + _also(comparisons, [f[0] for f in failures])
    (case, label, args, _), cmp = failures[first], comparisons[first]
    return TaskResult(
        task.name, "failed", case.name, label, cmp.vertex, cmp.expected, cmp.got,
        cmp.error, cmp.tol, key, describe(key, **details), cmp.message,
        n_failed=len(failures), n_calls=len(run.calls), difference=cmp.difference,
        picture=_picture(failures, comparisons, task), note="; ".join(notes),
        repro=(case, label, args),
    )  # fmt: skip


def _passed(task: Task, run: TaskRun, cases: dict[str, Case], notes: list[str],
            require_speed: bool, source: Path | None) -> TaskResult:  # fmt: skip
    speed = measure(run.speed, len(cases[task.speed_case].V))
    if speed is not None and speed.slow and source is not None:
        speed = type(speed)(**{**speed.to_dict(), "loop": hot_loop(run.hot, source)})
    if speed is not None and speed.slow and require_speed:
        text = describe("slow_loop", ratio=speed.low, n=speed.vertices, seconds=speed.seconds)
        return TaskResult(task.name, "failed", task.speed_case, diagnosis="slow_loop",
                          diagnosis_text=text, n_calls=len(run.calls), speed=speed,
                          speed_required=True, note="; ".join(notes))  # fmt: skip
    return TaskResult(task.name, "passed", n_calls=len(run.calls), speed=speed,
                      speed_required=require_speed, note="; ".join(notes))  # fmt: skip


def _picture(failures: list, comparisons: list[Comparison], task: Task) -> tuple | None:
    """(V, F, difference, mesh name, signed) of the largest failing mesh with a difference
    map (``signed``: a scalar per vertex, student − reference)."""
    pairs = zip(failures, comparisons, strict=True)
    shown = [(f[0], c) for f, c in pairs if c.difference is not None]
    if not shown:
        return None
    case, cmp = max(shown, key=lambda s: len(s[0].V))
    signed = task.kind == "array" and np.ndim(cmp.expected) == 0
    return case.V, case.F, cmp.difference, case.name, signed


# ---- a failed dependency -------------------------------------------------------------------


def calls_in_file(path: Path) -> dict[str, set[str]]:
    """For every top-level function of the student's file, the top-level functions it calls,
    directly or through others (the file is parsed, never run)."""
    tree = parse_source(path)
    if tree is None:
        return {}
    funcs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    direct = {
        name: {c.func.id for c in ast.walk(node)
               if isinstance(c, ast.Call) and isinstance(c.func, ast.Name) and c.func.id in funcs}
        for name, node in funcs.items()
    }  # fmt: skip
    reach: dict[str, set[str]] = {}
    for name in funcs:
        seen, todo = set(), list(direct[name])
        while todo:
            f = todo.pop()
            if f not in seen:
                seen.add(f)
                todo.extend(direct.get(f, ()))
        reach[name] = seen - {name}
    return reach


def name_dependencies(results: list[TaskResult], student: Path | None) -> None:
    """A failing task that calls (or is built from) another failing task names it: as its
    diagnosis when it has none, else in its note."""
    failed = {r.task for r in results if not r.passed and r.status not in ("missing",)}
    calls = calls_in_file(student) if student is not None else {}
    for r in results:
        if r.passed or r.status in ("missing", "not_implemented", "import_error"):
            continue
        called = [t for t in TASKS if t in calls.get(r.task, set())]
        used = called or (list(TASKS[r.task].uses) if r.diagnosis is None else [])
        broken = [d for d in used if d in failed and d != r.task]
        if not broken:
            continue
        text = describe("failed_dependency", dependency=broken[0], task=r.task)
        if r.diagnosis is None:
            r.diagnosis, r.diagnosis_text = "failed_dependency", text
        else:
            r.note = "; ".join(x for x in (r.note, text) if x)
