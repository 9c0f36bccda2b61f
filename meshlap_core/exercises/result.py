"""The result of a check: per task passed or why not, as text, JSON, JUnit XML, and for
notebooks an HTML table (``_repr_html_``) and a small picture (``_repr_png_``): the task cells
(matplotlib) beside the difference map on the failing mesh, drawn by the viewer's EGL snapshot
renderer (the ``meshlap.check_picture`` entry point; the core never imports the viewer), or by
matplotlib with the reason written under it when EGL is unavailable."""

from __future__ import annotations

import html
import io
import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .speed import Speed

STATUS_WORDS = {
    "passed": "passed",
    "failed": "FAILED",
    "error": "ERROR (your code raised)",
    "timeout": "TIMEOUT",
    "memory": "OUT OF MEMORY",
    "crashed": "CRASHED",
    "missing": "missing",
    "not_implemented": "not implemented",
    "import_error": "ERROR (the file does not import)",
    "refused": "REFUSED (the sandbox stopped it)",
}
LOG_LINES = 20
"""Lines of what the student's file printed that the text report shows."""


@dataclass
class TaskResult:
    """One task's verdict.

    Attributes
    ----------
    task, status : str
        ``status`` is a key of :data:`STATUS_WORDS`.
    case, label : str
        The first failing mesh and call (``boundary=pi``, ``k=6``...).
    vertex : int or None
        The vertex with the largest error there.
    expected, got : Any
        That vertex's reference and student values.
    error, tol : float
    diagnosis : str or None
        A key of :data:`~.diagnose.DIAGNOSES`; ``diagnosis_text`` its sentence.
    message, traceback : str
    n_failed, n_calls : int
    difference : (n,) float or None
        Student − reference per vertex of ``case`` (the difference map).
    note : str
        Calls a mesh could not judge, and why (:attr:`.tasks.Task.not_judged`).
    picture : (V, F, difference, mesh name, signed) or None
        The largest failing mesh and its difference map (the notebook picture); ``signed``:
        a scalar per vertex (coolwarm around 0), else a magnitude (viridis from 0).
    speed : Speed or None
        The speed line (a right task timed on its speed mesh); ``speed_required``: a slow one
        fails (``--require-speed``).
    repro : (case, label, args) or None
        The first failing call: the mesh and arguments a student can export.
    """

    task: str
    status: str
    case: str = ""
    label: str = ""
    vertex: int | None = None
    expected: Any = None
    got: Any = None
    error: float = 0.0
    tol: float = 0.0
    diagnosis: str | None = None
    diagnosis_text: str = ""
    message: str = ""
    traceback: str = ""
    n_failed: int = 0
    n_calls: int = 0
    difference: np.ndarray | None = field(default=None, repr=False)
    picture: tuple | None = field(default=None, repr=False)
    note: str = ""
    speed: Speed | None = None
    speed_required: bool = False
    repro: tuple | None = field(default=None, repr=False)

    @property
    def passed(self) -> bool:
        return self.status == "passed"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (no difference array)."""
        hidden = ("difference", "picture", "repro", "speed")
        out = {k: v for k, v in vars(self).items() if k not in hidden}
        out["speed"] = self.speed.to_dict() if self.speed is not None else None
        out["passed"] = self.passed
        return out

    def lines(self) -> list[str]:
        """The text report of this task (first line: name and verdict)."""
        head = f"{self.task:<24} {STATUS_WORDS.get(self.status, self.status)}"
        speed = [f"  {self.speed.line(self.speed_required)}"] if self.speed is not None else []
        if self.passed:
            return [f"{head} ({self.n_calls} calls)", *speed, *self._note()]
        out = [head]
        if self.case:
            where = f"  on mesh {self.case}" + (f" ({self.label})" if self.label else "")
            if self.n_failed > 1:
                where += f", and {self.n_failed - 1} more failing call(s)"
            out.append(where)
        if self.expected is not None or self.got is not None:
            out.append(f"  at vertex {self.vertex}:" if self.vertex is not None else "  values:")
            out.append(f"    expected {_short(self.expected)}")
            out.append(f"    got      {_short(self.got)}")
            if self.tol:
                out.append(f"    largest error {self.error:.3g} (tolerance {self.tol:.3g})")
        if self.diagnosis_text:
            out.append(f"  likely mistake: {self.diagnosis_text}")
        if self.message and self.message != self.traceback:
            out.append(f"  {self.message}")
        if self.traceback:
            out.extend("  " + line for line in self.traceback.splitlines())
        return out + speed + self._note()

    def _note(self) -> list[str]:
        return [f"  note: {self.note}"] if self.note else []


def _short(value: Any, limit: int = 160) -> str:
    if isinstance(value, list) and value and isinstance(value[0], tuple):
        text = ", ".join(f"[{j}] {v:.6g}" for j, v in value)
    elif isinstance(value, float):
        text = f"{value:.9g}"
    elif isinstance(value, list) and value and isinstance(value[0], float):
        text = "[" + ", ".join(f"{v:.6g}" for v in value) + "]"
    else:
        text = str(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


@dataclass
class CheckResult:
    """All tasks of one student file, and how the file was run.

    Attributes
    ----------
    file : str
        The file as the report names it (control characters escaped).
    tasks : list of TaskResult
    isolation : dict
        :meth:`.isolation.Isolation.to_dict` of the sandbox it ran in.
    log : str
        What the file printed (capped; control characters escaped), ``log_bytes`` in all.
    notes : list of str
        What the copy of the submission left out, and why.
    seconds : float
        Wall time of the whole check.
    survivors : int
        Processes the file left running that the end of the check killed.
    submission : str
        The student (a folder's submission name; ``""`` for a single file).
    """

    file: str
    tasks: list[TaskResult]
    isolation: dict[str, Any] = field(default_factory=dict)
    log: str = ""
    log_bytes: int = 0
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0
    survivors: int = 0
    submission: str = ""

    @property
    def passed(self) -> bool:
        return all(t.passed for t in self.tasks)

    @property
    def n_passed(self) -> int:
        return sum(t.passed for t in self.tasks)

    def __getitem__(self, name: str) -> TaskResult:
        for t in self.tasks:
            if t.task == name:
                return t
        raise KeyError(name)

    def format_text(self) -> str:
        lines = [f"{self.file}: {self.n_passed}/{len(self.tasks)} tasks passed"]
        if self.isolation:
            lines.append(f"  sandbox: {self.isolation.get('description', '')}")
        lines.extend(f"  note: {n}" for n in self.notes)
        for t in self.tasks:
            lines.extend(t.lines())
        if self.survivors:
            lines.append(f"  the file left {self.survivors} process(es) running: killed")
        if self.log_bytes:
            shown = self.log.splitlines()
            lines.append(f"  your file printed ({self.log_bytes} bytes; the first lines):")
            lines.extend("  | " + x for x in shown[:LOG_LINES])
            if len(shown) > LOG_LINES:
                lines.append(f"  | … ({len(shown) - LOG_LINES} more lines)")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        return {
            "file": self.file,
            "submission": self.submission,
            "passed": self.n_passed,
            "total": len(self.tasks),
            "isolation": self.isolation,
            "seconds": self.seconds,
            "notes": self.notes,
            "log": self.log,
            "log_bytes": self.log_bytes,
            "survivors": self.survivors,
            "tasks": [t.to_dict() for t in self.tasks],
        }

    def to_junit(self) -> str:
        """A JUnit XML report (one ``testsuite``, one ``testcase`` per task)."""
        return junit_document([self])

    def junit_suite(self) -> ET.Element:
        """This file's ``testsuite`` element (one ``testcase`` per task)."""
        failures = sum(t.status == "failed" for t in self.tasks)
        errors = sum(t.status not in ("passed", "failed") for t in self.tasks)
        suite = ET.Element(
            "testsuite",
            name=xml_text(f"meshlap check {self.file}"),
            tests=str(len(self.tasks)),
            failures=str(failures),
            errors=str(errors),
            time=f"{self.seconds:.3f}",
        )
        student = xml_text(self.submission or os.path.splitext(os.path.basename(self.file))[0])
        share = self.seconds / max(len(self.tasks), 1)
        for t in self.tasks:
            case = ET.SubElement(suite, "testcase", classname=student, name=t.task,
                                 time=f"{share:.3f}")  # fmt: skip
            if t.speed is not None:
                ET.SubElement(case, "system-out").text = xml_text(t.speed.line(t.speed_required))
            if t.passed:
                continue
            tag = "failure" if t.status == "failed" else "error"
            why = t.diagnosis_text or (t.message.splitlines() or [t.status])[0]
            node = ET.SubElement(case, tag, message=xml_text(why or t.status), type=t.status)
            node.text = xml_text("\n".join(t.lines()[1:]))
        return suite

    def gradescope(self) -> dict[str, Any]:
        """Gradescope's ``results.json`` of this file: one test per task (1 point each),
        its output the report's lines, and the file's score."""
        tests = [
            {"name": t.task, "number": str(i + 1), "score": float(t.passed), "max_score": 1.0,
             "status": "passed" if t.passed else "failed", "output": "\n".join(t.lines()),
             "visibility": "visible"}
            for i, t in enumerate(self.tasks)
        ]  # fmt: skip
        head = [self.format_text().splitlines()[0], *self.format_text().splitlines()[1:2]]
        return {"score": float(self.n_passed), "max_score": float(len(self.tasks)),
                "execution_time": round(self.seconds, 3), "output": "\n".join(head),
                "visibility": "visible", "stdout_visibility": "hidden", "tests": tests}  # fmt: skip

    def export_failing(self, folder: str | os.PathLike) -> list[str]:
        """Write each failing task's first failing mesh (``<task>_<mesh>.obj``) and its call's
        arguments (``.npz``: arrays, numbers; a sparse matrix as ``NAME_data``,
        ``NAME_indices``, ``NAME_indptr``, ``NAME_shape``) into ``folder``: the student can
        reproduce the call. Returns the files written."""
        from ..io.write import save_mesh
        from .plain import save_arguments

        written = []
        for t in self.tasks:
            if t.passed or t.repro is None:
                continue
            case, _label, args = t.repro
            stem = os.path.join(os.fspath(folder), f"{t.task}_{case.name}")
            save_mesh(stem + ".obj", case.V, case.F)
            save_arguments(stem + ".npz", tuple(args))
            written += [stem + ".obj", stem + ".npz"]
        return written

    # ---- notebooks ------------------------------------------------------------------------

    def _repr_html_(self) -> str:
        rows = []
        for t in self.tasks:
            colour = "#1a7f37" if t.passed else "#cf222e"
            detail = "" if t.passed else "<br>".join(html.escape(x) for x in t.lines()[1:14])
            rows.append(
                f"<tr><td><code>{html.escape(t.task)}</code></td>"
                f"<td style='color:{colour};font-weight:bold'>"
                f"{html.escape(STATUS_WORDS.get(t.status, t.status))}</td>"
                f"<td style='text-align:left'>{detail}</td></tr>"
            )
        sandbox = self.isolation.get("description", "")
        warn = "" if self.isolation.get("isolated", True) else (
            f"<p style='color:#9a6700'>sandbox: {html.escape(sandbox)}</p>")  # fmt: skip
        return (
            f"<p><b>{html.escape(self.file)}</b>: {self.n_passed}/{len(self.tasks)} passed</p>"
            + warn
            + "<table><tr><th>task</th><th>verdict</th><th>where and why</th></tr>"
            + "".join(rows)
            + "</table>"
        )

    def _repr_png_(self) -> bytes:
        """The notebook picture (:meth:`picture`, EGL when it can)."""
        return self.picture().png

    def picture(self, renderer: Literal["auto", "egl", "matplotlib"] = "auto") -> Picture:
        """A small picture: one cell per task (green passed, red failed, grey not done) and the
        first failure's largest failing mesh coloured by its difference map.

        Parameters
        ----------
        renderer : {"auto", "egl", "matplotlib"}
            ``"auto"``: the viewer's EGL snapshot renderer (``meshlap.check_picture`` entry
            point), and matplotlib's 3D plot if it is not installed or EGL cannot render (the
            picture and :attr:`Picture.reason` say why); ``"egl"`` raises instead of falling
            back.

        Returns
        -------
        Picture

        Raises
        ------
        RuntimeError
            ``renderer="egl"`` and EGL did not render.
        """
        import matplotlib

        matplotlib.use("Agg", force=False)
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6.4, 2.6), dpi=80)
        ax = fig.add_axes((0.02, 0.05, 0.42, 0.9))
        n = len(self.tasks)
        for k, t in enumerate(self.tasks):
            colour = CELL_COLOURS.get(t.status, CELL_COLOURS["failed"])
            ax.barh(n - 1 - k, 1.0, color=colour, height=0.9)
            ax.text(0.03, n - 1 - k, f"{t.task}: {t.status}", va="center", fontsize=7, color="w")
        ax.set_axis_off()
        fail = next((t for t in self.tasks if t.picture is not None and not t.passed), None)
        used, reason = "none", ""
        if fail is None:
            fig.text(0.72, 0.5, f"{self.n_passed}/{n} passed", ha="center", fontsize=12)
        else:
            image = None
            if renderer != "matplotlib":
                try:
                    image = _egl_image(fail)
                except RuntimeError as exc:
                    if renderer == "egl":
                        raise
                    reason = str(exc)
            if image is not None:
                used = "egl"
                _show_image(fig, fail, image)
            else:
                used = "matplotlib"
                _draw_difference(fig, fail)
                if reason:
                    fig.text(0.72, 0.02, _short("EGL unavailable: " + reason, 70),
                             ha="center", fontsize=6, color="#57606a")  # fmt: skip
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        return Picture(buf.getvalue(), used, reason)


