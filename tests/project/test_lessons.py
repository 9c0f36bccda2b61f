"""The lessons (``docs/lessons/NN_*.ipynb``) run top to bottom in a Jupyter kernel with no
cell raising, each draws at least one picture (an ``image/png`` output), its pictures come
from the viewer's EGL renderer where EGL starts, and its exercise check passes (the lesson's
last cells assert it); the notebooks are what ``build_lessons.py`` writes from their sources."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="the test extra: pip install -e '.[test]'")
nbclient = pytest.importorskip("nbclient", reason="the test extra: pip install -e '.[test]'")

ROOT = Path(__file__).resolve().parents[2]
LESSONS = ROOT / "docs" / "lessons"
NOTEBOOKS = sorted(LESSONS.glob("[0-9][0-9]_*.ipynb"))


def test_there_are_six_lessons_each_from_its_source():
    assert [p.name[:2] for p in NOTEBOOKS] == ["01", "02", "03", "04", "05", "06"]
    sources = sorted((LESSONS / "src").glob("[0-9][0-9]_*.md"))
    assert [p.stem for p in sources] == [p.stem for p in NOTEBOOKS]
    res = subprocess.run(
        [sys.executable, str(LESSONS / "build_lessons.py"), "--check"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr


def test_the_notebooks_are_committed_without_outputs():
    for path in NOTEBOOKS:
        nb = nbformat.read(path, as_version=4)
        code = [c for c in nb.cells if c.cell_type == "code"]
        assert code and all(not c.outputs and c.execution_count is None for c in code), path


def test_a_source_splits_into_markdown_and_code_cells(tmp_path):
    """``cells_of`` by hand: text becomes Markdown cells, each fenced block one code cell."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("build_lessons", LESSONS / "build_lessons.py")
    build = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(build)
    text = (
        "# Title\n\nSome text.\n\n```python\nx = 1\n```\n\n"
        "More.\n```python\n%%writefile f\ny\n```\n"
    )
    assert build.cells_of(text) == [
        ("markdown", "# Title\n\nSome text."),
        ("code", "x = 1"),
        ("markdown", "More."),
        ("code", "%%writefile f\ny"),
    ]
    nb = build.notebook("01_x", text)
    assert [c.id for c in nb.cells] == ["01_x-0", "01_x-1", "01_x-2", "01_x-3"]
    assert build.rendered(_write(tmp_path / "01_x.md", text)) == build.rendered(
        _write(tmp_path / "01_x.md", text)
    )  # the same bytes each time


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.lessons
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem[:2] for p in NOTEBOOKS])
def test_the_lesson_runs_and_draws(path, tmp_path, monkeypatch):
    """Executed as a reader runs it (in a temporary working folder, with a private
    eigenbasis cache): nbclient raises on the first cell that errors."""
    from tests.support.egl import egl_available

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    pictures = [o for o in outputs if "image/png" in o.get("data", {})]
    assert pictures, f"{path.name} drew no picture"
    drawn = [o.data["text/plain"] for o in pictures if "MeshPicture" in o.data["text/plain"]]
    assert drawn, f"{path.name} has no picture of meshlap_core.show"
    if egl_available():  # the viewer's renderer drew them, not the fallback
        assert all("drawn by egl" in text for text in drawn), drawn
