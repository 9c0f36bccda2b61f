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
- an import of meshlap itself (which would return the reference): refused (:mod:`.guard`);
- a window opened, a process started, a file opened outside the student's folder: stopped by
  :class:`.guard.Fence` and reported ``refused`` with its diagnosis (the rest still checked);
- an import that never ends: ``timeout`` with the diagnosis ``hangs_at_import``.

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
        ``"timeout"``, ``"memory"``, ``"crashed"``, ``"refused"`` or ``"import_error"``.
    calls : list of (case name, label, answer, seconds)
    message : str
        The student's traceback (their file's frames only) or what stopped the task.
    case, label : str
        The call that raised or was stopped.
    speed : (float, float) or None
        Student and reference seconds on the large case, measured side by side in the worker
        (:func:`_speed`).
    diagnosis : str or None
        Why the sandbox stopped the task (a :data:`.guard.FENCE_WHY` key, ``hangs_at_import``).
    """

    status: str = "ran"
    calls: list[tuple[str, str, Any, float]] = field(default_factory=list)
    message: str = ""
    case: str = ""
    label: str = ""
    speed: tuple[float, float] | None = None
    diagnosis: str | None = None


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


def _speed(
    task: Any, func: Any, case: Case, fence: guard.Fence, conn: Connection
) -> tuple[float, float]:
    """(student seconds, reference seconds) on ``case``, from the round most favourable to the
    student: each round times the reference (best of 3) and then the student, side by side, so
    that a burst of load on a shared machine hits both; a correct answer is never called slow
    because the machine was busy during one call. A student call over 2 s ends the rounds."""
    (_label, args), *_ = task.calls(case)
    best: tuple[float, float] | None = None
    for _round in range(SPEED_ROUNDS):
        refs = [_seconds(task.reference, case, args) for _ in range(3)]
        conn.send(("budget", task.name, case.name, max(refs)))
        ref = min(refs)
        with fence.student():
            mine = _seconds(func, *args)
        if best is None or mine / max(ref, 1e-9) < best[0] / max(best[1], 1e-9):
            best = (mine, ref)
        if mine > 2.0:
            break
    return best if best is not None else (0.0, 1.0)


SPEED_ROUNDS = 4
TIME_FACTOR = 2000.0
"""A call on a mesh of :data:`BUDGET_MIN_VERTICES` or more may take this many times the
reference's time on the same mesh, measured in the worker just before the call (side by side:
a loaded machine slows both), when that is more than the task's time limit: a right answer
written with dense matrices (O(n³), about 200× the sparse reference on the 2562-vertex mesh)
is never stopped as an infinite loop because the machine was busy, nor on a big scan."""
BUDGET_MIN_VERTICES = 1000
"""Below this the reference takes milliseconds: the task's time limit alone applies."""

STARTUP_TIMEOUT = 120.0
"""Seconds a worker may take to start before the student's file is imported (the interpreter,
numpy, scipy and meshlap in a spawned process: ours, not the student's; a few seconds, more on
a loaded machine). The student's import and every task then get ``timeout`` each."""


def _run_task(
    conn: Connection, task: Any, func: Any, cases: list[Case], path: str, fence: guard.Fence
) -> None:
    for case in cases:
        for label, args in task.calls(case):
            where = ("call", task.name, case.name, label)
            if len(case.V) >= BUDGET_MIN_VERTICES:  # the reference here, now: the call's time
                ref = _seconds(task.reference, case, args)
                conn.send(("budget", task.name, case.name, ref))
            try:
                t0 = time.perf_counter()
                with fence.student():
                    answer = func(*args)
                seconds = time.perf_counter() - t0
                refused = fence.take()
                if refused is not None:  # caught by the student: still refused
                    raise refused
                conn.send((*where, _portable(answer, task.kind), seconds))
            except guard.Refused as exc:
                _send_refused(conn, fence, exc, path, (task.name, case.name, label))
                return
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
        try:
            conn.send(("speed", task.name, *_speed(task, func, big, fence, conn)))
        except guard.Refused as exc:  # only now (the speed call): refused all the same
            _send_refused(conn, fence, exc, path, (task.name, big.name, "speed"))


