"""What the linear-algebra modules share: array aliases, the progress callback, ``SolveInfo``."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import check_cancel

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

ProgressCallback = Callable[[float, str], None]
"""``progress(fraction, message)``: ``fraction`` in ``[0, 1]``; raise from it to cancel."""


@dataclass
class SolveInfo:
    """How an eigenbasis was computed (for reports and the benchmark)."""

    method: str = ""
    n_vertices: int = 0
    k: int = 0
    n_components: int = 0
    shifts: list[float] = field(default_factory=list)
    krylov_dims: list[int] = field(default_factory=list)
    n_operator_applications: int = 0
    n_factorizations: int = 0
    n_clipped: int = 0
    min_raw_eigenvalue: float = 0.0
    max_residual: float = float("nan")
    orthogonality_error: float = float("nan")  # max|UᵀMU − I| of the result (sampled rows)
    timings: dict[str, float] = field(default_factory=dict)
    from_cache: bool = False
    cache_path: str | None = None
    messages: list[str] = field(default_factory=list)


class CancellableProgress:
    """A :data:`ProgressCallback` that raises :class:`~meshlap_core.errors.Cancelled` once
    ``cancel`` asks to stop, at the next report or :meth:`check` (the slice workers check
    between Lanczos blocks), and otherwise forwards to ``progress``.

    Parameters
    ----------
    progress : callable or None
        ``progress(fraction, message)``.
    cancel : threading.Event, callable or None
        See :func:`meshlap_core.errors.cancelled`.
    what : str
        Named in the exception: ``"<what> cancelled"``.
    """

    def __init__(self, progress: ProgressCallback | None, cancel: Any, what: str) -> None:
        self.progress, self.cancel, self.what = progress, cancel, what

    def check(self) -> None:
        """Raise :class:`~meshlap_core.errors.Cancelled` if ``cancel`` asks to stop."""
        check_cancel(self.cancel, self.what)

    def __call__(self, fraction: float, message: str) -> None:
        self.check()
        if self.progress is not None:
            self.progress(fraction, message)


def with_cancel(
    progress: ProgressCallback | None, cancel: Any, what: str
) -> ProgressCallback | None:
    """``progress`` unchanged without ``cancel``, else a :class:`CancellableProgress`."""
    return progress if cancel is None else CancellableProgress(progress, cancel, what)


def cancel_check(progress: ProgressCallback | None) -> Callable[[], None] | None:
    """The ``check()`` of a :class:`CancellableProgress` (``None`` for any other callback)."""
    return progress.check if isinstance(progress, CancellableProgress) else None


def report_progress(progress: ProgressCallback | None, frac: float, msg: str) -> None:
    """Call ``progress`` (if any) with ``frac`` clipped to ``[0, 1]``."""
    if progress is not None:
        progress(float(min(max(frac, 0.0), 1.0)), msg)
