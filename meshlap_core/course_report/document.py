"""The report as a document: paragraphs, figures, tables and sections, independent of the output
format (:mod:`.render_md` and :mod:`.render_html` turn the same blocks into Markdown and HTML),
and how numbers are written in cells, CSV files and sentences."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class Para:
    """A paragraph (``kind`` ``"note"``: a highlighted remark)."""

    text: str
    kind: str = "p"  # "p" | "note" | "code"


@dataclass
class Fig:
    """One picture: a plot, a viewer screenshot or a matplotlib rendering of a mesh."""

    path: str  # relative to the output directory
    caption: str
    kind: str = "plot"  # "plot" | "screenshot" | "render"


@dataclass
class FigRow:
    """Figures shown side by side."""

    figs: list[Fig]


@dataclass
class Table:
    """A table as shown (``max_rows`` first rows; ``0``: only the link to its CSV file)."""

    name: str
    caption: str
    columns: list[str]
    rows: list[list[Any]]
    csv: str
    max_rows: int | None = None


@dataclass
class Section:
    """One numbered section of the report: its blocks in order, its time and error."""

    key: str
    number: int
    title: str
    blocks: list[Any] = field(default_factory=list)
    seconds: float = 0.0
    error: str | None = None

    def p(self, text: str) -> None:
        self.blocks.append(Para(text))

    def note(self, text: str) -> None:
        self.blocks.append(Para(text, "note"))

    def add(self, block: Any) -> None:
        if block is not None:
            self.blocks.append(block)

    def figs(self, figs: Sequence[Fig | None]) -> None:
        got = [f for f in figs if f is not None]
        if got:
            self.blocks.append(FigRow(got))


@dataclass
class ReportResult:
    """What :func:`build_report` wrote and measured.

    Attributes
    ----------
    out_dir : Path
    markdown, html : Path
        ``report.md`` and ``report.html``.
    figures, tables : list of Path
        Every PNG and CSV written (tables: one CSV per table, shown or not).
    section_seconds : dict
        Wall-clock seconds per section key.
    total_seconds : float
    mesh_note : str
        Where the meshes came from (the sentence at the top of the report).
    screenshots_ok : int
        Viewer screenshots that succeeded.
    screenshot_failures : list of str
        Why screenshots failed (each also noted in the report).
    errors : dict
        Section key → error message for sections that failed (the report notes them too).
    """

    out_dir: Path
    markdown: Path
    html: Path
    figures: list[Path]
    tables: list[Path]
    section_seconds: dict[str, float]
    total_seconds: float
    mesh_note: str
    screenshots_ok: int
    screenshot_failures: list[str]
    errors: dict[str, str]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "out_dir": str(self.out_dir),
            "markdown": str(self.markdown),
            "html": str(self.html),
            "figures": [str(p) for p in self.figures],
            "tables": [str(p) for p in self.tables],
            "section_seconds": self.section_seconds,
            "total_seconds": self.total_seconds,
            "mesh_note": self.mesh_note,
            "screenshots_ok": self.screenshots_ok,
            "screenshot_failures": self.screenshot_failures,
            "errors": self.errors,
        }


# --------------------------------------------------------------------------------------------
# formatting
# --------------------------------------------------------------------------------------------


def fmt_cell(x: Any) -> str:
    """A table cell: 4 significant digits, ``—`` for missing values, yes/no for booleans."""
    if x is None:
        return "—"
    if isinstance(x, bool | np.bool_):
        return "yes" if x else "no"
    if isinstance(x, int | np.integer):
        return f"{int(x):,}" if abs(int(x)) >= 10000 else str(int(x))
    if isinstance(x, float | np.floating):
        f = float(x)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "−inf"
        if f == 0:
            return "0"
        a = abs(f)
        if 1e-3 <= a < 1e5:
            return f"{f:.4g}"
        return f"{f:.3e}"
    return str(x)


def csv_cell(x: Any) -> str:
    """A CSV cell: the shortest text that reads back exactly, empty for missing values."""
    if x is None:
        return ""
    if isinstance(x, bool | np.bool_):
        return "true" if x else "false"
    if isinstance(x, int | np.integer):
        return str(int(x))
    if isinstance(x, float | np.floating):
        return repr(float(x))  # shortest string that reads back exactly
    return str(x)


def num(x: float, digits: int = 3) -> str:
    """A number inside a sentence."""
    f = float(x)
    if not math.isfinite(f):
        return str(f)
    if f == 0:
        return "0"
    if 1e-3 <= abs(f) < 1e5:
        return f"{f:.{digits}g}"
    return f"{f:.{max(digits - 1, 1)}e}"


def pct(x: float) -> str:
    """A percentage inside a sentence, one decimal."""
    return f"{float(x):.1f} %"