def _send_refused(
    conn: Connection, fence: guard.Fence, exc: guard.Refused, path: str, where: tuple[str, str, str]
) -> None:
    """Report a call the fence refused: ``where`` is (task, case, call label)."""
    fence.take()  # the attempt is reported once, here
    task, case, label = where
    conn.send(("stop", task, "refused", case, label, student_traceback(exc, path), exc.key))


def _worker(
    path: str, names: list[str], extra: list[Case], budget_mb: int, conn: Connection
) -> None:
    """The spawned worker's main: import, then run each task and report through ``conn``."""
    from .tasks import TASKS

    _limit_memory(budget_mb)
    all_cases = {c.name: c for c in battery()}
    conn.send(("ready",))  # the worker's own start-up is over: the student's clock starts
    sys.stdout = sys.stderr  # the student's prints must not mix with the checker's output
    refused = guard.scan(path)  # a file calling meshlap itself would check nothing
    if refused:
        conn.send(("import_error", refused))
        return
    guard.install(STUDENT_MODULE, path)
    fence = guard.Fence(path)
    fence.install()
    try:
        with fence.student():
            module = _import_student(path)
        refused = fence.take()
        if refused is not None:  # caught by the student: still refused
            raise refused
    except BaseException as exc:  # SystemExit, SyntaxError: the student's
        refused = fence.take()  # the first refused attempt, even if another error followed
        key = refused.key if refused is not None else getattr(exc, "key", None)
        conn.send(("import_error", student_traceback(exc, path), key))
        return
    for name in names:
        conn.send(("start", name))
        task = TASKS[name]
        func = getattr(module, name, None)
        if not callable(func):
            conn.send(("stop", name, "missing", "", "", ""))
            continue
        cases = [all_cases[c] for c in task.cases] + list(extra)
        _run_task(conn, task, func, cases, path, fence)
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
        run.diagnosis = msg[6] if len(msg) > 6 else None
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

    A worker's own start-up (interpreter, numpy, meshlap) has :data:`STARTUP_TIMEOUT`; from
    its ``ready`` message the student's import has the same deadline as a task; a task that
    overruns or dies is marked and the remaining ones go to a new worker.
    """
    current: str | None = None
    started = False
    done: set[str] = set()
    deadline = time.monotonic() + max(timeout, STARTUP_TIMEOUT)
    budget: tuple[str, float] | None = None  # (mesh, reference seconds) of the call running
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
                    runs[n].diagnosis = msg[2] if len(msg) > 2 else None
                return []
            if msg[0] == "finished":
                return []
            if msg[0] == "ready":  # the student's import starts now
                deadline = time.monotonic() + timeout
                continue
            if msg[0] == "budget":  # a call on a big mesh: TIME_FACTOR × the reference there
                budget = (msg[2], msg[3])
                deadline = max(deadline, time.monotonic() + TIME_FACTOR * msg[3])
                continue
            if msg[0] == "start":
                current, deadline, budget = msg[1], time.monotonic() + timeout, None
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
            runs[n].diagnosis = "hangs_at_import" if status == "timeout" else None
        return []
    if current is None:  # died between two tasks: the next one had not started
        return [n for n in todo if n not in done]
    diagnosis = None
    if status == "timeout" and budget is not None and TIME_FACTOR * budget[1] > timeout:
        mesh, ref = budget
        why = (
            f"stopped on mesh {mesh}: over {TIME_FACTOR:g}× the reference's {ref:.3g} s there "
            "(measured just before, on this machine)"
        )
        diagnosis = "too_slow"
    runs[current].status, runs[current].message = status, why
    runs[current].diagnosis = diagnosis
    return todo[todo.index(current) + 1 :]
