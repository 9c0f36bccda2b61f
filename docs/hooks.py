"""MkDocs hooks of meshlap's documentation site (``mkdocs.yml``: ``hooks``).

What the site takes from the repository at build time, so that nothing is copied by hand:

- the home page is ``README.md``, its links into ``docs/`` made site links;
- the API reference is one page per group of ``meshlap_core._PUBLIC`` (the groups are the
  comments of that map), one mkdocstrings entry per public name, pointed at the module that
  defines it (the lazy top-level names are not visible to a static reader);
- the nav's ``lessons/*.ipynb`` and ``reference/*.md`` entries become the lessons found in
  ``docs/lessons/`` (titled by their first heading) and the reference pages;
- a page's ``../README.md`` link (the pages' "back to README", written for a repository
  browser) leads to the home page, and a table's escaped pipe in code (``a\\|b``, which GitHub
  needs) is a plain one (Python-Markdown splits no cell inside code);
- the Sphinx roles of the docstrings (:func:`name`, :class:`~a.b.Name`, ...) become a link to the
  name's reference entry when it is public, inline code otherwise (``SphinxRoles``, a griffe
  extension named in mkdocs.yml).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import griffe
from mkdocs.structure.files import File, Files

LESSONS = "lessons/*.ipynb"
REFERENCE = "reference/*.md"
REFERENCE_DIR = "reference"
OTHER_GROUP = "errors and warnings"  # exported names outside _PUBLIC (MeshError, MeshWarning)
ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj):`(~?)([\w.]+?)(\(\))?`")


@dataclass(frozen=True)
class Entry:
    """One public name: how it is imported, where it is defined, its docstring's first line."""

    name: str
    path: str  # the defining module's dotted path + the object's qualified name
    summary: str


@dataclass(frozen=True)
class Group:
    """One reference page: the public names under one comment of ``_PUBLIC``."""

    title: str
    slug: str
    entries: tuple[Entry, ...]

    @property
    def src_uri(self) -> str:
        return f"{REFERENCE_DIR}/{self.slug}.md"


def _slug(text: str) -> str:
    head = re.split(r"[:(]", text, maxsplit=1)[0]
    return re.sub(r"[^a-z0-9]+", "-", head.lower()).strip("-")


def _comment_groups(source: str) -> dict[str, str]:
    """Public name → the full-line comment above it in the ``_PUBLIC`` literal."""
    literal = next(
        (
            n.value
            for n in ast.parse(source).body
            if isinstance(n, ast.AnnAssign)
            and isinstance(n.target, ast.Name)
            and n.target.id == "_PUBLIC"
            and isinstance(n.value, ast.Dict)
        ),
        None,
    )
    if literal is None:
        raise ValueError("meshlap_core/__init__.py: no `_PUBLIC: dict[...] = {...}` literal")
    lines = source.splitlines()
    out: dict[str, str] = {}
    for key in literal.keys:
        if not (isinstance(key, ast.Constant) and isinstance(key.value, str)):
            raise ValueError(
                f"meshlap_core._PUBLIC: a key that is not a string, line {literal.lineno}"
            )
        above = lines[literal.lineno - 1 : key.lineno - 1]
        comments = [ln.strip()[1:].strip() for ln in above if ln.strip().startswith("#")]
        out[key.value] = comments[-1] if comments else "other names"
    return out


def _entry(name: str) -> Entry:
    import meshlap_core

    obj = getattr(meshlap_core, name)
    doc = inspect.getdoc(obj) or ""
    return Entry(name, f"{obj.__module__}.{obj.__qualname__}", doc.split("\n\n")[0].strip())


def public_groups() -> list[Group]:
    """The reference pages: every name of ``meshlap_core.__all__`` (but ``__version__``), grouped
    as ``_PUBLIC``'s comments group them, in its order."""
    import meshlap_core

    by_name = _comment_groups(Path(meshlap_core.__file__).read_text(encoding="utf-8"))
    titles: dict[str, list[str]] = {}
    for name in meshlap_core._PUBLIC:
        titles.setdefault(by_name[name], []).append(name)
    rest = [n for n in meshlap_core.__all__ if n not in meshlap_core._PUBLIC and n[:2] != "__"]
    if rest:
        titles.setdefault(OTHER_GROUP, []).extend(rest)
    groups = [
        Group(title[0].upper() + title[1:], _slug(title), tuple(_entry(n) for n in names))
        for title, names in titles.items()
    ]
    slugs = [g.slug for g in groups]
    if len(set(slugs)) != len(slugs) or "index" in slugs:
        raise ValueError(f"reference pages: two groups of _PUBLIC share a page name: {slugs}")
    return groups


def _reference_page(group: Group) -> str:
    parts = [f"# {group.title}\n", "Each name is imported as `from meshlap_core import NAME`.\n"]
    for e in group.entries:
        if e.path.rsplit(".", 1)[1] != e.name:
            parts.append(f"`{e.name}` is `{e.path}` under its public name.\n")
        parts.append(
            f"::: {e.path}\n    options:\n      heading: {e.name}\n      toc_label: {e.name}\n"
        )
    return "\n".join(parts)


