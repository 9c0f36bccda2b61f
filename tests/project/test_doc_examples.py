"""The examples the documentation shows run: the package docstring (a doctest) and README's
"From Python" block (executed in a temporary folder holding the bundled mesh)."""

from __future__ import annotations

import doctest
import math
import re
import shutil
from pathlib import Path

import meshlap_core
from meshlap_core import options

ROOT = Path(__file__).resolve().parents[2]


def test_package_docstring_example_runs():
    result = doctest.testmod(meshlap_core, raise_on_error=False, report=True)
    assert result.attempted >= 5 and result.failed == 0


def test_options_doctests_run():
    result = doctest.testmod(options, raise_on_error=False, report=True)
    assert result.attempted >= 2 and result.failed == 0


def _readme_python_block() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## From Python", 1)[1]
    match = re.search(r"```python\n(.*?)```", section, re.S)
    assert match, "README's 'From Python' section has no python block"
    return match.group(1)


def test_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    (tmp_path / "assets").mkdir()
    shutil.copy(ROOT / "assets" / "bumpy.obj", tmp_path / "assets" / "bumpy.obj")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))  # the basis cache
    code = _readme_python_block()
    exec(compile(code, "README.md", "exec"), {"__name__": "readme"})
    printed = capsys.readouterr().out.strip()
    assert math.isfinite(float(printed))  # the inspector's H at vertex 100 of the bumpy sphere


def test_readme_lists_exactly_the_public_names():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    para = text.split("The names: ", 1)[1].split(". `examples/`", 1)[0]
    listed = set(re.findall(r"`(\w+)`", para))
    public = set(meshlap_core.__all__) - {"__version__"}
    assert listed == public, (sorted(listed - public), sorted(public - listed))
