"""Run a student's file in a separate process with a time and a memory limit.

The worker is a ``multiprocessing`` *spawn* child: a fresh interpreter that imports the student
file, calls each task's function on the battery and sends every answer back through a pipe. The
checker's process never runs student code, so nothing the student does can break it:

- an infinite loop: the task's deadline passes, the worker is killed, the task is reported
  ``timeout`` and a new worker continues with the next task;
- a 50 GB allocation: the worker's address space is limited (``resource.setrlimit(RLIMIT_AS)``,
  the worker's own size plus a budget), the allocation raises ``MemoryError``: ``memory``;
- a crash (``os._exit``, a segfault in an extension): ``crashed``, then the next task;
- an exception: ``error`` with the traceback frames of the student's file only;
- an import of meshlap itself (which would return the reference): refused (:mod:`.guard`).

The answers are compared with the reference in the checker's process (:mod:`.check`).
"""

from __future__ import annotations

import contextlib
import importlib.util
import multiprocessing
import os
import pickle
import sys
import time
import traceback
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from typing import Any

from ..errors import Cancel, check_cancel
from ..options import EXERCISE_MEMORY_MB, EXERCISE_TIMEOUT
from . import guard
from .meshes import Case, battery

STUDENT_MODULE = "student_exercises"
"""The module name the student's file is imported as in the worker."""


@dataclass
class TaskRun:
    """What the worker reported for one task.

    Attributes
    ----------
    status : str
        ``"ran"`` (every call returned), ``"missing"``, ``"not_implemented"``, ``"error"``,
        ``"timeout"``, ``"memory"``, ``"crashed"`` or ``"import_error"``.
    calls : list of (case name, label, answer, seconds)
    message : str
        The student's traceback (their file's frames only) or what stopped the task.
    case, label : str
        The call that raised or was stopped.
    speed : (float, float) or None
        Student and reference seconds on the large case, measured side by side in the worker
        (:func:`_speed`).
    """

    status: str = "ran"
    calls: list[tuple[str, str, Any, float]] = field(default_factory=list)
    message: str = ""
    case: str = ""
    label: str = ""
    speed: tuple[float, float] | None = None


def student_traceback(exc: BaseException, path: str) -> str:
    """The traceback of ``exc`` restricted to the frames of the student's file ``path``."""
    target = os.path.realpath(path)
    frames = [
        f for f in traceback.extract_tb(exc.__traceback__) if os.path.realpath(f.filename) == target
    ]
    lines = ["Traceback (your file only):\n", *traceback.format_list(frames)]
    lines += traceback.format_exception_only(type(exc), exc)
    return "".join(lines).rstrip()


def _address_space() -> int:
    """This process's virtual size in bytes (Linux ``/proc/self/statm``), 0 if unknown."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _limit_memory(budget_mb: int) -> None:
    with contextlib.suppress(ImportError, ValueError, OSError):
        import resource

        limit = _address_space() + budget_mb * 1024 * 1024
        _, hard = resource.getrlimit(resource.RLIMIT_AS)
        if hard != resource.RLIM_INFINITY:
            limit = min(limit, hard)
        resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


def _import_student(path: str) -> Any:
    spec = importlib.util.spec_from_file_location(STUDENT_MODULE, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot import {path}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _portable(answer: Any, kind: str) -> Any:
    """The answer in a form that pickles (a dense matrix as CSR, to send less)."""
    import numpy as np
    import scipy.sparse as sp

    if kind == "matrix" and not sp.issparse(answer):
        with contextlib.suppress(TypeError, ValueError):
            a = np.asarray(answer, dtype=np.float64)
            if a.ndim == 2:
                return sp.csr_matrix(a)
    pickle.dumps(answer)
    return answer


def _seconds(fn: Any, *args: Any) -> float:
    t0 = time.perf_counter()
    fn(*args)
    return time.perf_counter() - t0


def _speed(task: Any, func: Any, case: Case) -> tuple[float, float]:
    """(student seconds, reference seconds) on ``case``, from the round most favourable to the
    student: each round times the reference (best of 3) and then the student, side by side, so
    that a burst of load on a shared machine hits both; a correct answer is never called slow
    because the machine was busy during one call. A student call over 2 s ends the rounds."""
    (_label, args), *_ = task.calls(case)
    best: tuple[float, float] | None = None
    for _round in range(SPEED_ROUNDS):
        ref = min(_seconds(task.reference, case, args) for _ in range(3))
        mine = _seconds(func, *args)
        if best is None or mine / max(ref, 1e-9) < best[0] / max(best[1], 1e-9):
            best = (mine, ref)
        if mine > 2.0:
            break
    return best if best is not None else (0.0, 1.0)


SPEED_ROUNDS = 4


def _run_task(conn: Connection, task: Any, func: Any, cases: list[Case], path: str) -> None:
    for case in cases:
        for label, args in task.calls(case):
            where = ("call", task.name, case.name, label)
            try:
                t0 = time.perf_counter()
                answer = func(*args)
                seconds = time.perf_counter() - t0
                conn.send((*where, _portable(answer, task.kind), seconds))
            except NotImplementedError:
                conn.send(("stop", task.name, "not_implemented", case.name, label, ""))
                return
            except MemoryError as exc:
                text = student_traceback(exc, path)
                conn.send(("stop", task.name, "memory", case.name, label, text))
                return
            except Exception as exc:
                text = student_traceback(exc, path)
                conn.send(("stop", task.name, "error", case.name, label, text))
                return
    if task.speed and any("speed" in c.tags for c in cases):
        big = next(c for c in cases if "speed" in c.tags)
        conn.send(("speed", task.name, *_speed(task, func, big)))


def _worker(
    path: str, names: list[str], extra: list[Case], budget_mb: int, conn: Connection
) -> None:
    """The spawned worker's main: import, then run each task and report through ``conn``."""
    from .tasks import TASKS

    _limit_memory(budget_mb)
    all_cases = {c.name: c for c in battery()}
    sys.stdout = sys.stderr  # the student's prints must not mix with the checker's output
    refused = guard.scan(path)  # a file calling meshlap itself would check nothing
    if refused:
        conn.send(("import_error", refused))
        return
    guard.install(STUDENT_MODULE, path)
    try:
        module = _import_student(path)
    except BaseException as exc:  # SystemExit, SyntaxError: the student's
        conn.send(("import_error", student_traceback(exc, path)))
        return
    for name in names:
        conn.send(("start", name))
        task = TASKS[name]
        func = getattr(module, name, None)
        if not callable(func):
            conn.send(("stop", name, "missing", "", "", ""))
            continue
        cases = [all_cases[c] for c in task.cases] + list(extra)
        _run_task(conn, task, func, cases, path)
        conn.send(("done", name))
    conn.send(("finished",))