def _reference_index(groups: list[Group]) -> str:
    rows = [
        "# API reference\n",
        "Every public name of `meshlap_core` (`from meshlap_core import NAME`), generated from the",
        "package's export map `meshlap_core._PUBLIC` and the docstrings when the site is built.",
        "Each docstring's *Examples* run as tests (`tests/project/test_doc_examples.py`).\n",
    ]
    paths = {e.name: e.path for g in groups for e in g.entries}
    for g in groups:
        rows += [f"## {g.title}\n", "| name | what it is |", "|---|---|"]
        for e in g.entries:
            summary = roles_to_markdown(" ".join(e.summary.split()), paths).replace("|", "\\|")
            rows.append(f"| [`{e.name}`]({g.slug}.md#{e.path}) | {summary} |")
        rows.append("")
    return "\n".join(rows)


def _first_heading(notebook: Path) -> str:
    cells = json.loads(notebook.read_text(encoding="utf-8")).get("cells", [])
    for cell in cells:
        if cell.get("cell_type") == "markdown":
            source = "".join(cell.get("source", []))
            match = re.search(r"^#\s+(.+)$", source, re.M)
            if match:
                return match.group(1).strip()
    return notebook.stem.replace("_", " ")


def _expand(nav: Any, docs_dir: Path) -> Any:
    """The nav with its ``lessons/*.ipynb`` and ``reference/*.md`` entries expanded; a section
    left empty (no lesson yet) is dropped."""
    if isinstance(nav, list):
        out = []
        for item in nav:
            expanded = _expand(item, docs_dir)
            if expanded is not None:
                out.append(expanded)
        return out
    if isinstance(nav, dict):
        (title, value), *_ = nav.items()
        if value == LESSONS:
            lessons = sorted((docs_dir / "lessons").glob("*.ipynb"))
            items = [{_first_heading(p): f"lessons/{p.name}"} for p in lessons]
            return {title: items} if items else None
        if value == REFERENCE:
            pages = [{g.title: g.src_uri} for g in public_groups()]
            return {title: [f"{REFERENCE_DIR}/index.md", *pages]}
        return {title: _expand(value, docs_dir)}
    return nav


def on_config(config: Any) -> Any:
    config["nav"] = _expand(config["nav"], Path(config["docs_dir"]))
    return config


def on_files(files: Files, config: Any) -> Files:
    groups = public_groups()
    files.append(
        File.generated(config, f"{REFERENCE_DIR}/index.md", content=_reference_index(groups))
    )
    for g in groups:
        files.append(File.generated(config, g.src_uri, content=_reference_page(g)))
    readme = Path(config["config_file_path"]).parent / "README.md"
    home = re.sub(r"\]\(docs/", "](", readme.read_text(encoding="utf-8"))
    files.append(File.generated(config, "index.md", content=home))
    return files


def _table_pipes(markdown: str) -> str:
    def row(line: str) -> str:
        if not line.lstrip().startswith("|"):
            return line
        return re.sub(r"`[^`]*`", lambda m: m.group(0).replace("\\|", "|"), line)

    return "\n".join(row(line) for line in markdown.split("\n"))


def on_page_markdown(markdown: str, page: Any, **_: Any) -> str:
    depth = page.file.src_uri.count("/")
    home = "../" * depth + "index.md"
    return _table_pipes(re.sub(r"\]\((?:\.\./)+README\.md", f"]({home}", markdown))


def _resolve(dotted: str) -> Any:
    """The object a full dotted path names (a module, then attributes), or None."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr, None)
        return obj
    return None


def _role_target(target: str, paths: dict[str, str]) -> str | None:
    """The reference identifier of a role's target (``name``, ``Class.member`` of a public
    class, or a full path to a public object), or None when it has no entry."""
    import meshlap_core

    parts = target.removeprefix("meshlap_core.").split(".")
    if parts[0] in paths:
        obj = getattr(meshlap_core, parts[0])
        for member in parts[1:]:
            if member.startswith("_") or not hasattr(obj, member):
                return None
            obj = getattr(obj, member)
        return ".".join([paths[parts[0]], *parts[1:]])
    if target.startswith("meshlap_core."):
        obj = _resolve(target)
        name = getattr(obj, "__name__", None)
        if name in paths and getattr(meshlap_core, name) is obj:
            return paths[name]
    return None


def roles_to_markdown(text: str, paths: dict[str, str]) -> str:
    """Replace each Sphinx role of a docstring by a Markdown link to the public name's entry
    (``paths``: public name → identifier) or by inline code."""

    def one(match: re.Match[str]) -> str:
        tilde, target, call = match.groups()
        shown = (target.rsplit(".", 1)[-1] if tilde else target) + (call or "")
        identifier = _role_target(target, paths)
        return f"[`{shown}`][{identifier}]" if identifier else f"`{shown}`"

    return ROLE.sub(one, text)


class SphinxRoles(griffe.Extension):
    """Griffe extension: the docstrings' Sphinx roles as Markdown (see ``roles_to_markdown``)."""

    def __init__(self) -> None:
        super().__init__()
        self.paths = {e.name: e.path for g in public_groups() for e in g.entries}

    def on_instance(self, *, obj: griffe.Object, **_: Any) -> None:
        if obj.docstring is not None and ":" in obj.docstring.value:
            obj.docstring.value = roles_to_markdown(obj.docstring.value, self.paths)
