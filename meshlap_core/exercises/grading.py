"""Grade a class: a folder of submissions, each in a sandbox and a copy of its own, in
parallel, into the reports a course reads.

A class folder holds, side by side, students' files (``alice.py``: the file is the submission)
and students' folders (``bob/``, as course sites export them: its ``exercises.py``, else its one
``.py`` file defining a task; helper modules and data files beside it come along). Each is
checked by :func:`~.check.check_file` in a copy of its own (:mod:`.copies`), ``jobs`` at a time,
within a per-file time cap; a submission that cannot be checked at all (no exercises file, a
checker error) is that student's error row, never the end of the run. The references are
computed once for the whole class (:mod:`.references`).

Reports: :func:`summary_csv` (one row per student, one column per task), the JSON and JUnit
documents (:mod:`.result`), and Gradescope's ``results.json`` per student
(:func:`write_gradescope`).
"""

from __future__ import annotations

import ast
import csv
import io
import json
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from ..errors import MeshError, printable
from ..io.atomic import atomic_write
from ..options import EXERCISE_MEMORY_MB, EXERCISE_TIMEOUT
from .check import check_file
from .copies import Submission, parse_source
from .result import CheckResult, TaskResult
from .tasks import EXERCISE_TASKS
from .worker import Session

MAIN_FILE = "exercises.py"
"""The file looked for first in a student's folder."""


def _task_count(path: Path) -> int:
    """How many task functions ``path`` defines (parsed, never run)."""
    tree = parse_source(path)
    if tree is None:
        return 0
    names = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    return len(names & set(EXERCISE_TASKS))


def _main_file(folder: Path) -> Path | None:
    """A student's exercises file in ``folder``: ``exercises.py``, else the ``.py`` file
    defining the most tasks (None: no file defines one)."""
    if (folder / MAIN_FILE).is_file():
        return folder / MAIN_FILE
    scored = [(_task_count(p), p) for p in sorted(folder.glob("*.py")) if p.is_file()]
    scored = [(n, p) for n, p in scored if n > 0]
    return max(scored, key=lambda s: s[0])[1] if scored else None


def find_submissions(folder: Path) -> list[Submission | tuple[str, str]]:
    """The class folder's submissions, sorted by name; a student's folder without an
    exercises file is ``(name, why)``.

    Raises
    ------
    MeshError
        Nothing to grade in the folder.
    """
    found: list[Submission | tuple[str, str]] = []
    for entry in sorted(folder.iterdir(), key=lambda p: p.name):
        if entry.name.startswith((".", "__")):
            continue
        if entry.is_dir() and entry.is_symlink():
            found.append((entry.name, "a link to a folder: not followed"))
        elif entry.is_dir():
            main = _main_file(entry)
            if main is None:
                found.append((entry.name, f"no {MAIN_FILE} and no .py file defining a task"))
            else:
                found.append(Submission(entry.name, main, entry))
        elif entry.suffix == ".py" and entry.is_file():
            real = Path(os.path.realpath(entry))
            if entry.is_symlink() and not real.is_relative_to(os.path.realpath(folder)):
                found.append((entry.stem, "a link to a file outside the class folder: not read"))
            else:
                found.append(Submission(entry.stem, entry, among_others=True))
    if not found:
        raise MeshError("no .py submissions and no student folders here", printable(str(folder)))
    return found


def error_result(name: str, shown: str, tasks: Sequence[str], why: str) -> CheckResult:
    """The row of a submission the checker could not check: every task an error, saying why."""
    rows = [TaskResult(t, "error", message=why) for t in tasks]
    return CheckResult(printable(shown), rows, submission=printable(name))