def _receive(conn: Connection, runs: dict[str, TaskRun], msg: tuple) -> str | None:
    """Record one message; return the name of the task it starts or finishes, if any."""
    kind = msg[0]
    if kind == "call":
        runs[msg[1]].calls.append((msg[2], msg[3], msg[4], msg[5]))
    elif kind == "stop":
        run = runs[msg[1]]
        run.status, run.case, run.label, run.message = msg[2], msg[3], msg[4], msg[5]
    elif kind == "speed":
        runs[msg[1]].speed = (msg[2], msg[3])
    return None


def run_student(
    path: str | os.PathLike,
    names: list[str],
    extra: list[Case] | None = None,
    timeout: float = EXERCISE_TIMEOUT,
    memory_mb: int = EXERCISE_MEMORY_MB,
    cancel: Cancel = None,
) -> dict[str, TaskRun]:
    """Run the tasks ``names`` of the student file ``path`` in spawned workers.

    Parameters
    ----------
    path : str or PathLike
    names : list of str
        Task names (:data:`~.tasks.TASKS`).
    extra : list of Case, optional
        More meshes to call every task on (the viewer's mesh).
    timeout : float
        Seconds per task.
    memory_mb : int
        Address space the student may use on top of the worker's own, in MiB.
    cancel : threading.Event or callable, optional
        Asks to stop: the worker is killed and :class:`~meshlap_core.errors.Cancelled` raised.

    Returns
    -------
    dict
        Task name -> :class:`TaskRun`.
    """
    path = os.fspath(path)
    runs = {n: TaskRun() for n in names}
    todo = list(names)
    ctx = multiprocessing.get_context("spawn")
    while todo:
        receiver, sender = ctx.Pipe(duplex=False)
        proc = ctx.Process(
            target=_worker, args=(path, todo, list(extra or []), memory_mb, sender), daemon=True
        )
        proc.start()
        sender.close()
        todo = _drive(proc, receiver, runs, todo, timeout, cancel)
    return runs


def _drive(
    proc: Any,
    conn: Connection,
    runs: dict[str, TaskRun],
    todo: list[str],
    timeout: float,
    cancel: Cancel = None,
) -> list[str]:
    """Read one worker's messages until it finishes, dies or overruns; the tasks left to do.

    A worker's start-up (interpreter, numpy, the student's import) has the same deadline as a
    task; a task that overruns or dies is marked and the remaining ones go to a new worker.
    """
    current: str | None = None
    started = False
    done: set[str] = set()
    deadline = time.monotonic() + timeout
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                status = "timeout"
                break
            if not conn.poll(min(left, 0.1)):
                check_cancel(cancel, "the check")  # the finally below ends the worker
                continue
            try:
                msg = conn.recv()
            except (EOFError, OSError):
                status = "crashed"
                break
            if msg[0] == "import_error":
                for n in todo:
                    runs[n].status, runs[n].message = "import_error", msg[1]
                return []
            if msg[0] == "finished":
                return []
            if msg[0] == "start":
                current, deadline = msg[1], time.monotonic() + timeout
                started = True
                done.update(todo[: todo.index(msg[1])])
            elif msg[0] == "done":
                done.add(msg[1])
                current = None
            else:
                _receive(conn, runs, msg)
    finally:
        if proc.is_alive():
            proc.kill()
        proc.join(5)
        conn.close()
    why = (
        f"stopped after {timeout:g} s (an infinite loop?)"
        if status == "timeout"
        else f"the worker died (exit code {proc.exitcode}): a crash in native code, or os._exit"
    )
    if not started:  # the import itself never finished: every task is lost
        for n in todo:
            runs[n].status, runs[n].message = status, f"while importing your file: {why}"
        return []
    if current is None:  # died between two tasks: the next one had not started
        return [n for n in todo if n not in done]
    runs[current].status, runs[current].message = status, why
    return todo[todo.index(current) + 1 :]
