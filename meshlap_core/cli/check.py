"""``meshlap check FILE|FOLDER [--task NAME] [--json] [--csv OUT.csv] [--junit OUT.xml]
[--gradescope OUT] [--jobs N] [--sandbox auto|bwrap|process] ...``.

Check a student file written from ``meshlap exercises init``: the file runs in a sandbox
(bubblewrap where it works; the checker says on every run when it does not) on a copy of its
own, and every answer is compared with the reference on a battery of meshes; every failure
names the mesh, the vertex, expected vs got and the likely mistake, and every task gets a speed
line. A folder is a class: each ``*.py`` in it, and each student's subfolder, checked on its own
(``--jobs`` at a time), summarised as a CSV (one row per student, one column per task).

Exit codes: 0 every task passed; 3 some task did not pass; 2 bad arguments (one line).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..errors import MeshError, printable
from ..exercises import CheckResult, check_file
from ..exercises.check import check_limits, task_names
from ..exercises.grading import class_json, grade_folder, summary_csv, write_gradescope
from ..exercises.isolation import LEVELS, choose
from ..exercises.result import junit_document
from ..exercises.tasks import EXERCISE_TASKS
from ..io.atomic import atomic_write, check_output_path
from ..options import EXERCISE_MEMORY_MB, EXERCISE_TIMEOUT
from ._common import add_json_flag, emit_json

FAILED = 3


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("check", help="check a student's exercises file (or a class folder)")
    p.add_argument("path", help="the student's .py file, or a folder of submissions")
    p.add_argument(
        "--task", action="append", choices=EXERCISE_TASKS, metavar="NAME",
        help=f"check only this task (repeatable): {', '.join(EXERCISE_TASKS)}",
    )  # fmt: skip
    add_json_flag(p)
    p.add_argument("--csv", metavar="OUT.csv", help="write the summary here (one row per file)")
    p.add_argument("--junit", metavar="OUT.xml", help="also write a JUnit XML report")
    p.add_argument(
        "--gradescope", metavar="OUT",
        help="Gradescope's results.json: this file (one submission), or a folder with "
        "OUT/<student>/results.json (a class)",
    )  # fmt: skip
    p.add_argument("--timeout", type=float, default=EXERCISE_TIMEOUT, help="seconds per task")
    p.add_argument("--file-timeout", type=float, metavar="S", help="seconds per submission")
    p.add_argument(
        "--memory", type=int, default=EXERCISE_MEMORY_MB, help="MiB a submission may allocate"
    )
    p.add_argument("--jobs", type=int, default=1, metavar="N", help="submissions at a time")
    p.add_argument(
        "--sandbox", choices=LEVELS, default=None,
        help="bwrap: refuse to run without bubblewrap; process: a plain process (not "
        "isolated); auto (default, or $MESHLAP_SANDBOX): bubblewrap where it works",
    )  # fmt: skip
    p.add_argument(
        "--require-speed", action="store_true",
        help="a right answer that is slow (100× the reference and 0.5 s or more) fails",
    )  # fmt: skip
    p.add_argument(
        "--export-failing", metavar="DIR",
        help="write each failing task's mesh (.obj) and call arguments (.npz) into DIR",
    )  # fmt: skip
    p.set_defaults(func=run)


def _check_arguments(args: argparse.Namespace) -> None:
    """Every argument checked before any student code runs."""
    for out, suffix in ((args.junit, ".xml"), (args.csv, ".csv")):
        if out:
            check_output_path(out, [args.path], suffixes=[suffix])
    check_limits(args.timeout, args.memory)
    if args.file_timeout is not None and not args.file_timeout > 0:
        raise MeshError("must be a positive number of seconds", "--file-timeout")
    if args.jobs < 1:
        raise MeshError("must be at least 1", "--jobs")
    task_names(args.task)
    if args.export_failing and not Path(args.export_failing).is_dir():
        raise MeshError("no such folder", printable(args.export_failing))
    if args.gradescope and not Path(args.path).is_dir():
        check_output_path(args.gradescope, [args.path], suffixes=[".json"])
    elif args.gradescope and not Path(args.gradescope).resolve().parent.is_dir():
        raise MeshError("its parent folder does not exist", printable(args.gradescope))


def _warn_isolation(args: argparse.Namespace) -> None:
    """On every run without bubblewrap: say so, and how to get it (standard error)."""
    iso = choose(args.sandbox)
    if not iso.isolated:
        sys.stderr.write(f"meshlap: warning: student code runs {printable(iso.describe())}\n")


def _write(path: str, text: str) -> None:
    with atomic_write(path) as f:
        f.write(text)


def run(args: argparse.Namespace) -> int:
    _check_arguments(args)
    _warn_isolation(args)
    path = Path(args.path)
    if path.is_dir():
        return _folder(args, path)
    names = task_names(args.task)
    result = check_file(
        path, names, timeout=args.timeout, memory_mb=args.memory,
        file_timeout=args.file_timeout, require_speed=args.require_speed, sandbox=args.sandbox,
    )  # fmt: skip
    _reports(args, [result], names)
    if args.json:
        emit_json(result.to_dict())
    else:
        print(result.format_text())
    if args.export_failing:
        for f in result.export_failing(args.export_failing):
            sys.stderr.write(f"wrote {printable(f)}\n")
    return 0 if result.passed else FAILED


def _reports(args: argparse.Namespace, results: list[CheckResult], names: list[str]) -> None:
    """The files asked for: CSV, JUnit, Gradescope."""
    if args.csv:
        _write(args.csv, summary_csv(results, names))
    if args.junit:
        _write(args.junit, junit_document(results))
    if args.gradescope:
        if Path(args.path).is_dir():
            write_gradescope(results, args.gradescope)
        else:
            _write(args.gradescope, json.dumps(results[0].gradescope(), indent=1) + "\n")


def _progress(done: int, total: int, result: CheckResult) -> None:
    if sys.stderr.isatty():
        sys.stderr.write(f"\rchecked {done}/{total} ({result.submission})\x1b[K")
        if done == total:
            sys.stderr.write("\n")


def _folder(args: argparse.Namespace, folder: Path) -> int:
    names = task_names(args.task)
    results = grade_folder(
        folder, names, jobs=args.jobs, timeout=args.timeout, memory_mb=args.memory,
        file_timeout=args.file_timeout, require_speed=args.require_speed,
        sandbox=args.sandbox, progress=_progress,
    )  # fmt: skip
    _reports(args, results, names)
    if args.json:
        emit_json(class_json(results))
    elif not args.csv:
        print(summary_csv(results, names), end="")
    return 0 if all(r.passed for r in results) else FAILED
