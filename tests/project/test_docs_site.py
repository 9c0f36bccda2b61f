"""The documentation site (``mkdocs.yml``, ``docs/hooks.py``) builds with warnings as errors:
every page, every internal link and anchor (MkDocs' strict validation, and here every ``href``
and ``src`` of the built HTML), an API reference entry for every public name of
``meshlap_core`` with its Examples, every lesson of ``docs/lessons/`` in the nav and rendered,
and a sample lesson executed at build time with its picture. External links are listed, never
fetched.

One build, of a copy of the site's sources with the sample lesson added to ``docs/lessons/``:
the sample is executed, the repository's lessons are rendered without being executed (their
own runner executes them; ``MESHLAP_DOCS_EXECUTE=true`` executes them here as well).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

import meshlap_core

pytest.importorskip("mkdocs", reason="mkdocs is not installed (it comes with the [test] extra)")

ROOT = Path(__file__).resolve().parents[2]
PUBLIC = sorted(n for n in meshlap_core.__all__ if not n.startswith("__"))


def sample_lesson(cells: list[tuple[str, str]]) -> str:
    """A notebook (nbformat 4) of ("markdown" | "code", source) cells."""
    out = []
    for kind, source in cells:
        cell = {"cell_type": kind, "metadata": {}, "source": source}
        if kind == "code":
            cell |= {"execution_count": None, "outputs": []}
        out.append(cell)
    kernel = {"name": "python3", "display_name": "Python 3", "language": "python"}
    notebook = {"cells": out, "metadata": {"kernelspec": kernel}, "nbformat": 4}
    return json.dumps(notebook | {"nbformat_minor": 5})


SAMPLE = [
    ("markdown", "# Sample lesson: the sphere's mean curvature\n\nOn the unit sphere H = 1."),
    (
        "code",
        "import matplotlib.pyplot as plt\n"
        "from meshlap_core import curvature_field, icosphere\n"
        "V, F = icosphere(2)\n"
        "H = curvature_field(V, F, 'cotan', area='voronoi')\n"
        "print('mean H', round(float(H.mean()), 3))",
    ),
    ("code", "fig, ax = plt.subplots(figsize=(3, 2))\nax.hist(H, bins=20)\nplt.show()"),
]


def build(project: Path, site: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1", MESHLAP_DOCS_EXECUTE="true")
    cmd = [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", "mkdocs.yml", "-d", site]
    return subprocess.run(cmd, cwd=project, env=env, capture_output=True, text=True, timeout=900)


def copy_project(tmp_path: Path, lesson: str, execute_lessons: bool) -> Path:
    """The site's sources (mkdocs.yml, README.md, docs/) with ``lesson`` (notebook JSON) as
    docs/lessons/sample.ipynb; the repository's lessons are not executed unless
    ``execute_lessons``."""
    project = tmp_path / "project"
    shutil.copytree(ROOT / "docs", project / "docs", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "README.md", project / "README.md")
    (project / "docs" / "lessons").mkdir(exist_ok=True)
    (project / "docs" / "lessons" / "sample.ipynb").write_text(lesson, encoding="utf-8")
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    ignore = [f"lessons/{p.name}" for p in (ROOT / "docs" / "lessons").glob("*.ipynb")]
    if ignore and not execute_lessons:
        option = "      include_source: true\n"
        assert option in config, "mkdocs.yml's mkdocs-jupyter options changed: update this test"
        config = config.replace(option, f"{option}      execute_ignore: {json.dumps(ignore)}\n")
    (project / "mkdocs.yml").write_text(config, encoding="utf-8")
    return project


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("docs")
    execute = os.environ.get("MESHLAP_DOCS_EXECUTE", "").lower() == "true"
    project = copy_project(tmp, sample_lesson(SAMPLE), execute_lessons=execute)
    res = build(project, tmp / "site")
    assert res.returncode == 0, res.stdout + res.stderr
    return tmp / "site"


class Links(HTMLParser):
    """The ids, the ``href`` / ``src`` targets and the ``<title>`` of one HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.targets: list[str] = []
        self.title = ""
        self._in_title = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for key, value in attrs:
            if key in ("id", "name") and value:
                self.ids.add(value)
            if key in ("href", "src") and value is not None:
                self.targets.append(value)
        self._in_title = tag == "title"

    def handle_data(self, data: str) -> None:
        if self._in_title:
            self.title += data

    def handle_endtag(self, tag: str) -> None:
        self._in_title = False


def parse(page: Path) -> Links:
    links = Links()
    links.feed(page.read_text(encoding="utf-8"))
    return links


def page_of(site: Path, page: Path, path: str) -> Path:
    target = (page.parent / unquote(path)).resolve() if path else page
    return target / "index.html" if target.is_dir() else target


