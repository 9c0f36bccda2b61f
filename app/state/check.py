"""The Check panel's state (``CheckState``): a student's exercises file checked on the mesh on
screen, the difference map student − reference and the rows at a clicked vertex (no polyscope).

The check itself is :func:`meshlap_core.exercises.check.check_on_mesh`: the student's file runs
in a separate process with a time and memory limit, so a hung or crashing student function
never touches the viewer; the panel runs it as a background job.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError
from meshlap_core.exercises.check import MeshCheck, check_on_mesh
from meshlap_core.exercises.tasks import EXERCISE_TASKS, TASKS
from meshlap_core.options import length_unit, titled

from ..panel_spec import PanelSpec
from .isolines import isoline_fields
from .settings import MAX_INT, Choice, Integer, Settings, Text, Toggle

VIEWER_TASKS: tuple[str, ...] = EXERCISE_TASKS
"""Every task ``meshlap check`` checks: each has a difference map per vertex of the mesh on
screen (the eigenbasis: ``|u_j − u_ref,j|`` with signs aligned, or the residual; the
reconstruction: the row's largest component) and rows at a vertex."""


# fmt: off
SETTINGS = Settings(
    Text("file", "", label="student file", max_len=4096, example="hw/exercises.py",
         tooltip="your exercises .py (meshlap exercises init DIR writes one)"),
    Choice("task", "cotan_laplacian", choices=VIEWER_TASKS, label="task",
           tooltip="the function of your file"),
    Integer("vertex", -1, lo=-1, hi=MAX_INT - 1, label="vertex",
            tooltip="click the mesh, or type a vertex"),
    Toggle("checked", False, label="check", widget="button",
           tooltip="run your function on this mesh and the battery",
           quiet=False),  # another panel's animation runs no student code
    isoline_fields(("difference",)),
)
# fmt: on
"""The Check panel's section of a saved session: the student file as typed (relative: in the
viewer's folder), the task, the clicked vertex, and whether a check was shown (``checked``:
loading the session runs it again, as a job, on the session's mesh). A student file missing on
this machine does not refuse the session: the panel says so in red."""


def check_mesh(values: dict[str, Any], mesh: Any, source: Any) -> None:
    """A saved vertex the session's mesh has (``-1``: none).

    Raises
    ------
    MeshError
        ``check.vertex`` beyond the mesh's vertices.
    """
    if values["vertex"] >= len(mesh.V):
        raise MeshError(
            f'"check.vertex" {values["vertex"]} is out of range (the mesh has '
            f"{len(mesh.V)} vertices)",
            source,
        )


@dataclass
class CheckState:
    """What the Check panel shows.

    Attributes
    ----------
    file : str
        The student's file as typed.
    task : str
        One of :data:`VIEWER_TASKS`.
    check : MeshCheck or None
        The last finished check (kept while a new one runs, and when a new one fails).
    checked_for : tuple
        ``(mesh version, file, task)`` of ``check``.
    vertex : int
        The clicked vertex (``-1``: none).
    """

    file: str = SETTINGS.default("file")
    task: str = SETTINGS.default("task")
    check: MeshCheck | None = None
    checked_for: tuple[Any, ...] = ()
    vertex: int = SETTINGS.default("vertex")

    def set_task(self, task: str) -> None:
        self.task = SETTINGS["task"].checked(task, "task")

    def student_path(self, folder: Path) -> Path:
        """The typed file (relative to ``folder``), checked to exist.

        Raises
        ------
        MeshError
            Empty, missing, or not a ``.py`` file.
        """
        text = self.file.strip()
        if not text:
            raise MeshError("type the path of your exercises file (.py) first", "student file")
        path = Path(text).expanduser()
        path = path if path.is_absolute() else folder / path
        if not path.is_file():
            raise MeshError(f"{os.fspath(path)!r} does not exist", "student file")
        if path.suffix != ".py":
            raise MeshError(f"{path.name!r} is not a Python file (.py)", "student file")
        return path

    @staticmethod
    def compute(path: Path, task: str, V: np.ndarray, F: np.ndarray, progress: Any = None):
        """The check (any thread: touches no state). The student's code runs in a process of
        its own, so a job's thread only waits; ``progress.cancel`` (a job's Cancel) kills it."""
        if progress is not None:
            progress(None, f"checking {task} of {path.name} (separate process)")
        cancel = getattr(progress, "cancel", None)
        return check_on_mesh(path, task, V, F, cancel=cancel)

    def adopt(self, check: MeshCheck, key: tuple[Any, ...]) -> None:
        self.check, self.checked_for = check, key

    def current(self, version: int) -> bool:
        """The shown check was made on this mesh version."""
        return self.check is not None and self.checked_for[:1] == (version,)

    def select(self, vertex: int, n: int) -> None:
        """Select ``vertex`` (its rows are shown beside the reference's).

        Raises
        ------
        MeshError
            Out of range.
        """
        if not 0 <= vertex < n:
            raise MeshError(
                f"vertex {vertex} is out of range (the mesh has {n} vertices)", "vertex"
            )
        self.vertex = int(vertex)

    def rows(self) -> list[tuple[str, str, str]]:
        """``(term, student, reference)`` at the selected vertex (``[]``: nothing to show)."""
        if self.check is None or self.vertex < 0:
            return []
        return self.check.rows(self.vertex)

    def verdict(self) -> list[str]:
        """The check's text report, one line each: the battery's, as ``meshlap check``
        prints it (one function, one count of failing calls), then the mesh on screen's."""
        if self.check is None:
            return []
        ok = self.check.on_screen
        screen = {True: "right", False: "wrong (the map shows where)", None: "no answer"}[ok]
        return [*self.check.result.tasks[0].lines(), f"on the mesh on screen: {screen}"]


def difference_title(task: str, signed: bool) -> str:
    """The colour bar's title of a check's difference map on the mesh: what it measures and
    its unit (the task's answer is in ``length^power``, :attr:`.tasks.Task.power`; an
    eigenbasis is mapped by its vectors, ``|u_j − u_ref,j|`` in ``1/length``)."""
    t = TASKS[task]
    if t.kind == "ring":
        return titled(f"{task}: ring wrong (1) or right (0)", "dimensionless")
    if t.kind == "eigen":
        return titled(f"{task}: largest |u_j - u_ref,j| over j", "1/length")
    what = "student - reference" if signed else "largest |student - reference| of the row"
    return titled(f"{task}: {what}", length_unit(t.power))


SPEC = PanelSpec(
    name="check",
    title="Check (exercises)",
    summary="a student's exercises file checked on the mesh on screen: the verdict, the "
    "difference map student - reference, and the rows at a clicked vertex",
    panel="CheckPanel",
    state=CheckState,
    settings=SETTINGS,
    check_mesh=check_mesh,
)
"""The Check panel."""
