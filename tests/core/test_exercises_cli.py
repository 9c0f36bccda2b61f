"""``meshlap exercises init`` and ``meshlap check`` as a student and a grader type them."""

from __future__ import annotations

import csv
import io
import json
import shutil
import xml.etree.ElementTree as ET

import pytest

from meshlap_core.cli import main
from meshlap_core.options import EXERCISE_TASKS
from tests.support.students import STUDENTS


def test_init_writes_the_template_and_never_overwrites(tmp_path, capsys):
    assert main(["exercises", "init", str(tmp_path / "hw")]) == 0
    target = tmp_path / "hw" / "exercises.py"
    text = target.read_text()
    assert all(f"def {t}(" in text for t in EXERCISE_TASKS)
    assert "meshlap check" in capsys.readouterr().out
    target.write_text("# my work\n")
    assert main(["exercises", "init", str(tmp_path / "hw")]) == 2
    assert "--force" in capsys.readouterr().err
    assert target.read_text() == "# my work\n"  # untouched
    assert main(["exercises", "init", str(tmp_path / "hw"), "--force"]) == 0
    assert target.read_text() == text
    assert [p.name for p in (tmp_path / "hw").iterdir()] == ["exercises.py"]  # no temp left


def test_check_text_json_and_junit(tmp_path, capsys):
    student = STUDENTS / "wrong_uniform_sign.py"
    junit = tmp_path / "out.xml"
    code = main(["check", str(student), "--task", "uniform_laplacian", "--junit", str(junit)])
    out = capsys.readouterr().out
    assert code == 3
    assert "FAILED" in out and "sign flip" in out and "at vertex" in out
    suite = ET.parse(junit).getroot().find("testsuite")
    assert suite.get("tests") == "1" and suite.get("failures") == "1"
    assert "sign flip" in suite.find("testcase/failure").get("message")

    assert main(["check", str(STUDENTS / "right_loops.py"), "--task", "one_ring", "--json"]) == 3
    data = json.loads(capsys.readouterr().out)
    assert data["tasks"][0]["status"] == "missing" and data["passed"] == 0

    code = main(["check", str(STUDENTS / "right_loops.py"), "--task", "angle_defect", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and data["tasks"][0]["passed"] is True


def test_check_rejects_an_unknown_task_and_a_missing_file(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["check", str(STUDENTS / "right_loops.py"), "--task", "nope"])
    assert exit_.value.code == 2
    assert main(["check", "/nonexistent/student.py"]) == 2
    err = capsys.readouterr().err
    assert err.count("meshlap: error:") == 2


def test_a_folder_of_submissions_gives_one_csv_row_each_isolated(tmp_path, capsys):
    folder = tmp_path / "submissions"
    folder.mkdir()
    shutil.copy(STUDENTS / "right_vectorized.py", folder / "alice.py")
    shutil.copy(STUDENTS / "hostile_crash.py", folder / "bob.py")  # dies in uniform_laplacian
    shutil.copy(STUDENTS / "wrong_uniform_graph.py", folder / "carol.py")
    out_csv = tmp_path / "summary.csv"
    code = main(
        ["check", str(folder), "--task", "uniform_laplacian", "--task", "barycentric_areas",
         "--csv", str(out_csv), "--timeout", "20"]
    )  # fmt: skip
    assert code == 3
    rows = list(csv.DictReader(io.StringIO(out_csv.read_text())))
    by = {r["file"]: r for r in rows}
    assert by["alice.py"]["uniform_laplacian"] == "passed" and by["alice.py"]["passed"] == "2"
    assert by["bob.py"]["uniform_laplacian"] == "crashed"
    assert by["bob.py"]["barycentric_areas"] == "passed"  # the crash did not take it along
    assert by["carol.py"]["uniform_laplacian"] == "failed (graph_not_normalised)"
    assert by["carol.py"]["barycentric_areas"] == "missing"
