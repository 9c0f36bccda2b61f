"""Run a student's file in its sandbox and collect its answers: the checker owns the clock.

:func:`run_student` copies the submission (:mod:`.copies`), starts a :class:`~.worker.Worker`
on the copy and drives it task by task, call by call. For every call the checker writes the
inputs, sends the command, and waits for the reply up to a deadline of its own:

- the task's time limit (``timeout``, for all of its calls), or on a big mesh
  :data:`TIME_FACTOR` × the reference's own time there when that is longer: a right answer
  on a busy machine or a big scan is not stopped as an endless loop;
- a reply that never comes: ``timeout`` (``too_slow`` past a big mesh's budget,
  ``hangs_at_import`` during the import); the worker and all it started are killed and a new
  one continues with the next task;
- the worker dying: ``crashed``, with how (a signal, an exit code); the next task goes on;
- a reply that is not the harness's (the student wrote on the checker's channel): the rest of
  the file is ``error`` with the diagnosis ``tampers``.

An answer is read back as plain arrays (:mod:`.plain`) and compared at once: a task wrong on
the small meshes is not run on the big ones (its diagnosis comes from the small ones; the big
ones would only cost time). Every right task is then timed on its speed mesh (the ``large``
sphere; ``large_disk`` for the maps of a disk) in :data:`SPEED_RUNS` runs, each beside the
reference's best of three in the checker, in CPU seconds (the worker's from ``/proc``, the
reference's thread time): a busy machine slows the wall clock, not the CPU time a loop needs.
"""

from __future__ import annotations

import os
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..options import EXERCISE_MEMORY_MB, EXERCISE_TIMEOUT
from . import references as refs
from .compare import COMPARE
from .copies import Submission, copy_submission
from .guard import scan
from .isolation import Isolation, Limits
from .meshes import Case, battery
from .plain import BadAnswer, Tampered, read_answer, unpack
from .tasks import TASKS, Task
from .worker import Session, Worker, WorkerGone, default_session

TIME_FACTOR = 2000.0
"""A call on a mesh of :data:`BUDGET_MIN_VERTICES` or more may take this many times the
reference's time on the same mesh, when that is more than the task's time limit: a right answer
written with dense matrices on a 2562-vertex mesh (about 200× the sparse reference) is never
stopped as an infinite loop because the machine was busy, nor on a big scan."""
BUDGET_MIN_VERTICES = 1000
"""Below this the reference takes milliseconds: the task's time limit alone applies."""
STARTUP_TIMEOUT = 120.0
"""Seconds a worker may take to start (the interpreter, numpy, the sandbox: ours, not the
student's; a second, more on a loaded machine). The student's import and every task then get
``timeout`` each."""
SPEED_RUNS = 3
"""Timed runs of every task on the speed mesh (a band: the lowest and the highest ratio)."""
SPEED_MAX_SECONDS = 20.0
"""A task whose answer on the speed mesh took longer is timed once (that call), not again."""


@dataclass
class TaskRun:
    """What the worker did for one task.

    Attributes
    ----------
    status : str
        ``"ran"`` (every call answered), ``"missing"``, ``"not_implemented"``, ``"error"``,
        ``"timeout"``, ``"memory"``, ``"crashed"``, ``"refused"`` or ``"import_error"``.
    calls : list of (case name, label, answer, seconds)
        The answers (plain arrays, or a :class:`~.plain.BadAnswer`) and wall seconds.
    planned : list of (case name, label)
        Every call the task has (a call without an answer has failed).
    message : str
        The student's traceback (their files' frames only) or what stopped the task.
    case, label : str
        The call that raised or was stopped.
    diagnosis : str or None
        Why it stopped (a :data:`.diagnose.DIAGNOSES` key).
    what : str
        What the sandbox refused (``subprocess.Popen``, a path...).
    speed : list of (student CPU s, student wall s, reference CPU s, reference wall s)
    hot : list of [file, line, samples]
        Where the timed runs spent their time (the profiler's lines, summed).
    """

    status: str = "ran"
    calls: list[tuple[str, str, Any, float]] = field(default_factory=list)
    planned: list[tuple[str, str]] = field(default_factory=list)
    message: str = ""
    case: str = ""
    label: str = ""
    diagnosis: str | None = None
    what: str = ""
    speed: list[tuple[float, float, float, float]] = field(default_factory=list)
    hot: list[list[Any]] = field(default_factory=list)
    failing: bool = False
    """An answer already differs from the reference (the big meshes are then skipped)."""

    def stop(
        self,
        status: str,
        message: str = "",
        diagnosis: str | None = None,
        where: tuple[str, str] = ("", ""),
    ) -> None:
        self.status, self.message, self.diagnosis = status, message, diagnosis
        self.case, self.label = where


