"""Hostile student files, one per attack class, graded as a class would be — under bubblewrap
and forced without it (``--sandbox process``): no PASS that was not earned, nothing written or
read outside the student's copy, no process left behind, the checker's standard output its own,
and the folder run complete.

Each class has its file in ``tests/exercises/`` (named by what it does); the docstring of each
test says what the checker did with it before this fix. One folder run per isolation level
(``graded``) holds them all, each as a student's subfolder, beside right and wrong students and
a classmate whose files must stay untouched.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from meshlap_core.cli import main
from meshlap_core.exercises.compare import COMPARE
from meshlap_core.exercises.grading import grade_folder
from meshlap_core.exercises.isolation import bwrap_problem
from tests.support.students import STUDENTS

BWRAP = pytest.param(
    "bwrap",
    marks=pytest.mark.skipif(bwrap_problem() is not None, reason=f"{bwrap_problem()}"),
)
MODES = [BWRAP, "process"]
HOSTILE = [
    "hostile_pickle_payload", "hostile_forged_finish", "hostile_reference_grab",
    "hostile_memory_raise", "hostile_clock_patch", "hostile_fork_survivor",
    "hostile_write_outside", "hostile_stdout_inject", "hostile_unreadable_answer",
    "hostile_network", "hostile_exit",
]  # fmt: skip
TASKS = [
    "uniform_laplacian", "cotan_laplacian", "barycentric_areas", "voronoi_areas", "mass_matrix",
    "mean_curvature", "angle_defect",
]  # fmt: skip
PICKLE_MARKER = Path("/tmp/meshlap_hostile_pickle_ran")
CLASSMATE = "# carol's own file: nobody else writes here\n"


def _tree(root: Path) -> dict[str, bytes]:
    return {os.fspath(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def _orphans() -> list[int]:
    """Processes named ``meshlap-orphan`` (hostile_fork_survivor's child, if it ever ran)."""
    found = []
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            try:
                with open(f"{entry.path}/comm") as f:
                    if f.read().strip() == "meshlap-orphan":
                        found.append(int(entry.name))
            except OSError:
                continue
    return found


@pytest.fixture(scope="module", params=MODES)
def graded(request, tmp_path_factory):
    """One class folder graded at one isolation level: the hostile students (each a folder,
    ``hostile_write_outside`` told where the class is), a right student with a helper module,
    a wrong student after the pickle payload, a folder with no exercises file, and carol."""
    mode = request.param
    root = tmp_path_factory.mktemp(f"class-{mode}")
    klass = root / "class"
    for name in HOSTILE:
        (klass / name).mkdir(parents=True)
        shutil.copy(STUDENTS / f"{name}.py", klass / name / "exercises.py")
    carol = klass / "zz_carol"
    carol.mkdir()
    shutil.copy(STUDENTS / "right_loops.py", carol / "exercises.py")
    (carol / "classmate.py").write_text(CLASSMATE)
    (klass / "hostile_write_outside" / "target.txt").write_text(os.fspath(carol))
    (klass / "right_with_helper").mkdir()
    shutil.copy(STUDENTS / "right_helper_module.py", klass / "right_with_helper" / "hw.py")
    shutil.copy(STUDENTS / "mesh_helpers.py", klass / "right_with_helper" / "mesh_helpers.py")
    shutil.copy(STUDENTS / "wrong_uniform_sign.py", klass / "zz_wrong_after_payload.py")
    (klass / "empty_student").mkdir()
    (klass / "empty_student" / "notes.txt").write_text("nothing to grade\n")
    PICKLE_MARKER.unlink(missing_ok=True)
    before = _tree(root)
    compare_before = dict(COMPARE)
    results = grade_folder(klass, TASKS, jobs=2, timeout=8.0, sandbox=mode)
    return {
        "mode": mode,
        "root": root,
        "by": {r.submission: r for r in results},
        "results": results,
        "before": before,
        "after": _tree(root),
        "compare_intact": dict(COMPARE) == compare_before,
    }


def test_the_folder_run_is_complete_whatever_the_students_did(graded):
    """Every submission has its row, the run's reports exist; before, an answer that raised
    when unpickled, or a student whose file imported a helper beside it, made the whole folder
    run exit 1 with no CSV or JUnit, and a folder of student folders was refused."""
    by = graded["by"]
    assert set(by) == {*HOSTILE, "zz_carol", "right_with_helper", "zz_wrong_after_payload",
                       "empty_student"}  # fmt: skip
    assert by["right_with_helper"]["barycentric_areas"].passed, by[
        "right_with_helper"
    ].format_text()
    assert by["zz_carol"]["uniform_laplacian"].passed
    assert all(t.status == "error" for t in by["empty_student"].tasks)
    assert "no exercises.py" in by["empty_student"].tasks[0].message
    unreadable = by["hostile_unreadable_answer"]
    assert unreadable["uniform_laplacian"].status == "error"  # its __array__ raised
    assert unreadable["barycentric_areas"].diagnosis == "not_numbers"  # a dict
    assert unreadable["voronoi_areas"].diagnosis == "not_numbers"  # a generator
    assert unreadable["mass_matrix"].diagnosis == "no_answer"  # None
    iso = by["zz_carol"].isolation
    assert iso["level"] == graded["mode"] and iso["isolated"] == (graded["mode"] == "bwrap")


def test_an_unpickling_payload_never_runs_in_the_checker(graded):
    """hostile_pickle_payload returns objects whose unpickling would write a marker and make
    every later comparison pass: before, the worker's answers were unpickled in the checker.
    Now answers are plain arrays: the task fails, the comparison is untouched, a wrong file
    graded after it still fails."""
    r = graded["by"]["hostile_pickle_payload"]
    assert not any(t.passed for t in r.tasks), r.format_text()
    assert not PICKLE_MARKER.exists()
    assert graded["compare_intact"]
    wrong = graded["by"]["zz_wrong_after_payload"]["uniform_laplacian"]
    assert wrong.status == "failed" and wrong.diagnosis == "sign_flip"


def test_a_forged_finish_passes_nothing(graded):
    """hostile_forged_finish writes the checker's channel itself (found through gc): before,
    15/15 passed with no task ever called. Now a forged line is named, and a task passes only on
    answers it gave."""
    r = graded["by"]["hostile_forged_finish"]
    assert r.n_passed == 0, r.format_text()
    assert any(t.diagnosis == "tampers" for t in r.tasks), r.format_text()


def test_the_reference_is_out_of_reach(graded):
    """hostile_reference_grab looks for meshlap in its process and imports it past the guard:
    before, the reference ran in the student's process (``sys.modules`` handed it over). The
    harness imports no meshlap module and (bubblewrap) cannot even see its files."""
    r = graded["by"]["hostile_reference_grab"]["cotan_laplacian"]
    assert not r.passed, r.lines()


def test_the_limits_cannot_be_lifted(graded):
    """hostile_memory_raise raises its soft memory limit to the hard one and fills 3 GB;
    hostile_clock_patch stops its own clocks and runs 200 s under an 8 s limit: before, the
    first allocated 3 GB and the second ran 181 s (the worker set its own deadline). Limits are
    soft = hard, the clock is the checker's; the next task passes."""
    memory = graded["by"]["hostile_memory_raise"]
    assert memory["uniform_laplacian"].status == "memory", memory.format_text()
    assert memory["barycentric_areas"].passed
    clock = graded["by"]["hostile_clock_patch"]
    assert clock["uniform_laplacian"].status == "timeout", clock.format_text()
    assert clock["barycentric_areas"].passed


def test_no_process_outlives_the_check(graded):
    """hostile_fork_survivor forks through ctypes and leaves the process group: before, only the
    worker was killed and the child lived on. The C call is refused, and nothing is left."""
    r = graded["by"]["hostile_fork_survivor"]
    assert r["uniform_laplacian"].status == "refused", r.format_text()
    assert r["uniform_laplacian"].diagnosis == "native_calls"
    assert r["barycentric_areas"].passed
    assert not _orphans()
    assert all(x.survivors == 0 for x in graded["results"])


def test_nothing_is_written_or_read_outside_the_students_copy(graded):
    """hostile_write_outside tries os.mkdir, os.symlink, os.link, sqlite3 and libc through
    ctypes on the folder above its own and on a classmate's folder: before, one file overwrote
    a classmate's file and another ran a classmate's solution. Every attempt is refused, and the
    class folder is byte for byte what it was."""
    r = graded["by"]["hostile_write_outside"]
    for task in ("barycentric_areas", "voronoi_areas", "mean_curvature", "angle_defect",
                 "mass_matrix"):  # fmt: skip
        assert r[task].status == "refused", r[task].lines()
        assert r[task].diagnosis in ("outside_folder", "native_calls"), r[task].lines()
    assert graded["after"] == graded["before"]


def test_the_network_is_refused(graded):
    r = graded["by"]["hostile_network"]["barycentric_areas"]
    assert r.status == "refused" and r.diagnosis == "uses_network", r.lines()


def test_sys_exit_is_reported_as_such(graded):
    """hostile_exit calls sys.exit() in a task: before, "crash in native code (exit -9)" with a
    traceback. Now it is named; the next task passes."""
    r = graded["by"]["hostile_exit"]
    t = r["uniform_laplacian"]
    assert t.status == "error" and t.diagnosis == "calls_exit", t.lines()
    assert "native code" not in "\n".join(t.lines())
    assert r["barycentric_areas"].passed


def test_what_a_file_prints_is_in_its_log(graded):
    r = graded["by"]["hostile_stdout_inject"]
    assert r["barycentric_areas"].passed
    assert "INJECTED print" in r.log and "forged" in r.log and r.log_bytes >= len(r.log) > 0


@pytest.mark.parametrize("mode", MODES)
def test_the_checkers_standard_output_is_its_own(mode, tmp_path, capfd):
    """hostile_stdout_inject writes to file descriptors 1 and 2: before, its line landed in
    ``--json`` and in the folder CSV. Now the student's output goes to the report's log."""
    path = STUDENTS / "hostile_stdout_inject.py"
    code = main(["check", str(path), "--task", "barycentric_areas", "--json", "--sandbox", mode])
    out, err = capfd.readouterr()
    assert code == 0
    data = json.loads(out)  # one document, nothing else
    assert data["passed"] == 1 and "INJECTED" in data["log"] and "INJECTED" not in err
    folder = tmp_path / "class"
    folder.mkdir()
    shutil.copy(path, folder / "mallory.py")
    shutil.copy(STUDENTS / "right_vectorized.py", folder / "alice.py")
    code = main(["check", str(folder), "--task", "barycentric_areas", "--sandbox", mode])
    out, _ = capfd.readouterr()
    assert code == 0
    assert out.splitlines() == [
        "submission,file,passed,total,barycentric_areas",
        "alice,alice.py,1,1,passed",
        "mallory,mallory.py,1,1,passed",
    ]
