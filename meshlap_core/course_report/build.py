"""Building the report: which sections, where the meshes come from, the head of the page, and
the run of every section (one failing section is noted, never fatal)."""

from __future__ import annotations

import html
import os
import platform
import re
import time
from collections.abc import Sequence
from pathlib import Path
from typing import IO

import numpy as np

from .._version import __version__
from ..errors import MeshError
from ..io import atomic_write
from ..progress import Progress, bar
from .context import Context, default_meshes_dir
from .document import FigRow, Para, ReportResult, Section, Table
from .render_html import html_inline, render_html
from .render_md import render_md
from .sections import SECTION_RUNNERS, SECTION_TITLES, SECTIONS
from .shots import Screenshot


def parse_sections(text: str | Sequence[str] | None) -> list[str]:
    """Section keys from ``"1,5"`` / ``"onering,spectral"`` (``None``: all, in order)."""
    if text is None:
        return list(SECTIONS)
    items = [t.strip() for t in (text.split(",") if isinstance(text, str) else text)]
    items = [t for t in items if t]
    if not items:
        raise MeshError("the list of sections is empty", "--sections")
    out = []
    for t in items:
        key = SECTIONS[int(t) - 1] if t.isdigit() and 1 <= int(t) <= len(SECTIONS) else t
        if key not in SECTIONS:
            raise MeshError(
                f"unknown section {t!r}; choose from 1-{len(SECTIONS)} or {', '.join(SECTIONS)}",
                "--sections",
            )
        if key not in out:
            out.append(key)
    return sorted(out, key=SECTIONS.index)


def _mesh_note(ctx: Context) -> str:
    """The sentence at the top: where the meshes came from, and which are stand-ins."""
    subs = {k: m for k, m in ctx.used.items() if m.substitute}
    real = {k: m for k, m in ctx.used.items() if not m.substitute}
    where = str(ctx.meshes_wanted) if ctx.meshes_wanted is not None else "(none)"
    if not ctx.used:
        return "No mesh files were needed by the selected sections."
    if not subs:
        return f"All meshes come from {where}."
    why = (
        f"{where} does not exist"
        if ctx.meshes_dir is None or not ctx.meshes_dir.is_dir()
        else f"{where} has no " + ", ".join(f"{k}.obj" for k in subs)
    )
    head = (
        "**The course meshes were not found, so this report uses the bundled assets instead** "
        if not real
        else "**Some course meshes were not found; bundled assets stand in for them** "
    )
    return (
        head
        + f"({why}). The numbers below are therefore NOT those of the course meshes: "
        + "; ".join(f"{k} → {m.label}" for k, m in subs.items())
        + ". Run with `--meshes DIR` (a folder with the course's .obj files) for the real "
        "study."
    )