@dataclass
class StudentRun:
    """Everything the sandbox reports for one file: per task, and what the file printed."""

    tasks: dict[str, TaskRun]
    isolation: Isolation
    log: str = ""
    log_bytes: int = 0
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    survivors: list[int] = field(default_factory=list)
    """Processes the file left behind that the end of the check had to kill."""


@dataclass
class _Plan:
    """The checker's side of one check."""

    session: Session
    cases: dict[str, Case]
    extra: list[Case]
    timeout: float
    deadline: float
    cancel: Any
    speed: bool


def _call_command(
    plan: _Plan, task: Task, case: Case, label: str, args: tuple, ident: int, profile: bool
) -> dict[str, Any]:
    key = f"{task.name}|{case.name}|{label}" + ("" if refs.is_battery(case) else f"|{id(case)}")
    file, specs = plan.session.store.put(key, args)
    return {
        "op": "call",
        "id": ident,
        "func": task.name,
        "kind": task.kind,
        "inputs": file,
        "args": specs,
        "profile": profile,
    }


def _answer(worker: Worker, reply: dict[str, Any], cap: int) -> Any:
    if reply["ev"] == "raised" and reply["kind"] == "unsendable":
        return BadAnswer(reply["text"], reply["key"])
    try:
        arrays = read_answer(worker.outputs / f"{reply['id']}.npz", reply["tag"], cap)
    except (OSError, ValueError) as exc:
        return BadAnswer(f"an answer that could not be read back: {exc}", "not_numbers")
    return unpack(reply["tag"], arrays)


def _budget(plan: _Plan, task: Task, case: Case, label: str, args: tuple) -> float:
    """Seconds this call may take beyond the task's deadline (big meshes, see module)."""
    if len(case.V) < BUDGET_MIN_VERTICES:
        return 0.0
    return TIME_FACTOR * refs.expected_timed(task, case, label, args)[1]


def _call(worker: Worker, plan: _Plan, command: dict[str, Any], deadline: float) -> dict | None:
    """Send one call and wait for its reply (None: the deadline passed)."""
    worker.send(command)
    while True:
        reply = worker.receive(min(deadline, plan.deadline), plan.cancel)
        if reply is None or reply.get("id") == command["id"]:
            return reply
        raise Tampered(f"a reply for call {reply.get('id')} during call {command['id']}")


def _stopped(run: TaskRun, reply: dict[str, Any], where: tuple[str, str]) -> None:
    kind = reply["kind"]
    status = {"exit": "error", "unsendable": "error"}.get(kind, kind)
    run.stop(status, reply["text"], reply["key"], where)
    run.what = reply.get("what", "")


def _correctness(
    worker: Worker, plan: _Plan, task: Task, run: TaskRun, limits: Limits, counter: list[int]
) -> str | None:
    """Every call of ``task``; None when they all ran or one raised, else how it was lost
    (``"timeout"``: the worker must be replaced)."""
    deadline = time.monotonic() + plan.timeout
    for case in _meshes(plan, task):
        if run.failing and len(case.V) >= BUDGET_MIN_VERTICES and refs.is_battery(case):
            continue  # wrong already: the small meshes diagnose it, the big ones would only cost
        for label, args in refs.calls(task, case):
            counter[0] += 1
            command = _call_command(plan, task, case, label, args, counter[0], False)
            extra = _budget(plan, task, case, label, args)
            t0 = time.monotonic()
            reply = _call(worker, plan, command, max(deadline, t0 + extra))
            if reply is None:
                over_budget = extra > plan.timeout and time.monotonic() >= t0 + extra
                _lost(run, plan, (case.name, label), over_budget, extra / TIME_FACTOR)
                return "timeout"
            if reply["ev"] == "raised" and reply["kind"] != "unsendable":
                _stopped(run, reply, (case.name, label))
                return None
            answer = _answer(worker, reply, limits.answer)
            run.calls.append((case.name, label, answer, time.monotonic() - t0))
            expected = refs.expected(task, case, label, args)
            run.failing = run.failing or not COMPARE[task.kind](answer, expected, case,
                                                                task.power).ok  # fmt: skip
    return None