def grade_folder(
    folder: str | os.PathLike,
    tasks: Sequence[str] | None = None,
    *,
    jobs: int = 1,
    timeout: float = EXERCISE_TIMEOUT,
    memory_mb: int = EXERCISE_MEMORY_MB,
    file_timeout: float | None = None,
    require_speed: bool = False,
    speed: bool = True,
    sandbox: str | None = None,
    progress: Callable[[int, int, CheckResult], None] | None = None,
) -> list[CheckResult]:
    """Check every submission of a class folder (see module).

    Parameters
    ----------
    folder : str or PathLike
    tasks : sequence of str, optional
        The tasks (all by default).
    jobs : int
        Submissions checked at the same time.
    timeout, memory_mb, file_timeout, require_speed, speed
        As :func:`~.check.check_file` (``file_timeout``: each submission's cap).
    sandbox : {"auto", "bwrap", "process"}, optional
    progress : callable, optional
        ``progress(done, total, result)`` after each submission (any thread).

    Returns
    -------
    list of CheckResult
        One per submission, in the folder's order.
    """
    root = Path(folder)
    names = list(dict.fromkeys(tasks or EXERCISE_TASKS))
    subs = find_submissions(root)
    done = [0]
    with Session(sandbox) as session:

        def one(sub: Submission | tuple[str, str]) -> CheckResult:
            if isinstance(sub, tuple):
                result = error_result(sub[0], sub[0] + "/", names, sub[1])
            else:
                result = _check_one(sub, root, names, session, timeout, memory_mb,
                                    file_timeout, require_speed, speed)  # fmt: skip
            done[0] += 1
            if progress is not None:
                progress(done[0], len(subs), result)
            return result

        with ThreadPoolExecutor(max_workers=max(1, int(jobs))) as pool:
            return list(pool.map(one, subs))


def _check_one(sub: Submission, root: Path, names: list[str], session: Session,
               timeout: float, memory_mb: int, file_timeout: float | None,
               require_speed: bool, speed: bool) -> CheckResult:  # fmt: skip
    shown = os.fspath(sub.path.relative_to(root))
    try:
        result = check_file(
            sub.path, names, timeout=timeout, memory_mb=memory_mb, session=session,
            folder=sub.folder, among_others=sub.among_others, file_timeout=file_timeout,
            require_speed=require_speed,
            speed=speed, name=shown,
        )  # fmt: skip
    except Exception as exc:  # the checker's failure on this file: this student's row only
        why = f"the checker could not check this file: {type(exc).__name__}: {exc}"
        return error_result(sub.name, shown, names, why)
    result.submission = printable(sub.name)
    return result


def _cell(t: TaskResult) -> str:
    slow = t.passed and t.speed is not None and t.speed.slow
    return t.status + (f" ({t.diagnosis})" if t.diagnosis else " (slow)" if slow else "")


def summary_csv(results: list[CheckResult], tasks: Sequence[str]) -> str:
    """One row per submission: who, the file, passed, total, then each task's status with its
    diagnosis (``passed (slow)``: right, and slow)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["submission", "file", "passed", "total", *tasks])
    for r in results:
        by = {t.task: t for t in r.tasks}
        cells = [_cell(by[name]) if name in by else "" for name in tasks]
        w.writerow([r.submission or os.path.basename(r.file), r.file, r.n_passed, len(r.tasks),
                    *cells])  # fmt: skip
    return buf.getvalue()


def write_gradescope(results: list[CheckResult], out: str | os.PathLike) -> list[Path]:
    """Gradescope's ``results.json`` of each submission, in ``out/<submission>/`` (created);
    the files written."""
    root = Path(out)
    root.mkdir(parents=True, exist_ok=True)
    written = []
    for r in results:
        name = r.submission or Path(r.file).stem
        safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in name).lstrip(".") or "_"
        (root / safe).mkdir(exist_ok=True)
        target = root / safe / "results.json"
        with atomic_write(target) as f:
            json.dump(r.gradescope(), f, indent=1, ensure_ascii=False)
        written.append(target)
    return written


def class_json(results: list[CheckResult]) -> dict[str, Any]:
    """The JSON document of a folder run."""
    return {
        "isolation": results[0].isolation if results else {},
        "passed": sum(r.passed for r in results),
        "submissions": [r.to_dict() for r in results],
    }
