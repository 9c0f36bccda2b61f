"""Exercises that check themselves: a student writes the operators, the lab says where and why
they differ from the reference.

- :mod:`.templates`: the student file (``meshlap exercises init DIR``);
- :mod:`.tasks`: the task table, its references (the core) and the classic mistakes;
- :mod:`.meshes`: the battery of meshes chosen to expose those mistakes;
- :mod:`.sandbox`: the student's file runs in a spawned process with time and memory limits;
- :mod:`.compare`: scale-aware tolerances; :mod:`.diagnose`: naming the mistake;
- :mod:`.check`: :func:`check_file`, which ties them together; :mod:`.result`: its report
  (text, JSON, JUnit, notebook table and picture).
"""

from __future__ import annotations

from .check import check_file
from .result import CheckResult, TaskResult
from .templates import template

__all__ = ["CheckResult", "TaskResult", "check_file", "template"]