def _meshes(plan: _Plan, task: Task) -> list[Case]:
    return [plan.cases[c] for c in task.cases] + plan.extra


def _lost(run: TaskRun, plan: _Plan, where: tuple[str, str], over_budget: bool, ref: float) -> None:
    if time.monotonic() >= plan.deadline:
        run.stop("timeout", "the file's time cap was reached", None, where)
    elif over_budget:
        why = (
            f"stopped on mesh {where[0]}: over {TIME_FACTOR:g}× the reference's "
            f"{ref:.3g} s there (measured on this machine)"
        )
        run.stop("timeout", why, "too_slow", where)
    else:
        run.stop("timeout", f"stopped after {plan.timeout:g} s (an infinite loop?)", None, where)


def _timed_runs(worker: Worker, plan: _Plan, task: Task, run: TaskRun, counter: list[int]) -> None:
    """The speed runs (see module); a run that fails or overruns ends them quietly."""
    case = plan.cases[task.speed_case]
    first = next((s for c, _, a, s in run.calls if c == case.name), None)
    if first is None or run.status != "ran" or run.failing:
        return
    (label, args), *_ = refs.calls(task, case)
    rounds = 1 if first > SPEED_MAX_SECONDS else SPEED_RUNS
    for _ in range(rounds):
        ref_cpu, ref_wall = refs.reference_speed(task, case, args)
        counter[0] += 1
        command = _call_command(plan, task, case, label, args, counter[0], True)
        c0, t0 = worker.cpu(), time.monotonic()
        reply = _call(worker, plan, command, t0 + max(plan.timeout, 3 * first + 1.0))
        if reply is None:
            raise _Overran
        if reply["ev"] != "answer":
            return
        run.speed.append((worker.cpu() - c0, time.monotonic() - t0, ref_cpu, ref_wall))
        run.hot = _merge(run.hot, reply["hot"])


class _Overran(Exception):
    """A timed run did not end: the worker is replaced (the verdict stands)."""


def _merge(a: list[list[Any]], b: list[list[Any]]) -> list[list[Any]]:
    counts: dict[tuple[str, int], int] = {}
    for file, line, n in [*a, *b]:
        counts[(file, line)] = counts.get((file, line), 0) + n
    return [[f, ln, n] for (f, ln), n in sorted(counts.items(), key=lambda kv: -kv[1])[:8]]


def _start(worker: Worker, plan: _Plan, todo: list[str], runs: dict[str, TaskRun]) -> list | None:
    """Wait for the worker's start-up, then the student's import; the functions found, or
    None when the file is done for (every task marked)."""
    try:
        ready = worker.receive(time.monotonic() + STARTUP_TIMEOUT, plan.cancel)
        if ready is None or ready["ev"] != "ready":
            raise WorkerGone("the worker did not start")
        worker.locate()
        worker.send({"op": "import"})
        reply = worker.receive(min(time.monotonic() + plan.timeout, plan.deadline), plan.cancel)
    except WorkerGone as exc:
        for n in todo:
            runs[n].stop("crashed", f"while importing your file: {exc}")
        return None
    if reply is None:
        for n in todo:
            runs[n].stop(
                "timeout",
                f"while importing your file: stopped after {plan.timeout:g} s",
                "hangs_at_import",
            )
        return None
    if reply["ev"] == "import_error":
        for n in todo:
            _stopped(runs[n], reply, ("", ""))
            runs[n].status = "import_error"
        return None
    if reply["ev"] != "imported":
        raise Tampered(f"a {reply['ev']!r} reply to the import")
    return reply["functions"]


def _drive(
    worker: Worker, plan: _Plan, todo: list[str], runs: dict[str, TaskRun], limits: Limits
) -> list[str]:
    """Run ``todo`` on one worker; the tasks left for a new one."""
    counter = [0]
    functions = _start(worker, plan, todo, runs)
    if functions is None:
        return []
    for name in todo:
        if name not in functions:
            runs[name].stop("missing")
    for i, name in enumerate(todo):
        task, run = TASKS[name], runs[name]
        if run.status == "missing":
            continue
        try:
            lost = _correctness(worker, plan, task, run, limits, counter)
            if lost is not None:
                return (
                    todo[i + 1 :]
                    if time.monotonic() < plan.deadline
                    else _capped(todo[i + 1 :], runs)
                )
            if plan.speed:
                _timed_runs(worker, plan, task, run, counter)
        except WorkerGone as exc:
            run.stop("crashed", str(exc), None, (run.case, run.label))
            return todo[i + 1 :]
        except _Overran:
            return todo[i + 1 :]
    return []


