"""The examples the documentation shows run: the package docstring (a doctest), the
*Examples* section of every public name's docstring (the API reference shows them; a public
name without one fails here) and the "From Python" page's block (``docs/python.md``, executed
in a temporary folder holding the bundled mesh)."""

from __future__ import annotations

import doctest
import inspect
import math
import re
import shutil
from pathlib import Path

import pytest

import meshlap_core
from meshlap_core import options

ROOT = Path(__file__).resolve().parents[2]
# every exported name: meshlap_core._PUBLIC (the lazy map) plus MeshError, MeshWarning
PUBLIC = sorted(n for n in meshlap_core.__all__ if not n.startswith("__"))
EXAMPLES = re.compile(r"^[ ]*Examples\n[ ]*-{8,}\n", re.M)


def test_package_docstring_example_runs():
    result = doctest.testmod(meshlap_core, raise_on_error=False, report=True)
    assert result.attempted >= 5 and result.failed == 0


def test_options_doctests_run():
    result = doctest.testmod(options, raise_on_error=False, report=True)
    assert result.attempted >= 2 and result.failed == 0


PYTHON_PAGE = ROOT / "docs" / "python.md"


def _python_page_block() -> str:
    text = PYTHON_PAGE.read_text(encoding="utf-8")
    section = text.split("# From Python", 1)[1]
    match = re.search(r"```python\n(.*?)```", section, re.S)
    assert match, "docs/python.md ('From Python') has no python block"
    return match.group(1)


def test_python_page_example_runs(tmp_path, monkeypatch, capsys):
    (tmp_path / "assets").mkdir()
    shutil.copy(ROOT / "assets" / "bumpy.obj", tmp_path / "assets" / "bumpy.obj")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))  # the basis cache
    code = _python_page_block()
    exec(compile(code, "docs/python.md", "exec"), {"__name__": "python_page"})
    printed = capsys.readouterr().out.strip()
    assert math.isfinite(float(printed))  # the inspector's H at vertex 100 of the bumpy sphere


def test_python_page_lists_exactly_the_public_names():
    text = PYTHON_PAGE.read_text(encoding="utf-8")
    para = text.split("The names: ", 1)[1].split(". `examples/`", 1)[0]
    listed = set(re.findall(r"`(\w+)`", para))
    public = set(meshlap_core.__all__) - {"__version__"}
    assert listed == public, (sorted(listed - public), sorted(public - listed))


def public_doctest(name: str) -> doctest.DocTest:
    """The doctest of a public name's own docstring (not one inherited from a base class),
    with no globals: each example imports what it uses, as a reader copying it would."""
    obj = getattr(meshlap_core, name)
    doc = obj.__doc__ or ""
    assert EXAMPLES.search(doc), f"{name}: its docstring has no 'Examples' section"
    source = inspect.getsourcefile(obj)
    lineno = inspect.getsourcelines(obj)[1]
    return doctest.DocTestParser().get_doctest(doc, {}, f"meshlap_core.{name}", source, lineno)


def test_public_names_cover_the_export_map():
    assert set(meshlap_core._PUBLIC) <= set(PUBLIC)
    assert {"MeshError", "MeshWarning"} <= set(PUBLIC)


@pytest.mark.parametrize("name", PUBLIC)
def test_public_name_has_examples_that_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an example that writes a file writes it here
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    test = public_doctest(name)
    assert test.examples, f"{name}: its Examples section has no >>> example"
    assert any(ex.want.strip() for ex in test.examples), f"{name}: no example shows an output"
    skipped = [ex.source for ex in test.examples if ex.options.get(doctest.SKIP)]
    assert not skipped, f"{name}: skipped examples {skipped}"
    report: list[str] = []
    runner = doctest.DocTestRunner(verbose=False)
    result = runner.run(test, out=report.append)
    assert result.failed == 0 and result.attempted == len(test.examples), "".join(report)
