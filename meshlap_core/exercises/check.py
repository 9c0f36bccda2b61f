"""Check a student's file: run it sandboxed, compare every answer, diagnose every failure
(:func:`check_file`); on the battery and one more mesh with both whole answers kept, for the
viewer (:func:`check_on_mesh`).

>>> from meshlap_core.exercises import check_file            # doctest: +SKIP
>>> result = check_file("exercises.py", ["cotan_laplacian"])  # doctest: +SKIP
>>> print(result.format_text())                               # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError, printable
from ..laplacian import vertex_areas
from ..options import EXERCISE_MEMORY_MB, EXERCISE_TIMEOUT, MASS_AREA, check_choice
from . import references as refs
from .compare import COMPARE, aligned_columns, as_matrix
from .copies import student_file
from .meshes import Case, battery
from .result import CheckResult
from .sandbox import StudentRun, run_student
from .tasks import EXERCISE_TASKS, TASKS
from .verdict import evaluate, name_dependencies
from .worker import Session, default_session

MEMORY_MIN_MB = 32
"""The smallest ``--memory``: a student's arrays on top of the harness's own numpy."""


def task_names(tasks: Sequence[str] | None) -> list[str]:
    """The tasks asked for, each once, in the order given (all by default).

    Raises
    ------
    MeshError
        An unknown task name.
    """
    names = list(EXERCISE_TASKS) if not tasks else [str(t) for t in tasks]
    for name in names:
        check_choice(name, EXERCISE_TASKS, "exercise", "--task")
    return list(dict.fromkeys(names))


def check_limits(timeout: float, memory_mb: int) -> None:
    """Raises :class:`MeshError` for a time limit that is not positive, or a memory budget
    under :data:`MEMORY_MIN_MB`."""
    if not timeout > 0:
        raise MeshError("must be a positive number of seconds", "--timeout")
    if memory_mb < MEMORY_MIN_MB:
        raise MeshError(
            f"{memory_mb} MiB is too little: a student's file needs at least {MEMORY_MIN_MB} "
            f"MiB for its arrays (default {EXERCISE_MEMORY_MB})",
            "--memory",
        )


def result_of(
    student: StudentRun,
    names: list[str],
    shown: str,
    source: Path | None,
    cases: dict[str, Case],
    *,
    require_speed: bool = False,
    kept: dict[str, Any] | None = None,
) -> CheckResult:
    """The :class:`CheckResult` of a sandbox run (``source``: the student's file, parsed for
    the slow loop and the failed dependencies, never run)."""
    folder = source.parent if source is not None else None
    results = [
        evaluate(TASKS[n], student.tasks[n], cases, kept, require_speed=require_speed,
                 source=folder)
        for n in names
    ]  # fmt: skip
    name_dependencies(results, source)
    return CheckResult(
        shown, results, isolation=student.isolation.to_dict(), log=student.log,
        log_bytes=student.log_bytes, notes=student.notes, seconds=student.seconds,
        survivors=len(student.survivors),
    )  # fmt: skip


def check_file(
    path: str | os.PathLike,
    tasks: Sequence[str] | None = None,
    *,
    extra: Sequence[Case] = (),
    timeout: float = EXERCISE_TIMEOUT,
    memory_mb: int = EXERCISE_MEMORY_MB,
    session: Session | None = None,
    sandbox: str | None = None,
    folder: str | os.PathLike | None = None,
    among_others: bool = False,
    file_timeout: float | None = None,
    require_speed: bool = False,
    speed: bool = True,
    name: str | None = None,
) -> CheckResult:
    """Check the student file ``path`` on ``tasks`` (all by default).

    The file runs in a sandboxed worker (:mod:`.sandbox`, :mod:`.isolation`) on a copy of its
    own, with ``timeout`` seconds per task and ``memory_mb`` MiB of address space; this process
    computes the references and compares.

    Parameters
    ----------
    path : str or PathLike
        The student's Python file (``meshlap exercises init`` writes the template).
    tasks : sequence of str, optional
        Names from :data:`~.tasks.EXERCISE_TASKS` (a name given twice is checked once).
    extra : sequence of Case
        More meshes to check on (the viewer's).
    timeout : float
    memory_mb : int
    session : Session, optional
        The grading run (isolation, inputs); the process's default one when omitted.
    sandbox : {"auto", "bwrap", "process"}, optional
        The isolation of the default session (``$MESHLAP_SANDBOX``, else ``auto``).
    folder : str or PathLike, optional
        The student's folder, copied whole (helper modules, data files): ``path`` is in it.
    among_others : bool
        ``path`` lies among other students' files: a module beside it defining a task is
        theirs, and not copied with it (a class folder of files).
    file_timeout : float, optional
        Seconds for the whole file.
    require_speed : bool
        A right but slow answer fails (``slow_loop``).
    speed : bool
        Time every task (the speed line).
    name : str, optional
        The file as the report names it (default: ``path``).

    Returns
    -------
    CheckResult

    Raises
    ------
    MeshError
        Not a regular file, an unknown task name, a limit out of range.
    """
    names = task_names(tasks)
    check_limits(timeout, memory_mb)
    student = student_file(path)
    session = session or default_session(sandbox)
    root = Path(folder) if folder is not None else None
    student_run = run_student(
        student, names, list(extra), timeout=timeout, memory_mb=memory_mb, session=session,
        folder=root, among_others=among_others, file_timeout=file_timeout, speed=speed,
    )  # fmt: skip
    cases = {c.name: c for c in [*battery(), *extra]}
    shown = printable(name if name is not None else os.fspath(path))
    return result_of(student_run, names, shown, student, cases, require_speed=require_speed)


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
    on_screen : bool or None
        The answer on the mesh on screen is right (``None``: the call gave none). ``result``
        is the battery's verdict alone, the one ``meshlap check`` prints (its count of
        failing calls included): the mesh on screen is judged here, not counted there.
    """

    result: CheckResult
    expected: Any
    got: Any
    difference: np.ndarray | None
    signed: bool
    on_screen: bool | None = None

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
    student = student_file(path)
    case = Case("your_mesh", np.asarray(V, float), np.asarray(F, np.int64), "the mesh on screen")
    t = TASKS[task]
    run = run_student(student, [task], [case], timeout=timeout, memory_mb=memory_mb,
                      cancel=cancel, speed=False)  # fmt: skip
    kept: dict[str, Any] = {}
    cases = {c.name: c for c in battery()}
    mine = run.tasks[task]
    on_battery = dataclasses.replace(  # the verdict of `meshlap check`: the battery's calls
        run,
        tasks={
            **run.tasks,
            task: dataclasses.replace(
                mine,
                calls=[c for c in mine.calls if c[0] != case.name],
                planned=[p for p in mine.planned if p[0] != case.name],
            ),
        },
    )
    result = result_of(on_battery, [task], printable(os.fspath(path)), student, cases, kept=kept)
    # a note about the mesh on screen (e.g. not judged there: the heat underflows) is kept
    full = result_of(run, [task], printable(os.fspath(path)), student, {**cases, case.name: case})
    said = full.tasks[0].note
    if said and case.name in said and said not in result.tasks[0].note:
        mine_note = result.tasks[0].note
        result.tasks[0] = dataclasses.replace(
            result.tasks[0], note=f"{mine_note}; {said}" if mine_note else said
        )
    (label, args), *_ = refs.calls(t, case)
    expected = refs.expected(t, case, label, args)
    got = next((a for c, _, a, _ in mine.calls if c == case.name), None)
    difference, signed, ok = None, False, None
    if got is not None:
        cmp = COMPARE[t.kind](got, expected, case, t.power)
        difference, ok = cmp.difference, bool(cmp.ok)
        signed = t.kind == "array" and np.ndim(expected) == 1
        if t.kind == "eigen":
            got = _aligned_eigen(got, expected, case)
            U = np.asarray(got[1], dtype=float) if len(got) == 2 else None
            if U is not None and U.shape == expected[1].shape:  # the map is |u − u_ref| per
                difference = np.abs(U - expected[1]).max(axis=1)  # vertex, whatever failed
    return MeshCheck(result, expected, got, difference, signed, ok)


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
