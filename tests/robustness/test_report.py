"""Robustness (issue 8) of ``meshlap report``: bad arguments fail at once in one line; a
corrupt course mesh fails its section only, named, and the report is still written."""

from __future__ import annotations

import pytest

from meshlap_core.cli import COMMANDS, main
from tests.support import hostile

pytestmark = pytest.mark.skipif(
    "report" not in COMMANDS, reason="the report command is not registered yet"
)


@pytest.fixture(autouse=True)
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))


@pytest.mark.parametrize(
    ("argv", "names"),
    [
        (["--out", "{file}", "--sections", "onering"], ("{file}", "not a directory")),
        (["--meshes", "{file}", "--sections", "onering"], ("{file}", "not a directory")),
        (["--meshes", "{tmp}/nowhere", "--sections", "onering"], ("nowhere",)),
        (["--sections", "bogus"], ("--sections",)),
        (["--sections", "0"], ("--sections",)),
        (["--sections", ""], ("--sections",)),
    ],
)
def test_report_bad_arguments_one_line(capsys, tmp_path, argv, names):
    file = tmp_path / "afile"
    file.write_text("not a folder\n")
    code = main(["report", *[a.format(file=file, tmp=tmp_path) for a in argv]])
    out, err = capsys.readouterr()
    assert code == 2 and out == "", err
    assert err.count("\n") == 1 and err.startswith("meshlap: error: "), err
    for n in names:
        assert n.format(file=file) in err
    assert file.read_text() == "not a folder\n"
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "cache") == ["afile"]


def test_report_corrupt_course_mesh_fails_its_section_only(capsys, tmp_path):
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    (meshes / "cube.obj").write_bytes(hostile.build("garbage.obj", tmp_path).read_bytes())
    out = tmp_path / "report"
    code = main(
        [
            "report",
            "--meshes",
            str(meshes),
            "--out",
            str(out),
            "--sections",
            "onering",
            "--quick",
            "--no-screenshots",
        ]
    )
    _, err = capsys.readouterr()
    assert code != 0 and "Traceback" not in err
    errors = [line for line in err.splitlines() if line.startswith("meshlap: error: ")]
    assert len(errors) == 1 and "cube.obj" in errors[0] and "binary data" in errors[0]
    assert (out / "report.md").is_file() and (out / "report.html").is_file()
    assert "cube.obj" in (out / "report.md").read_text()
    assert not any(out.rglob(".*.tmp"))
