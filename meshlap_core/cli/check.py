"""``meshlap check FILE|DIR [--task NAME] [--json] [--junit OUT.xml] [--csv OUT.csv]``.

Check a student file written from ``meshlap exercises init``: each task runs in a separate
process with a time and memory limit and is compared with the reference on a battery of meshes;
every failure names the mesh, the vertex, expected vs got and the likely mistake. A folder
checks every ``*.py`` in it, each submission in its own processes, and prints a CSV summary
(one row per file, one column per task).

Exit codes: 0 every task passed; 3 some task did not pass; 2 bad arguments (one line).
"""

from __future__ import annotations

import argparse
import csv
import io
import os
from pathlib import Path

from ..errors import MeshError
from ..exercises import CheckResult, check_file
from ..exercises.result import junit_document
from ..io.atomic import atomic_write, check_output_path
from ..options import EXERCISE_MEMORY_MB, EXERCISE_TASKS, EXERCISE_TIMEOUT
from ._common import add_json_flag, emit_json

FAILED = 3


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("check", help="check a student's exercises file (or a folder of them)")
    p.add_argument("path", help="the student's .py file, or a folder of submissions")
    p.add_argument(
        "--task", action="append", choices=EXERCISE_TASKS, metavar="NAME",
        help=f"check only this task (repeatable): {', '.join(EXERCISE_TASKS)}",
    )  # fmt: skip
    add_json_flag(p)
    p.add_argument("--junit", metavar="OUT.xml", help="also write a JUnit XML report")
    p.add_argument("--csv", metavar="OUT.csv", help="folder: write the summary here (not stdout)")
    p.add_argument("--timeout", type=float, default=EXERCISE_TIMEOUT, help="seconds per task")
    p.add_argument("--memory", type=int, default=EXERCISE_MEMORY_MB, help="MiB per submission")
    p.set_defaults(func=run)


def _outputs(args: argparse.Namespace) -> None:
    for out, suffix in ((args.junit, ".xml"), (args.csv, ".csv")):
        if out:
            check_output_path(out, [args.path], suffixes=[suffix])
    if args.timeout <= 0 or args.memory <= 0:
        raise MeshError("must be positive", "--timeout" if args.timeout <= 0 else "--memory")


def run(args: argparse.Namespace) -> int:
    _outputs(args)
    path = Path(args.path)
    if path.is_dir():
        return _folder(args, path)
    result = check_file(path, args.task, timeout=args.timeout, memory_mb=args.memory)
    if args.json:
        emit_json(result.to_dict())
    else:
        print(result.format_text())
    if args.junit:
        with atomic_write(args.junit) as f:
            f.write(result.to_junit())
    return 0 if result.passed else FAILED


def summary_csv(results: list[CheckResult], tasks: list[str]) -> str:
    """One row per submission: file, passed, total, then each task's status (diagnosis)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["file", "passed", "total", *tasks])
    for r in results:
        cells = []
        for name in tasks:
            t = r[name]
            cells.append(t.status + (f" ({t.diagnosis})" if t.diagnosis else ""))
        w.writerow([os.path.basename(r.file), r.n_passed, len(r.tasks), *cells])
    return buf.getvalue()


def _folder(args: argparse.Namespace, folder: Path) -> int:
    files = sorted(p for p in folder.glob("*.py") if p.is_file())
    if not files:
        raise MeshError("no .py submissions in this folder", os.fspath(folder))
    tasks = list(args.task or EXERCISE_TASKS)
    results = [check_file(f, tasks, timeout=args.timeout, memory_mb=args.memory) for f in files]
    text = summary_csv(results, tasks)
    if args.csv:
        with atomic_write(args.csv) as f:
            f.write(text)
    elif not args.json:
        print(text, end="")
    if args.json:
        emit_json({"submissions": [r.to_dict() for r in results]})
    if args.junit:
        with atomic_write(args.junit) as f:
            f.write(junit_document(results))
    return 0 if all(r.passed for r in results) else FAILED
