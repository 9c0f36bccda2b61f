"""Markdown rendering of the report's blocks (``report.md``)."""

from __future__ import annotations

from .document import FigRow, Para, Section, Table, fmt_cell


def md_table(t: Table) -> list[str]:
    """A table as Markdown lines: caption with the CSV link, then the first ``max_rows``."""
    rows = t.rows if t.max_rows is None else t.rows[: t.max_rows]
    out = [f"*{t.caption}* ([CSV]({t.csv}), {len(t.rows)} rows)", ""]
    if rows:
        out.append("| " + " | ".join(t.columns) + " |")
        out.append("|" + "|".join("---" for _ in t.columns) + "|")
        for r in rows:
            out.append("| " + " | ".join(fmt_cell(x).replace("|", "\\|") for x in r) + " |")
        if len(rows) < len(t.rows):
            out.append("")
            out.append(f"({len(t.rows) - len(rows)} more rows in the CSV.)")
    return out


def render_md(head: list[str], sections: list[Section], timing: Table) -> str:
    """The whole ``report.md``: the head lines, every section, then the timing table."""
    lines = list(head)
    for s in sections:
        lines += ["", f"## {s.number}. {s.title}", "", f"*Section time: {s.seconds:.1f} s.*", ""]
        if s.error:
            lines += [f"> **This section failed:** {s.error}", ""]
        for b in s.blocks:
            if isinstance(b, Para):
                lines += [f"> **Note:** {b.text}" if b.kind == "note" else b.text, ""]
            elif isinstance(b, FigRow):
                lines += [" ".join(f"![{f.caption}]({f.path})" for f in b.figs), ""]
                lines += ["*" + " | ".join(f.caption for f in b.figs) + "*", ""]
            elif isinstance(b, Table):
                lines += [*md_table(b), ""]
    lines += ["", "## Timings", "", *md_table(timing), ""]
    return "\n".join(lines).rstrip() + "\n"
