"""The seven sections of the report, one module each, in report order.

Each module defines ``KEY`` (its name for ``--sections``), ``TITLE``, ``STEPS`` (progress steps
in quick and in full mode) and ``run(ctx, sec)``, which measures, writes its tables and figures
through the :class:`~meshlap_core.course_report.context.Context` and appends its blocks to ``sec``.
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

from ..context import Context
from ..document import Section
from . import cotan, denoising, helicoid, onering, smoothing, spectral, uniform

SectionRunner = Callable[[Context, Section], None]

_MODULES: tuple[ModuleType, ...] = (
    onering,
    uniform,
    helicoid,
    cotan,
    spectral,
    smoothing,
    denoising,
)

SECTIONS: tuple[str, ...] = tuple(m.KEY for m in _MODULES)
"""Section keys, in report order (``--sections`` accepts these names or the numbers 1–7)."""

SECTION_TITLES: dict[str, str] = {m.KEY: m.TITLE for m in _MODULES}

SECTION_RUNNERS: dict[str, tuple[SectionRunner, int, int]] = {
    m.KEY: (m.run, *m.STEPS) for m in _MODULES
}
"""key → (function, progress steps in quick mode, progress steps in full mode)."""

COURSE_EIGEN_SECONDS = spectral.COURSE_EIGEN_SECONDS

__all__ = ["COURSE_EIGEN_SECONDS", "SECTIONS", "SECTION_RUNNERS", "SECTION_TITLES", "SectionRunner"]
