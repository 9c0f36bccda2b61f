"""``meshlap exercises init`` and ``meshlap check`` as a student and a grader type them."""

from __future__ import annotations

import csv
import io
import json
import os
import shutil
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from meshlap_core.cli import main
from meshlap_core.exercises.tasks import EXERCISE_TASKS
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


# ---- round 4: what a single file's check must say, and write -----------------------------


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--memory", "1"], "--memory: 1 MiB is too little"),
        (["--timeout", "0"], "--timeout: must be a positive"),
        (["--jobs", "0"], "--jobs: must be at least 1"),
    ],
)
def test_a_limit_out_of_range_is_one_clear_line(args, said, capsys):
    """``--memory 1``: before, a traceback blaming the student's import."""
    assert main(["check", str(STUDENTS / "right_loops.py"), *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("meshlap: error: ") and said in err and err.count("\n") == 1


def test_a_device_or_a_fifo_is_named_for_what_it_is(tmp_path, capsys):
    """/dev/null and a FIFO: before, "no such file" (and a FIFO is never opened: it would
    block)."""
    fifo = tmp_path / "pipe.py"
    os.mkfifo(fifo)
    assert main(["check", "/dev/null"]) == 2
    assert "a character device, not a Python file" in capsys.readouterr().err
    assert main(["check", str(fifo)]) == 2
    assert "a named pipe (FIFO), not a Python file" in capsys.readouterr().err
    assert main(["check", str(tmp_path / "nope.py")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_a_single_file_writes_its_csv_and_a_task_given_twice_is_checked_once(tmp_path, capsys):
    """``--csv`` with one file (before: ignored) and ``--task`` twice (before: checked twice)."""
    out = tmp_path / "one.csv"
    code = main(["check", str(STUDENTS / "right_loops.py"), "--task", "angle_defect",
                 "--task", "angle_defect", "--csv", str(out), "--json"])  # fmt: skip
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and [t["task"] for t in data["tasks"]] == ["angle_defect"]
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    assert len(rows) == 1 and rows[0]["angle_defect"] == "passed"


def test_a_right_file_reached_through_a_link_passes(tmp_path, capsys):
    """Before: "outside its folder" (the fence compared the link's folder with the target's)."""
    link = tmp_path / "mine.py"
    link.symlink_to(STUDENTS / "right_loops.py")
    assert main(["check", str(link), "--task", "barycentric_areas"]) == 0
    assert "1/1 tasks passed" in capsys.readouterr().out


def test_control_characters_in_a_file_name_are_escaped(tmp_path, capsys):
    """A name holding an escape sequence or a newline: before, printed raw (recolouring the
    terminal, breaking the CSV row and the JUnit document)."""
    folder = tmp_path / "class"
    folder.mkdir()
    evil = "ev\x1b[31mil\nrow.py"
    shutil.copy(STUDENTS / "wrong_uniform_sign.py", folder / evil)
    junit = tmp_path / "out.xml"
    code = main(["check", str(folder), "--task", "uniform_laplacian", "--junit", str(junit)])
    out = capsys.readouterr().out
    assert code == 3
    assert "\x1b" not in out and "\\x1b[31m" in out and len(out.splitlines()) == 2
    root = ET.parse(junit).getroot()  # well-formed
    assert "\\x1b" in root.find("testsuite").get("name")
    single = main(["check", str(folder / evil), "--task", "uniform_laplacian"])
    text = capsys.readouterr().out
    assert single == 3 and "\x1b" not in text and "ev\\x1b[31mil\\nrow.py" in text


def test_without_bubblewrap_every_run_says_it_is_not_isolated(capsys):
    code = main(["check", str(STUDENTS / "right_loops.py"), "--task", "barycentric_areas",
                 "--sandbox", "process"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0
    assert "meshlap: warning: student code runs NOT isolated" in err
    assert "apt-get install bubblewrap" in err
    assert "sandbox: NOT isolated" in out


def test_asking_for_bubblewrap_where_it_does_not_work_is_an_error(monkeypatch, capsys):
    from meshlap_core.exercises import isolation

    monkeypatch.setattr(isolation, "bwrap_problem", lambda: "bubblewrap is not installed")
    code = main(["check", str(STUDENTS / "right_loops.py"), "--sandbox", "bwrap"])
    err = capsys.readouterr().err
    assert code == 2 and "bubblewrap does not work here: bubblewrap is not installed" in err


def test_the_failing_mesh_can_be_exported_and_a_gradescope_file_written(tmp_path, capsys):
    """A student reproduces a failure on the mesh it happened on: the mesh (.obj) and the
    call's arguments (.npz); Gradescope's results.json for one submission."""
    out = tmp_path / "results.json"
    code = main(["check", str(STUDENTS / "wrong_uniform_sign.py"), "--task",
                 "uniform_laplacian", "--export-failing", str(tmp_path), "--gradescope",
                 str(out)])  # fmt: skip
    assert code == 3
    obj = tmp_path / "uniform_laplacian_one_triangle.obj"
    from meshlap_core.io import load_mesh

    mesh = load_mesh(obj)
    assert mesh.V.shape == (3, 3)
    with np.load(tmp_path / "uniform_laplacian_one_triangle.npz") as args:
        assert np.array_equal(args["a0"], mesh.V) and args["a1"].shape == (1, 3)
    results = json.loads(out.read_text())
    assert results["score"] == 0 and results["max_score"] == 1
    test = results["tests"][0]
    assert test["status"] == "failed" and "sign flip" in test["output"]
