"""Grading a class: N generated submissions (right, wrong and hostile students, as files and as
student folders) graded by ``meshlap check FOLDER --jobs J`` into CSV, JUnit, JSON and
Gradescope's ``results.json``; every row checked against what its student wrote; files per
minute beside the same class graded one at a time (``--jobs 1``, on the first ``--serial``
submissions).

    python benchmarks/bench_grading.py                      # 200 submissions, --jobs 2
    python benchmarks/bench_grading.py --files 12 --serial 0  # the test suite's small run

Every submission is a copy of a student file of ``tests/exercises/`` under a new name (every
third one a student's folder with ``exercises.py``), so that each row's right answer is known:
:data:`MIX` says, per file, the cell each task must get. The script exits 1 when a row, a JUnit
test case or a ``results.json`` is not what it must be. Timings depend on the machine's load,
printed beside them.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

STUDENTS = Path(__file__).resolve().parents[1] / "tests" / "exercises"
TASKS = ("uniform_laplacian", "cotan_laplacian", "barycentric_areas", "angle_defect")
MIX: list[tuple[str, dict[str, str]]] = [  # (student file, the cell of each task it defines)
    ("right_vectorized", dict.fromkeys(TASKS, "passed")),
    ("wrong_uniform_sign", {"uniform_laplacian": "failed (sign_flip)"}),
    ("hostile_crash", {"uniform_laplacian": "crashed", "barycentric_areas": "passed"}),
    ("wrong_cotan_full", {"cotan_laplacian": "failed (cot_not_half)"}),
    ("hostile_pickle_payload", {"uniform_laplacian": "error", "barycentric_areas": "error"}),
    ("right_loops", dict.fromkeys(TASKS, "passed")),
    ("hostile_forged_finish", dict.fromkeys(TASKS, "error (tampers)")),
    ("wrong_areas", {"barycentric_areas": "failed (not_divided_by_3)"}),
    ("hostile_stdout_inject", {"barycentric_areas": "passed"}),
    ("wrong_cotan_nan", {"cotan_laplacian": "failed (nan_on_degenerate)"}),
    (
        "hostile_spawn",
        {
            "uniform_laplacian": "refused (spawns_process)",
            "barycentric_areas": "refused (spawns_process)",
        },
    ),
    ("right_igl", {"cotan_laplacian": "passed", "angle_defect": "passed"}),
    ("wrong_defect", {"angle_defect": "failed (missing_boundary_term)"}),
    ("hostile_exit", {"uniform_laplacian": "error (calls_exit)", "barycentric_areas": "passed"}),
    ("wrong_cotan_dense", {"cotan_laplacian": "memory (dense_at_size)"}),
    ("hostile_memory", {"uniform_laplacian": "memory", "barycentric_areas": "passed"}),
    ("right_other_order", dict.fromkeys(TASKS, "passed")),
    ("hostile_network", {"barycentric_areas": "refused (uses_network)"}),
    ("wrong_float32", {"cotan_laplacian": "failed (single_precision)"}),
    (
        "hostile_fork_survivor",
        {"uniform_laplacian": "refused (native_calls)", "barycentric_areas": "passed"},
    ),
    ("cheat_import", dict.fromkeys(TASKS, "import_error (imports_meshlap)")),
    (
        "hostile_write_outside",
        {
            "barycentric_areas": "refused (outside_folder)",
            "angle_defect": "refused (outside_folder)",
        },
    ),
    ("wrong_cotan_clamped", {"cotan_laplacian": "failed (clamped_weights)"}),
    ("hostile_loop", {"uniform_laplacian": "timeout", "barycentric_areas": "passed"}),
    ("hostile_clock_patch", {"uniform_laplacian": "timeout", "barycentric_areas": "passed"}),
]
"""The class's students, cycled; a task a file does not define is ``missing``."""


