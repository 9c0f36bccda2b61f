"""Limiting BLAS threads around small or tall-skinny dense work.

Multi-threaded OpenBLAS gains little on such work on an idle 2-core machine and collapses
(5–20× slower, from spinning threads) when the cores are busy: a dense ``eigh`` of a
361-vertex Laplacian measured 1.9 s with the default threads under load and 0.02 s with one.
"""

from __future__ import annotations

from typing import Any

from threadpoolctl import ThreadpoolController, threadpool_limits


def blas_threads(limit: int, controller: Any = None) -> Any:
    """Context manager limiting BLAS to ``limit`` threads.

    ``controller`` is a cached :class:`threadpoolctl.ThreadpoolController` (0.02 ms per use
    instead of 0.5 ms for a fresh look-up).
    """
    if controller is not None:
        return controller.limit(limits=limit, user_api="blas")
    return threadpool_limits(limits=limit, user_api="blas")


def thread_controller() -> ThreadpoolController:
    """A controller to pass to :func:`blas_threads` in hot loops."""
    return ThreadpoolController()