def build_report(
    out_dir: str | os.PathLike,
    meshes_dir: str | os.PathLike | None = None,
    *,
    quick: bool = False,
    sections: Sequence[str] | str | None = None,
    screenshots: bool = True,
    progress_stream: IO[str] | None = None,
    screenshot: Screenshot | None = None,
    max_screenshots: int | None = None,
) -> ReportResult:
    """Run the study and write ``report.md``, ``report.html``, ``figures/*.png`` and
    ``tables/*.csv`` into ``out_dir`` (created if needed).

    Long because this docstring documents every parameter; the body is about 45 lines.

    Parameters
    ----------
    out_dir : path
        Output folder.
    meshes_dir : path, optional
        Folder with the course meshes (``cube.obj``, ``lilium_s.obj``, ``plane.obj``,
        ``armadillo.obj``, ``plane_ns.obj``, ``fandisk.obj``, ``fandisk_ns.obj``; in the full
        report also ``armadillo_igl.obj`` if present). Default: :func:`default_meshes_dir`.
        Missing meshes are replaced by the bundled assets, and the report says so at the top.
    quick : bool
        Smaller sweeps, fewer eigenvectors and pictures (under 2 minutes on 2 cores).
    sections : list of str or str, optional
        Subset of :data:`SECTIONS` (names or numbers 1–7); default all.
    screenshots : bool
        Take viewer screenshots with ``screenshot``. When ``False``, without ``screenshot``, or
        when the first screenshot fails, meshes are drawn with matplotlib and the report says
        why.
    progress_stream : text stream, optional
        Where the progress bar goes (the CLI passes stderr); ``None``: silent.
    screenshot : Screenshot, optional
        The function that renders a viewer frame
        (:class:`~meshlap_core.course_report.shots.Screenshot`; the ``meshlap report`` command
        passes the viewer's, from the ``meshlap.screenshots`` entry point).
        The report never imports the viewer itself.
    max_screenshots : int, optional
        Take at most this many viewer screenshots; the later pictures are drawn with
        matplotlib and the report says so. Default: no limit.

    Returns
    -------
    ReportResult

    Raises
    ------
    MeshError
        ``meshes_dir`` given but not a directory, a bad section name, an output directory that
        cannot be created. A failure *inside* a section does not raise: the section is marked
        failed in the report and in :attr:`ReportResult.errors`.
    """
    t_start = time.perf_counter()
    keys = parse_sections(sections)
    if max_screenshots is not None and int(max_screenshots) < 0:
        raise MeshError(f"must be >= 0, got {max_screenshots}", "--max-screenshots")
    explicit = meshes_dir is not None
    mdir = Path(meshes_dir) if meshes_dir is not None else default_meshes_dir()
    if explicit and not mdir.is_dir():
        raise MeshError("is not a directory", os.fspath(mdir))
    out = _output_dir(out_dir)
    progress = Progress(1, _section_line, stream=progress_stream)
    take = screenshot if screenshots else None
    ctx = Context(
        out, mdir if mdir.is_dir() else None, explicit, quick, take, progress, max_screenshots
    )
    if screenshots and screenshot is None:
        ctx.screenshot_reason = (
            "no screenshot function was given (`meshlap report` passes the viewer's)"
        )
    ctx.meshes_wanted = mdir
    built = [_run_section(ctx, key, i, len(keys)) for i, key in enumerate(keys, start=1)]
    total = time.perf_counter() - t_start
    note = _mesh_note(ctx)
    md_path, html_path = _write_pages(ctx, built, keys, total, note)
    return ReportResult(
        out_dir=out,
        markdown=md_path,
        html=html_path,
        figures=list(ctx.figures),
        tables=list(ctx.tables),
        section_seconds={s.key: s.seconds for s in built},
        total_seconds=total,
        mesh_note=note,
        screenshots_ok=ctx.shots_ok,
        screenshot_failures=list(ctx.shot_failures),
        errors={s.key: s.error for s in built if s.error},
    )


