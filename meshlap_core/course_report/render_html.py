"""HTML rendering of the report's blocks (``report.html``: one self-contained page, inline CSS)."""

from __future__ import annotations

import html
import re

from .document import FigRow, Para, Section, Table, fmt_cell

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1200px;
margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
table{border-collapse:collapse;font-size:12px;margin:.5em 0 1.2em}
th,td{border:1px solid #ccc;padding:2px 6px;text-align:right}
th{background:#f0f0f0}td.s{text-align:left}
.row{display:flex;flex-wrap:wrap;gap:10px;align-items:flex-start}
figure{margin:0;flex:1 1 320px;max-width:100%}
figure img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:12px;color:#444}
.note{background:#fff6d6;border-left:4px solid #e0b000;padding:.4em .8em}
.err{background:#ffe0e0;border-left:4px solid #c00;padding:.4em .8em}
code{background:#f3f3f3;padding:0 3px}
"""


def html_inline(text: str) -> str:
    """Escape ``text`` and turn its ``**bold**`` and ```code``` marks into HTML."""
    t = html.escape(text, quote=True)
    t = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", t)
    t = re.sub(r"`([^`]+)`", r"<code>\1</code>", t)
    return t


def html_table(t: Table) -> list[str]:
    """A table as HTML lines: caption with the CSV link, then the first ``max_rows``."""
    rows = t.rows if t.max_rows is None else t.rows[: t.max_rows]
    out = [
        f'<p><em>{html_inline(t.caption)}</em> (<a href="{html.escape(t.csv)}">CSV</a>, '
        f"{len(t.rows)} rows)</p>"
    ]
    if rows:
        out.append("<table>")
        out.append(
            "<thead><tr>"
            + "".join(f"<th>{html.escape(c)}</th>" for c in t.columns)
            + "</tr></thead>"
        )
        out.append("<tbody>")
        for r in rows:
            cells = "".join(
                f'<td class="s">{html.escape(fmt_cell(x))}</td>'
                if isinstance(x, str)
                else f"<td>{html.escape(fmt_cell(x))}</td>"
                for x in r
            )
            out.append(f"<tr>{cells}</tr>")
        out.append("</tbody></table>")
        if len(rows) < len(t.rows):
            out.append(f"<p>({len(t.rows) - len(rows)} more rows in the CSV.)</p>")
    return out


def render_html(title: str, head_html: list[str], sections: list[Section], timing: Table) -> str:
    """The whole ``report.html``: the head, every section, then the timing table."""
    out = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8" />',
        f"<title>{html.escape(title)}</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        "<body>",
    ]
    out += head_html
    for s in sections:
        out.append(f'<section id="{s.key}">')
        out.append(f"<h2>{s.number}. {html.escape(s.title)}</h2>")
        out.append(f"<p><em>Section time: {s.seconds:.1f} s.</em></p>")
        if s.error:
            out.append(
                f'<p class="err"><strong>This section failed:</strong> {html.escape(s.error)}</p>'
            )
        for b in s.blocks:
            if isinstance(b, Para):
                cls = ' class="note"' if b.kind == "note" else ""
                prefix = "<strong>Note:</strong> " if b.kind == "note" else ""
                out.append(f"<p{cls}>{prefix}{html_inline(b.text)}</p>")
            elif isinstance(b, FigRow):
                out.append('<div class="row">')
                for f in b.figs:
                    out.append(
                        f'<figure><a href="{html.escape(f.path)}"><img src="{html.escape(f.path)}"'
                        f' alt="{html.escape(f.caption)}" /></a>'
                        f"<figcaption>{html_inline(f.caption)}</figcaption></figure>"
                    )
                out.append("</div>")
            elif isinstance(b, Table):
                out += html_table(b)
        out.append("</section>")
    out.append('<section id="timings">')
    out.append("<h2>Timings</h2>")
    out += html_table(timing)
    out.append("</section>")
    out += ["</body>", "</html>"]
    return "\n".join(out) + "\n"
