"""What the linear-algebra modules share: array aliases, the progress callback, ``SolveInfo``."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

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


def report_progress(progress: ProgressCallback | None, frac: float, msg: str) -> None:
    """Call ``progress`` (if any) with ``frac`` clipped to ``[0, 1]``."""
    if progress is not None:
        progress(float(min(max(frac, 0.0), 1.0)), msg)