@dataclass(frozen=True)
class Picture:
    """A check result's picture.

    Attributes
    ----------
    png : bytes
    renderer : {"egl", "matplotlib", "none"}
        What drew the difference map (``"none"``: no failure with a map to draw).
    reason : str
        Why EGL was not used (``""`` when it was, or was not asked).
    """

    png: bytes
    renderer: str
    reason: str = ""


PICTURE_GROUP = "meshlap.check_picture"
"""Entry-point group of the difference-map renderer: ``f(V, F, difference, signed) -> PNG``."""


def _egl_image(t: TaskResult) -> np.ndarray:
    """The failing mesh's difference map as an RGBA image, rendered by the viewer's EGL
    snapshot renderer (the first ``meshlap.check_picture`` entry point).

    Raises
    ------
    RuntimeError
        No renderer installed, or it failed (its message).
    """
    from importlib.metadata import entry_points

    found = list(entry_points(group=PICTURE_GROUP))
    if not found:
        raise RuntimeError("the viewer (meshlap_app) is not installed")
    V, F, d, _name, signed = t.picture
    try:
        png = found[0].load()(V, F, d, signed)
    except ImportError as exc:
        raise RuntimeError(f"the viewer does not import: {exc}") from exc
    import matplotlib.image as mpimg

    return mpimg.imread(io.BytesIO(png), format="png")