def check_links(site: Path) -> tuple[list[str], set[str]]:
    """(broken internal links, external links) of every page of the built site."""
    pages = {p: parse(p) for p in site.rglob("*.html") if p.name != "404.html"}
    broken: list[str] = []
    external: set[str] = set()
    for page, links in pages.items():
        for url in links.targets:
            parts = urlsplit(url)
            if parts.scheme in ("data", "javascript"):
                continue
            if parts.scheme or parts.netloc:
                external.add(url)
                continue
            target = page_of(site, page, parts.path)
            where = f"{page.relative_to(site)}: {url}"
            if not target.exists():
                broken.append(f"{where} (no {target.relative_to(site)})")
            elif parts.fragment and target.suffix == ".html":
                ids = pages[target].ids if target in pages else parse(target).ids
                if unquote(parts.fragment) not in ids:
                    broken.append(f"{where} (no anchor)")
    return broken, external


def test_site_builds_with_warnings_as_errors(site):
    pages = ["install", "window", "diffusion", "commands", "exercises-and-grading", "python"]
    pages += ["conventions", "curvature-estimators", "findings", "bad-input", "benchmarks"]
    pages += ["exercises", "architecture", "reference"]
    for name in pages:
        assert (site / name / "index.html").is_file(), name
    home = (site / "index.html").read_text(encoding="utf-8")
    assert "meshlap view" in home and "img/window/1280x720_window.png" in home  # README


def test_every_internal_link_and_anchor_resolves(site):
    broken, external = check_links(site)
    assert not broken, broken
    for url in external:  # listed, not fetched: the build and the tests use no network
        parts = urlsplit(url)
        assert parts.scheme in ("http", "https", "mailto") and (parts.netloc or parts.path), url


def test_every_public_name_has_a_reference_entry_with_examples(site):
    pages = {p: p.read_text(encoding="utf-8") for p in (site / "reference").rglob("index.html")}
    missing = []
    for name in PUBLIC:
        obj = getattr(meshlap_core, name)
        anchor = f'id="{obj.__module__}.{obj.__qualname__}"'
        html = next((text for text in pages.values() if anchor in text), None)
        if html is None:
            missing.append(f"{name}: no entry")
            continue
        entry = html.split(anchor, 1)[1].split("<h2 ", 1)[0]  # members are <h3>
        if name not in entry.split("</h2>", 1)[0].split():
            missing.append(f"{name}: the entry is not headed by its public name")
        if "Examples:" not in entry or "&gt;&gt;&gt;" not in entry:
            missing.append(f"{name}: no Examples in the entry")
    assert not missing, missing


def test_every_lesson_is_in_the_nav_and_rendered(site):
    home = (site / "index.html").read_text(encoding="utf-8")
    for notebook in sorted((ROOT / "docs" / "lessons").glob("*.ipynb")):
        page = site / "lessons" / notebook.stem / "index.html"
        assert page.is_file(), notebook.name
        assert f"lessons/{notebook.stem}/" in home, f"{notebook.name} is not in the nav"


def test_a_lesson_is_executed_at_build_time_with_its_picture(site):
    page = site / "lessons" / "sample" / "index.html"
    html = page.read_text(encoding="utf-8")
    assert "mean H 1.0" in html  # the cell's output, computed at build time
    assert "data:image/png;base64," in html  # its figure
    assert (page.parent / "sample.ipynb").is_file()  # the notebook, to download
    home = parse(site / "index.html")
    assert "lessons/sample/" in home.targets  # in the nav, titled by its first heading
    assert "Sample lesson: the sphere" in (site / "index.html").read_text(encoding="utf-8")


def test_a_lessons_formulas_load_mathjax(site):
    """The notebook plugin's default loads no MathJax (an empty ``<script src="">``): the
    lessons' ``$...$`` stayed raw text. The page loads MathJax and configures ``$`` inline."""
    html = (site / "lessons" / "sample" / "index.html").read_text(encoding="utf-8")
    sources = re.findall(r'<script[^>]*src="([^"]*)"', html)
    assert '<script src="">' not in html.replace(" ", "")
    assert any("mathjax" in src.lower() for src in sources), sources
    assert "inlineMath" in html


def test_the_notebook_plugin_stops_on_a_failing_cell_and_reads_only_lessons():
    """mkdocs-jupyter stops the build on a cell's error only with ``allow_errors: false``."""
    from mkdocs.config import load_config

    config = load_config(str(ROOT / "mkdocs.yml"))
    options = config.plugins["mkdocs-jupyter"].config
    assert options["allow_errors"] is False and options["execute"] in (True, False)
    assert options["include"] == ["lessons/*.ipynb"]  # never docs/*.py (scripts, these hooks)
