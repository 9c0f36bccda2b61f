"""The checker's side of every call: its arguments, the reference answer and how long it took,
the classic mistakes' wrong answers — all computed in the checker's process, never in the
student's, and once per process for the battery's meshes (a class of 200 files computes each
reference once; threads of ``--jobs`` wait for the one computing it).

A mesh not in the battery (the viewer's) is computed afresh each time.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from .meshes import Case, battery
from .tasks import Args, Mistake, Output, Task

_LOCK = threading.Lock()
_CACHE: dict[tuple[Any, ...], Any] = {}
_PENDING: dict[tuple[Any, ...], threading.Lock] = {}


def is_battery(case: Case) -> bool:
    """``case`` is one of the battery's own meshes (not a copy, not the viewer's)."""
    return any(case is c for c in battery())


def _cached(key: tuple[Any, ...], case: Case, compute: Callable[[], Any]) -> Any:
    if not is_battery(case):
        return compute()
    with _LOCK:
        if key in _CACHE:
            return _CACHE[key]
        lock = _PENDING.setdefault(key, threading.Lock())
    with lock:
        with _LOCK:
            if key in _CACHE:
                return _CACHE[key]
        value = compute()
        with _LOCK:
            _CACHE[key] = value
            _PENDING.pop(key, None)
    return value


def calls(task: Task, case: Case) -> list[tuple[str, Args]]:
    """The task's calls on ``case``: ``[(label, args)]``."""
    return _cached(("calls", task.name, case.name), case, lambda: task.calls(case))


def _timed(task: Task, case: Case, args: Args) -> tuple[Output, float]:
    t0 = time.perf_counter()
    out = task.reference(case, args)
    return out, time.perf_counter() - t0


def expected_timed(task: Task, case: Case, label: str, args: Args) -> tuple[Output, float]:
    """The reference answer of one call, and the seconds it took when computed."""
    return _cached(("ref", task.name, case.name, label), case, lambda: _timed(task, case, args))


def expected(task: Task, case: Case, label: str, args: Args) -> Output:
    """The reference answer of one call."""
    return expected_timed(task, case, label, args)[0]


def wrong(task: Task, index: int, mistake: Mistake, case: Case, label: str, args: Args) -> Output:
    """Mistake number ``index`` of ``task``'s candidates: its wrong answer on one call."""
    key = ("wrong", task.name, index, mistake.key, case.name, label)
    return _cached(key, case, lambda: mistake.wrong(case, args))


def reference_speed(task: Task, case: Case, args: Args, repeat: int = 3) -> tuple[float, float]:
    """``(CPU seconds, wall seconds)`` of the reference on one call, the best of ``repeat``
    fresh runs (this thread's CPU time: other threads' work does not count)."""
    best = (float("inf"), float("inf"))
    for _ in range(repeat):
        c0, w0 = time.thread_time(), time.perf_counter()
        task.reference(case, args)
        best = min(best, (time.thread_time() - c0, time.perf_counter() - w0))
    return best