def _show_image(fig: Any, t: TaskResult, image: np.ndarray) -> None:
    ax = fig.add_axes((0.5, 0.05, 0.45, 0.8))
    ax.imshow(image)
    ax.set_axis_off()
    _caption(fig, t)


def _caption(fig: Any, t: TaskResult) -> None:
    _V, _F, d, name, _signed = t.picture
    top = float(np.abs(np.asarray(d, dtype=float)).max()) or 1.0
    fig.text(0.72, 0.92, f"{t.task} on {name}: |student − reference| ≤ {top:.3g}",
             ha="center", fontsize=7)  # fmt: skip


CELL_COLOURS = {
    "passed": "#2da44e",
    "failed": "#cf222e",
    "missing": "#8c959f",
    "not_implemented": "#8c959f",
}


def _draw_difference(fig: Any, t: TaskResult) -> None:
    """The mesh in 3D, each face coloured by its vertices' mean |student − reference|."""
    from matplotlib import colormaps

    V, F, d, _name, _signed = t.picture
    ax = fig.add_axes((0.5, 0.05, 0.45, 0.8), projection="3d")
    face = np.abs(np.asarray(d, dtype=float))[F].mean(axis=1)
    top = float(face.max()) or 1.0
    colours = colormaps["viridis"](face / top)
    poly = ax.plot_trisurf(V[:, 0], V[:, 1], V[:, 2], triangles=F, linewidth=0.2)
    poly.set_facecolors(colours)
    ax.set_axis_off()
    extent = np.ptp(V, axis=0)
    ax.set_box_aspect(np.maximum(extent, 0.05 * max(float(extent.max()), 1e-300)))
    _caption(fig, t)


_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f\ufffe\uffff]")


def xml_text(text: str) -> str:
    """``text`` with the characters XML 1.0 cannot carry escaped (``\x1b`` as ``\\x1b``)."""
    return _NOT_XML.sub(lambda m: repr(m.group())[1:-1], text)


def junit_document(results: list[CheckResult]) -> str:
    """A JUnit XML document: one ``testsuite`` per checked file inside ``testsuites``."""
    root = ET.Element("testsuites")
    root.extend(r.junit_suite() for r in results)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"
