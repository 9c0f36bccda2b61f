"""Grading a class: a folder of students' files and students' folders, checked in parallel,
each in a copy of its own, into CSV, JSON, JUnit and Gradescope's ``results.json``; one
student's failure is that student's row, never the run's."""

from __future__ import annotations

import csv
import io
import json
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from meshlap_core.cli import main
from meshlap_core.exercises import grading
from meshlap_core.exercises.grading import grade_folder
from tests.support.students import STUDENTS

BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_grading.py"
TASKS = ["uniform_laplacian", "barycentric_areas"]


@pytest.fixture
def klass(tmp_path):
    """alice.py (right), bob/ (right, a helper module beside his file), carol.py (wrong),
    dave/ (no exercises file)."""
    folder = tmp_path / "class"
    folder.mkdir()
    shutil.copy(STUDENTS / "right_vectorized.py", folder / "alice.py")
    (folder / "bob").mkdir()
    shutil.copy(STUDENTS / "right_helper_module.py", folder / "bob" / "exercises.py")
    shutil.copy(STUDENTS / "mesh_helpers.py", folder / "bob" / "mesh_helpers.py")
    shutil.copy(STUDENTS / "wrong_uniform_sign.py", folder / "carol.py")
    (folder / "dave").mkdir()
    (folder / "dave" / "README.txt").write_text("I did not do it\n")
    return folder


def test_a_class_is_graded_into_every_report(klass, tmp_path, capsys):
    """``--jobs 2`` into CSV, JUnit (a ``classname`` per student, the diagnosis as the failure's
    message, ``time``), JSON and ``results.json`` per student; exit 3 (some task failed)."""
    out = tmp_path / "out"
    out.mkdir()
    argv = ["check", str(klass), "--jobs", "2", "--csv", str(out / "c.csv"), "--junit",
            str(out / "j.xml"), "--gradescope", str(out / "gs"), "--json"]  # fmt: skip
    code = main(argv + [a for t in TASKS for a in ("--task", t)])
    data = json.loads(capsys.readouterr().out)
    assert code == 3
    assert [s["submission"] for s in data["submissions"]] == ["alice", "bob", "carol", "dave"]
    rows = {r["submission"]: r for r in csv.DictReader(io.StringIO((out / "c.csv").read_text()))}
    assert rows["alice"]["passed"] == "2" and rows["bob"]["barycentric_areas"] == "passed"
    assert rows["bob"]["file"] == "bob/exercises.py"
    assert rows["carol"]["uniform_laplacian"] == "failed (sign_flip)"
    assert rows["dave"]["uniform_laplacian"] == "error"
    suites = ET.parse(out / "j.xml").getroot().findall("testsuite")
    cases = {(c.get("classname"), c.get("name")): c for s in suites for c in s}
    assert {k[0] for k in cases} == {"alice", "bob", "carol", "dave"}
    failure = cases[("carol", "uniform_laplacian")].find("failure")
    assert failure.get("message").startswith("sign flip")
    assert all(float(s.get("time")) >= 0 for s in suites)
    gs = json.loads((out / "gs" / "carol" / "results.json").read_text())
    assert gs["score"] == 0 and gs["max_score"] == 2
    assert {t["name"]: t["status"] for t in gs["tests"]} == {
        "uniform_laplacian": "failed", "barycentric_areas": "failed",
    }  # fmt: skip
    assert json.loads((out / "gs" / "alice" / "results.json").read_text())["score"] == 2


def test_a_submission_the_checker_cannot_check_is_its_own_error_row(klass, monkeypatch):
    """The checker itself failing on one file (here made to raise): that student's row says
    so, the others are graded."""
    real = grading.check_file

    def flaky(path, *args, **kwargs):
        if Path(path).name == "carol.py":
            raise RuntimeError("a checker bug")
        return real(path, *args, **kwargs)

    monkeypatch.setattr(grading, "check_file", flaky)
    results = {r.submission: r for r in grade_folder(klass, TASKS, jobs=2)}
    assert results["alice"].passed
    assert all(t.status == "error" for t in results["carol"].tasks)
    assert "a checker bug" in results["carol"].tasks[0].message


def test_a_classmates_file_is_not_copied_with_a_student_who_imports_it(tmp_path):
    """In a class folder of files, ``import alice`` does not bring alice's solution along:
    a file beside it that defines a task is another student's, and is not copied."""
    folder = tmp_path / "class"
    folder.mkdir()
    shutil.copy(STUDENTS / "right_vectorized.py", folder / "alice.py")
    (folder / "mallory.py").write_text("from alice import barycentric_areas  # noqa: F401\n")
    results = {r.submission: r for r in grade_folder(folder, ["barycentric_areas"])}
    mallory = results["mallory"]
    assert mallory["barycentric_areas"].status == "import_error"
    assert any("another student's file" in n for n in mallory.notes)
    assert results["alice"].passed


def test_a_link_out_of_a_submission_is_never_followed(tmp_path):
    """A link inside a student's folder to a file outside it, or a class folder's entry that
    is such a link, is not followed (the checker would read the file for the student): the copy
    leaves it out, the report says so."""
    folder = tmp_path / "class" / "eve"
    folder.mkdir(parents=True)
    shutil.copy(STUDENTS / "right_vectorized.py", folder / "exercises.py")
    secret = tmp_path / "secret.txt"
    secret.write_text("the teacher's notes\n")
    (folder / "notes.txt").symlink_to(secret)
    (tmp_path / "class" / "trudy.py").symlink_to(secret)  # a "submission" that is a link out
    eve, trudy = grade_folder(tmp_path / "class", ["barycentric_areas"])
    assert eve.passed
    assert any("notes.txt" in n and "outside the submission" in n for n in eve.notes)
    assert trudy.tasks[0].status == "error" and "outside the class folder" in trudy.tasks[0].message


def test_the_class_benchmark_grades_every_row_right(python_ok):
    """``benchmarks/bench_grading.py`` on 12 generated submissions (right, wrong, hostile;
    files and folders): every CSV row, JUnit case and results.json is what the student wrote.
    The 200-submission run and its timings are the benchmark's, not a test's."""
    out = python_ok(BENCH, "--files", "12", "--serial", "0", "--timeout", "5").stdout
    assert "12 submissions, every row right" in out, out


def test_a_submission_stops_at_its_time_cap(tmp_path):
    """``file_timeout``: the task running when the cap passes, and every task after it, are
    ``timeout`` with the cap named (an endless loop under a 30 s task limit, a 3 s cap)."""
    folder = tmp_path / "class"
    folder.mkdir()
    shutil.copy(STUDENTS / "hostile_loop.py", folder / "zed.py")
    (result,) = grade_folder(folder, TASKS, timeout=30.0, file_timeout=3.0)
    loop, after = result["uniform_laplacian"], result["barycentric_areas"]
    assert loop.status == "timeout" and "time cap" in loop.message, loop.lines()
    assert after.status == "timeout" and "time cap" in after.message, after.lines()