def _capped(rest: list[str], runs: dict[str, TaskRun]) -> list[str]:
    for n in rest:
        runs[n].stop("timeout", "the file's time cap was reached before this task")
    return []


def run_student(
    path: str | os.PathLike,
    names: list[str],
    extra: list[Case] | None = None,
    *,
    timeout: float = EXERCISE_TIMEOUT,
    memory_mb: int = EXERCISE_MEMORY_MB,
    cancel: Any = None,
    session: Session | None = None,
    folder: Path | None = None,
    among_others: bool = False,
    file_timeout: float | None = None,
    speed: bool = True,
) -> StudentRun:
    """Run the tasks ``names`` of the student file ``path`` in its sandbox.

    Parameters
    ----------
    path : str or PathLike
    names : list of str
        Task names (:data:`~.tasks.TASKS`), each once.
    extra : list of Case, optional
        More meshes to call every task on (the viewer's mesh).
    timeout : float
        Seconds per task (and for the import).
    memory_mb : int
        Address space the student may use on top of the harness's own, in MiB.
    cancel : threading.Event or callable, optional
        Stops the worker and raises :class:`~meshlap_core.errors.Cancelled`.
    session : Session, optional
        The grading run (isolation, inputs); the process's default one when omitted.
    folder : Path, optional
        The student's folder, copied whole (``path`` is inside it).
    among_others : bool
        ``path`` lies among other students' files (see :class:`~.copies.Submission`).
    file_timeout : float, optional
        Seconds for the whole file; the tasks not done by then are ``timeout``.
    speed : bool
        Time every task on the speed mesh.

    Returns
    -------
    StudentRun
    """
    session = session or default_session()
    start = time.monotonic()
    cases = {c.name: c for c in battery()}
    plan = _Plan(
        session,
        cases,
        list(extra or []),
        timeout,
        start + (file_timeout or float("inf")),
        cancel,
        speed,
    )
    runs = {n: TaskRun(planned=_planned(plan, TASKS[n])) for n in names}
    limits = Limits(memory=memory_mb * 2**20, cpu=_cpu_cap(timeout, len(names), file_timeout))
    refused = scan(os.fspath(path))
    if refused is not None:  # calls meshlap itself: refused before it runs
        for run in runs.values():
            run.stop("import_error", refused, "imports_meshlap")
        return StudentRun(runs, session.isolation, seconds=time.monotonic() - start)
    copy = session.private_folder("copy-")
    try:
        sub = Submission(Path(path).stem, Path(path), folder, among_others)
        main, notes = copy_submission(sub, copy, tuple(TASKS))
        result = StudentRun(runs, session.isolation, notes=notes)
        todo = list(names)
        while todo:
            if time.monotonic() >= plan.deadline:
                todo = _capped(todo, runs)
                break
            worker = Worker(session, copy, main, todo, limits)
            try:
                todo = _drive(worker, plan, todo, runs, limits)
            except Tampered as exc:
                todo = _tampered(todo, runs, str(exc))
            finally:
                result.survivors += worker.close()
                result.log += worker.log.text().replace(os.fspath(copy) + os.sep, "")
                result.log_bytes += worker.log.total
    finally:
        shutil.rmtree(copy, ignore_errors=True)
    result.seconds = time.monotonic() - start
    return result


def _planned(plan: _Plan, task: Task) -> list[tuple[str, str]]:
    return [(c.name, label) for c in _meshes(plan, task) for label, _ in refs.calls(task, c)]


def _cpu_cap(timeout: float, tasks: int, file_timeout: float | None) -> int:
    """CPU seconds for one worker: every task's time limit and its timed runs, twice over (the
    wall clock stops a task first; this is the backstop of a worker the clock cannot stop)."""
    cap = 2.0 * timeout * (tasks + 1) * (1 + SPEED_RUNS)
    return int(min(cap, 2.0 * file_timeout) if file_timeout else cap) + 30


def _tampered(todo: list[str], runs: dict[str, TaskRun], why: str) -> list[str]:
    """The student's code wrote on the checker's channel: what was not done is an error."""
    for n in todo:
        r = runs[n]
        if r.status == "ran" and len(r.calls) < len(r.planned):
            r.stop("error", f"the checker's channel was written to ({why})", "tampers")
    return []
