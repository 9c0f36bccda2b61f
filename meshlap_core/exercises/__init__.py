"""Exercises that check themselves: a student writes the operators, the lab says where and why
they differ from the reference; a teacher grades a class with the same checker.

- :mod:`.tasks`: the task table (every task declared once: stub, meshes, reference, mistakes);
  :mod:`.task_formulas`, :mod:`.geodesic_task`: the references and the mistakes;
  :mod:`.templates`: the student file (``meshlap exercises init DIR``);
- :mod:`.meshes`: the battery of meshes chosen to expose those mistakes;
- :mod:`.harness`: the only program that runs beside a student's file (no meshlap in it);
  :mod:`.isolation`: bubblewrap, or a plain process (said); :mod:`.worker`, :mod:`.sandbox`:
  the checker drives it, owning the clock and the limits; :mod:`.plain`: what crosses back is
  plain arrays only; :mod:`.copies`: each submission in a copy of its own;
- :mod:`.references`: the reference answers, in the checker's process; :mod:`.compare`:
  scale-aware tolerances; :mod:`.diagnose`: naming the mistake; :mod:`.speed`: the speed line;
  :mod:`.verdict`: from answers to verdicts;
- :mod:`.check`: :func:`check_file` ties them together; :mod:`.grading`: a class folder,
  in parallel, into CSV, JSON, JUnit and Gradescope's ``results.json``; :mod:`.result`: one
  file's report (text, JSON, JUnit, notebook table and picture).
"""

from __future__ import annotations

from .check import check_file
from .result import CheckResult, TaskResult
from .tasks import EXERCISE_TASKS
from .templates import template
from .worker import Session

__all__ = ["EXERCISE_TASKS", "CheckResult", "Session", "TaskResult", "check_file", "template"]