def _output_dir(out_dir: str | os.PathLike) -> Path:
    """The output folder, created if needed (:class:`MeshError` naming it if it cannot be)."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise MeshError("exists and is not a directory", os.fspath(out))
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MeshError(
            f"cannot create the output directory: {exc.strerror or exc}", os.fspath(out)
        ) from None
    return out


def _section_line(p: Progress) -> str:
    """``report [######------...] section 2/7 cotan: histograms (1.2 s)``."""
    width = 24
    filled = bar(round(p.fraction * width), width, "#", "-")
    return f"report [{filled}] {p.label}: {p.message} ({p.elapsed:.1f} s)"


def _run_section(ctx: Context, key: str, index: int, n_sections: int) -> Section:
    """Run one section, timed; an exception marks it failed instead of ending the report. A
    note says why pictures are matplotlib renderings if the section has no note of its own."""
    func, steps_q, steps_f = SECTION_RUNNERS[key]
    sec = Section(key, SECTIONS.index(key) + 1, SECTION_TITLES[key])
    ctx.progress.restart(
        max(1, steps_q if ctx.quick else steps_f), f"section {index}/{n_sections} {key}"
    )
    ctx.progress.update(0, "starting")
    t0 = time.perf_counter()
    try:
        with np.errstate(all="ignore"):
            func(ctx, sec)
        status = "done"
    except Exception as exc:  # one broken section must not lose the whole report
        sec.error = f"{type(exc).__name__}: {exc}"
        status = "FAILED"
    sec.seconds = time.perf_counter() - t0
    fallback = any(
        isinstance(b, FigRow)
        and any(f.kind == "render" and f.caption.endswith("no screenshot)") for f in b.figs)
        for b in sec.blocks
    )
    noted = any(isinstance(b, Para) and b.kind == "note" for b in sec.blocks)
    if fallback and not noted:
        sec.note(
            "Pictures whose caption says 'matplotlib rendering' are not viewer "
            f"screenshots: {ctx.screenshot_reason}."
        )
    ctx.progress.update(ctx.progress.total, f"{status} in {sec.seconds:.1f} s")
    ctx.progress.close()
    return sec


def _write_pages(
    ctx: Context, built: list[Section], keys: list[str], total: float, note: str
) -> tuple[Path, Path]:
    """The timing table, then ``report.md`` and ``report.html``; returns their paths."""
    timing = ctx.table(
        "section_timings",
        "Wall-clock seconds per section on this machine.",
        ["section", "title", "seconds", "figures", "tables", "status"],
        [
            [
                f"{s.number}. {s.key}",
                s.title,
                s.seconds,
                sum(len(b.figs) for b in s.blocks if isinstance(b, FigRow)),
                sum(1 for b in s.blocks if isinstance(b, Table)),
                "failed" if s.error else "ok",
            ]
            for s in built
        ]
        + [["total", "", total, len(ctx.figures), len(ctx.tables) + 1, ""]],
    )
    head_md, head_html = _head(ctx, built, keys, total, note)
    md_path, html_path = ctx.out / "report.md", ctx.out / "report.html"
    with atomic_write(md_path, "w", overwrite_inputs=ctx.inputs) as f:
        f.write(render_md(head_md, built, timing))
    with atomic_write(html_path, "w", overwrite_inputs=ctx.inputs) as f:
        f.write(render_html("meshlap report", head_html, built, timing))
    return md_path, html_path


def _machine() -> str:
    """The machine and library versions, for the head of the report."""
    import scipy

    try:
        from importlib.metadata import version

        igl_v = version("libigl")
    except Exception:
        igl_v = "?"
    return (
        f"{platform.system()} {platform.machine()}, {os.cpu_count()} CPUs, Python "
        f"{platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"libigl {igl_v}"
    )


def _head(
    ctx: Context, built: list[Section], keys: list[str], total: float, note: str
) -> tuple[list[str], list[str]]:
    """The head of the report (title, mesh note, how it was made, how to reproduce it, the sign
    convention, failed sections, contents) as Markdown lines and as HTML lines."""
    mode = "quick" if ctx.quick else "full"
    cmd = (
        "meshlap report"
        + (f" --meshes {ctx.meshes_dir}" if ctx.meshes_explicit else "")
        + f" --out {ctx.out}"
        + (" --quick" if ctx.quick else "")
        + ("" if len(keys) == len(SECTIONS) else f" --sections {','.join(keys)}")
    )
    shots = f"{ctx.shots_ok} viewer screenshots" if ctx.shots_ok else "no viewer screenshots"
    if ctx.shot_failures:
        shots += f" (screenshots stopped: {ctx.shot_failures[0]})"
    elif not ctx.screenshots and ctx.screenshot_reason:
        shots += f" ({ctx.screenshot_reason})"
    failed = [s for s in built if s.error]
    lines = [
        "# meshlap report",
        "",
        f"> {note}",
        "",
        f"Generated by meshlap {__version__} on {time.strftime('%Y-%m-%d %H:%M:%S')}, "
        f"{mode} mode, in {total:.1f} s on {_machine()}; {len(ctx.figures)} figures "
        f"({shots}), {len(ctx.tables)} tables (CSV in `tables/`).",
        "",
        f"Reproduce with `{cmd}`.",
        "",
        "Sign convention: every Laplacian is negative semidefinite, Δx = −2Hn (H > 0 on a "
        "sphere with outward normals); eigenvalues shown are the frequencies λ ≥ 0 of −Δ. "
        "`meshlap_core.surfaces` (section 3) uses the same sign (II = −p_uu · n), so its H is "
        "the mesh H for the same normal.",
        "",
    ]
    if failed:
        lines += [
            "> **Failed sections:** "
            + "; ".join(f"{s.number}. {s.key}: {s.error}" for s in failed),
            "",
        ]
    lines += [
        "Contents: "
        + " · ".join(
            f"[{s.number}. {s.title}](#{s.number}-{_slug(s.title)}) ({s.seconds:.1f} s)"
            for s in built
        )
    ]
    h = [
        "<h1>meshlap report</h1>",
        f'<p class="note">{html_inline(note)}</p>',
        f"<p>{html_inline(lines[4])}</p>",
        f"<p>{html_inline(lines[6])}</p>",
        f"<p>{html_inline(lines[8])}</p>",
    ]
    if failed:
        h.append(
            '<p class="err">'
            + html.escape(
                "Failed sections: " + "; ".join(f"{s.number}. {s.key}: {s.error}" for s in failed)
            )
            + "</p>"
        )
    h.append(
        "<p>Contents: "
        + " · ".join(
            f'<a href="#{s.key}">{s.number}. {html.escape(s.title)}</a> ({s.seconds:.1f} s)'
            for s in built
        )
        + "</p>"
    )
    return lines, h


def _slug(title: str) -> str:
    """The anchor Markdown renderers make of a heading (GitHub style)."""
    s = re.sub(r"[^\w\s-]", "", title.lower())
    return re.sub(r"\s+", "-", s.strip())


__all__ = ["build_report", "parse_sections"]
