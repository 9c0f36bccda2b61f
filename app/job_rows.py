"""A job's row in meshlap's panel: its progress bar and Cancel button on one row, kept when no
job runs (no polyscope import).

The row is drawn where a panel asks for its jobs (:meth:`.host.Host.draw_job`); with none
running it keeps its place, saying how the last one ended (``done: title (1.2 s)``), so the
widgets below never move when a job starts or ends (before, two rows came and went: the
Diffusion panel jumped 60 px twice a second while *play t* ran its jobs, and after Cancel the
button below slid under the pointer). A panel whose button of the same height takes the row's
place passes ``reserve=False``. The jobs of views not on screen get their rows at the panel's
end, where they move nothing.
"""

from __future__ import annotations

from collections.abc import Iterable

from .jobs import Job, Jobs
from .ui import UI


def draw_job(ui: UI, jobs: Jobs, owners: Iterable[str], reserve: bool = True) -> bool:
    """The row of the running job of each of ``owners``; True when one runs. With none
    running (``reserve``) the row says how the last one ended, or is empty."""
    owners = tuple(owners)
    running = [j for o in owners if (j := jobs.running(o)) is not None]
    for job in running:
        draw_row(ui, jobs, job)
    if not running and reserve:
        ui.status_row(jobs.last_outcome(*owners))
    return bool(running)


def draw_row(ui: UI, jobs: Jobs, job: Job) -> None:
    """A running job's bar (what it does, cut at its end if too long; the seconds and the
    percentage kept) and its Cancel button."""
    r = job.reporter
    head, tail = job.line_parts()
    fraction = r.fraction if r.fraction is not None else 0.0
    tooltip = f"stop: {job.title} (what is shown stays)"
    if ui.job_row(fraction, head, tail, f"Cancel##{job.owner}", tooltip):
        jobs.cancel(job.owner)


def draw_others(ui: UI, jobs: Jobs, shown: set[str]) -> None:
    """A row for each running job whose owner is not in ``shown`` (its panel is not on
    screen), so a job is seen whatever view is active."""
    for job in jobs.all_running():
        if job.owner not in shown:
            draw_row(ui, jobs, job)
