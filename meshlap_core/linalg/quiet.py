"""Silencing what C libraries print on the process's standard output (file descriptor 1).

Operating-system plumbing, not linear algebra proper; it lives here because the sparse solvers
are what need it (CHOLMOD prints ``CHOLMOD warning: not positive definite`` with ``printf``).
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator


@contextlib.contextmanager
def quiet_c_stdout() -> Iterator[None]:
    """Silence what C libraries print on the process's standard output (file descriptor 1).

    CHOLMOD (inside ``cholespy``) prints ``CHOLMOD warning: not positive definite`` with
    ``printf`` before the Python exception is raised; on a ``--json`` command that line would
    corrupt the output. Python's own ``sys.stdout`` is flushed first and is unaffected.
    """
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):  # no real descriptor 1 (embedded interpreter)
        yield
        return
    libc = None
    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        if libc is not None:
            with contextlib.suppress(Exception):
                libc.fflush(None)  # drop C stdio's buffered copy of the message too
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
