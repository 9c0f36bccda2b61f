"""Speed is its own verdict: a band of ratios to the reference, the same rule for every task,
and the loop where a slow answer spends its time.

Every task is timed on its speed mesh (``large``; ``large_disk`` for the maps of a disk) in
several runs (:mod:`.sandbox`), each beside the reference's best of three. A run's student time
is the worker's CPU seconds (read by the checker from ``/proc``: a loaded machine stretches the
wall clock, not the CPU time a loop needs), or for a call under :data:`CPU_RESOLUTION` (below
the clock tick's resolution) its wall time beside the reference's. The band is the lowest and
the highest ratio; the answer is *slow* when even the lowest is ``EXERCISE_SLOW_RATIO`` or more
and the call takes at least ``EXERCISE_SLOW_MIN_SECONDS``. A slow right answer passes, with the
line saying so, unless the teacher asks (``meshlap check --require-speed``).
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..options import EXERCISE_SLOW_MIN_SECONDS, EXERCISE_SLOW_RATIO
from .copies import read_source

CPU_RESOLUTION = 0.1
"""Student CPU seconds below which a run is measured by its wall time (``/proc`` counts in
clock ticks of 10 ms)."""
REF_FLOOR = 1e-4
"""Seconds: a reference faster than this is counted as this (the ratio stays finite)."""


@dataclass(frozen=True)
class Speed:
    """The speed line of one task.

    Attributes
    ----------
    low, high : float
        The band: the lowest and the highest ratio student / reference over the runs.
    seconds : float
        The student's fastest run, seconds.
    reference : float
        The reference's time in that run, seconds.
    vertices : int
        The mesh's size.
    runs : int
    slow : bool
    loop : str
        Where a slow answer spends its time (``""`` when not slow, or not known).
    """

    low: float
    high: float
    seconds: float
    reference: float
    vertices: int
    runs: int
    slow: bool
    loop: str = ""

    def line(self, required: bool = False) -> str:
        """The report's line (``required``: ``--require-speed``, a slow answer fails)."""
        band = f"{self.low:.0f}×" if round(self.low) == round(self.high) else (
            f"{self.low:.0f}–{self.high:.0f}×")  # fmt: skip
        where = (f"{self.seconds:.3g} s on {self.vertices} vertices, the reference "
                 f"{self.reference:.2g} s; {self.runs} runs")  # fmt: skip
        if self.seconds < CPU_RESOLUTION:
            return (
                f"speed: fine, under {CPU_RESOLUTION:g} s on {self.vertices} vertices (the "
                f"reference {self.reference:.2g} s; {self.runs} runs)"
            )
        if not self.slow:
            return f"speed: fine, {band} the reference's time ({where})"
        verdict = "fails (--require-speed)" if required else "a right answer still passes"
        loop = f"; most of the time is in {self.loop}" if self.loop else ""
        return f"speed: SLOW, {band} the reference's time ({where}){loop} — {verdict}"

    def to_dict(self) -> dict[str, Any]:
        return dict(vars(self))


def measure(runs: list[tuple[float, float, float, float]], vertices: int) -> Speed | None:
    """The band of ``runs`` (student CPU, student wall, reference CPU, reference wall)."""
    if not runs:
        return None
    pairs = []
    for cpu, wall, ref_cpu, ref_wall in runs:
        mine, ref = (cpu, ref_cpu) if cpu >= CPU_RESOLUTION else (wall, ref_wall)
        pairs.append((mine / max(ref, REF_FLOOR), mine, max(ref, REF_FLOOR)))
    ratios = [p[0] for p in pairs]
    fastest = min(pairs, key=lambda p: p[1])
    slow = min(ratios) >= EXERCISE_SLOW_RATIO and fastest[1] >= EXERCISE_SLOW_MIN_SECONDS
    return Speed(min(ratios), max(ratios), fastest[1], fastest[2], vertices, len(runs), slow)


def _source_line(lines: list[str], number: int) -> str:
    text = lines[number - 1].strip() if 0 < number <= len(lines) else ""
    return text if len(text) <= 70 else text[:69] + "…"


def hot_loop(hot: list[list[Any]], folder: Path) -> str:
    """``the loop at line 14 of exercises.py (`for i in range(n):`)``: the innermost loop
    around the line the profiler saw most, read from the student's own file (parsed, never
    run), or ``""``."""
    for file, line, _count in hot:
        source = read_source(folder / file)
        try:
            tree = ast.parse(source) if source is not None else None
        except (SyntaxError, ValueError):
            tree = None
        if tree is None or source is None:
            continue
        loops = [
            n for n in ast.walk(tree)
            if isinstance(n, (ast.For, ast.While, ast.ListComp, ast.DictComp,
                              ast.SetComp, ast.GeneratorExp))
            and getattr(n, "lineno", 0) <= line <= (getattr(n, "end_lineno", 0) or 0)
        ]  # fmt: skip
        lines = source.splitlines()
        if not loops:
            return f"line {line} of {file} (`{_source_line(lines, line)}`)"
        inner = max(loops, key=lambda n: n.lineno)
        return f"the loop at line {inner.lineno} of {file} (`{_source_line(lines, inner.lineno)}`)"
    return ""