def make_class(folder: Path, count: int) -> dict[str, dict[str, str]]:
    """``count`` submissions in ``folder``; submission name -> the cells it must get."""
    expected = {}
    for i in range(count):
        source, cells = MIX[i % len(MIX)]
        name = f"s{i:03d}_{source}"
        if i % 3 == 2:  # a student's folder
            (folder / name).mkdir()
            shutil.copy(STUDENTS / f"{source}.py", folder / name / "exercises.py")
        else:
            shutil.copy(STUDENTS / f"{source}.py", folder / f"{name}.py")
        expected[name] = {t: cells.get(t, "missing") for t in TASKS}
    return expected


def grade(folder: Path, out: Path, jobs: int, timeout: float, sandbox: str) -> float:
    """``meshlap check`` on the class; its wall seconds (reports in ``out``)."""
    out.mkdir(parents=True, exist_ok=True)
    argv = [sys.executable, "-m", "meshlap_core.cli", "check", str(folder), "--jobs", str(jobs),
            "--timeout", str(timeout), "--sandbox", sandbox, "--csv", str(out / "class.csv"),
            "--junit", str(out / "class.xml"), "--gradescope", str(out / "gradescope"),
            *[a for t in TASKS for a in ("--task", t)]]  # fmt: skip
    t0 = time.perf_counter()
    res = subprocess.run(argv, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if res.returncode not in (0, 3):
        raise SystemExit(f"meshlap check exited {res.returncode}: {res.stderr.strip()}")
    return seconds


def wrong_rows(out: Path, expected: dict[str, dict[str, str]]) -> list[str]:
    """Every way the reports differ from what the students wrote (empty: all right)."""
    problems = []
    rows = {r["submission"]: r for r in csv.DictReader((out / "class.csv").open())}
    if set(rows) != set(expected):
        problems.append(f"CSV rows {sorted(set(rows) ^ set(expected))} missing or extra")
    for name, cells in expected.items():
        got = {t: rows.get(name, {}).get(t) for t in TASKS}
        if got != cells:
            problems.append(f"{name}: {got} != {cells}")
    suites = ET.parse(out / "class.xml").getroot().findall("testsuite")
    names = {c.get("classname") for s in suites for c in s.findall("testcase")}
    if len(suites) != len(expected) or names != set(expected):
        problems.append(f"JUnit: {len(suites)} suites for {len(expected)} submissions")
    for name, cells in expected.items():
        path = out / "gradescope" / name / "results.json"
        if not path.is_file():
            problems.append(f"{name}: no results.json")
            continue
        score = json.loads(path.read_text())["score"]
        if score != sum(c == "passed" for c in cells.values()):
            problems.append(f"{name}: results.json score {score}")
    return problems


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--files", type=int, default=200)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--serial", type=int, default=20, help="submissions graded one at a time")
    p.add_argument("--timeout", type=float, default=5.0, help="seconds per task")
    p.add_argument("--sandbox", default="auto", choices=("auto", "bwrap", "process"))
    args = p.parse_args()
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench-grading-") as tmp:
        root = Path(tmp)
        (root / "class").mkdir()
        expected = make_class(root / "class", args.files)
        seconds = grade(root / "class", root / "out", args.jobs, args.timeout, args.sandbox)
        problems = wrong_rows(root / "out", expected)
        rows = [(f"--jobs {args.jobs}", args.files, seconds)]
        if args.serial:
            (root / "serial").mkdir()
            sample = make_class(root / "serial", min(args.serial, args.files))
            s = grade(root / "serial", root / "out1", 1, args.timeout, args.sandbox)
            problems += wrong_rows(root / "out1", sample)
            rows.append(("--jobs 1", len(sample), s))
    print(f"| run | submissions | seconds | files per minute |  (load {load:.1f})")
    print("|---|---|---|---|")
    for run, n, s in rows:
        print(f"| {run} | {n} | {s:.1f} | {60 * n / s:.1f} |")
    if problems:
        print("WRONG ROWS:\n" + "\n".join(problems))
        return 1
    print(f"{args.files} submissions, every row right (CSV, JUnit, results.json)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
