"""Write the lessons' notebooks from their text sources.

Each lesson is written as Markdown in ``docs/lessons/src/NN_subject.md``: a fenced
```` ```python ```` block is a code cell, the text between blocks a Markdown cell. This script
turns every source into ``docs/lessons/NN_subject.ipynb`` (nbformat 4, no outputs, cell ids
numbered, the same bytes for the same source), so a lesson is edited and reviewed as text
and the notebook is regenerated:

    python docs/lessons/build_lessons.py          # write the notebooks
    python docs/lessons/build_lessons.py --check  # exit 1 if a notebook is not its source's

The notebooks are committed without outputs (executed outputs with their pictures would
grow the repository by megabytes at each change); ``tests/project/test_lessons.py`` executes them,
and a documentation build executes them to render the pages with their pictures.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import nbformat

HERE = Path(__file__).resolve().parent
SOURCES = HERE / "src"
FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$\n?", re.MULTILINE | re.DOTALL)

KERNEL = {"display_name": "Python 3", "language": "python", "name": "python3"}


def cells_of(text: str) -> list[tuple[str, str]]:
    """``(kind, source)`` of each cell of a lesson's Markdown: ``"code"`` for each fenced
    Python block, ``"markdown"`` for the non-empty text between them."""
    cells: list[tuple[str, str]] = []
    at = 0
    for m in FENCE.finditer(text):
        prose = text[at : m.start()].strip()
        if prose:
            cells.append(("markdown", prose))
        cells.append(("code", m.group(1).rstrip("\n")))
        at = m.end()
    prose = text[at:].strip()
    if prose:
        cells.append(("markdown", prose))
    return cells


def notebook(stem: str, text: str) -> nbformat.NotebookNode:
    """The notebook of one lesson (no outputs; cell ids ``<stem>-<k>``)."""
    nb = nbformat.v4.new_notebook()
    nb.metadata = {"kernelspec": KERNEL, "language_info": {"name": "python"}}
    for k, (kind, source) in enumerate(cells_of(text)):
        make = nbformat.v4.new_code_cell if kind == "code" else nbformat.v4.new_markdown_cell
        cell = make(source)
        cell.id = f"{stem[:50]}-{k}"
        nb.cells.append(cell)
    nbformat.validate(nb)
    return nb


def rendered(source: Path) -> str:
    """The notebook text written for ``source``."""
    return nbformat.writes(notebook(source.stem, source.read_text(encoding="utf-8"))) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="only check the notebooks")
    args = parser.parse_args(argv)
    stale = []
    for source in sorted(SOURCES.glob("[0-9][0-9]_*.md")):
        target = HERE / f"{source.stem}.ipynb"
        text = rendered(source)
        current = target.read_text(encoding="utf-8") if target.is_file() else None
        if current == text:
            continue
        if args.check:
            stale.append(target.name)
        else:
            target.write_text(text, encoding="utf-8")
            print(f"wrote {target.relative_to(HERE.parent.parent)}")
    if stale:
        print(f"not built from their sources: {', '.join(stale)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
