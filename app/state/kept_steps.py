"""The positions of a smoothing run's last steps, kept so that the window can step back (``←``)
and so that *pause* can show the step on screen when it was pressed, discarding the steps a
child-process stepper computed ahead (no polyscope).

:class:`meshlap_core.smoothing.Smoother` keeps no positions (a step replaces ``V``); going
back needs them. One ``(n,3) float64`` array per step is 24 bytes a vertex: every step of a
small mesh fits in a few megabytes, the 692k scan's take 16.6 MB each. So the last
:func:`kept_for` steps are kept: at most :data:`MAX_KEPT` and at most :data:`KEPT_BYTES`
(8 steps of the scan, 200 of the bundled mesh). The input (iteration 0) is always there: it
is the stepper's ``V0``.
"""

from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError

KEPT_BYTES = 128 * 2**20
"""Most bytes of positions a run keeps (see the module docstring)."""
MAX_KEPT = 200
"""Most steps a run keeps, however small the mesh."""


def kept_for(n: int) -> int:
    """Steps kept for a mesh of ``n`` vertices: ``KEPT_BYTES // (24 n)``, between 2 and
    :data:`MAX_KEPT`."""
    return int(max(2, min(MAX_KEPT, KEPT_BYTES // max(24 * int(n), 1))))


class KeptSteps:
    """The last :attr:`capacity` steps' positions of one stepper, by iteration.

    Parameters
    ----------
    n : int
        The mesh's vertex count (sets :attr:`capacity`, :func:`kept_for`).
    """

    def __init__(self, n: int) -> None:
        self.capacity = kept_for(n)
        self._kept: deque[tuple[int, np.ndarray]] = deque()

    def record(self, iteration: int, V: Any) -> None:
        """Keep a copy of ``V (n,3)``, the positions after step ``iteration`` (what was kept
        for that iteration or later, from a run stepped back, goes)."""
        self.truncate(iteration - 1)
        if iteration > 0:
            self._kept.append((int(iteration), np.array(V, dtype=np.float64)))
        while len(self._kept) > self.capacity:
            self._kept.popleft()

    def truncate(self, iteration: int) -> None:
        """Forget the steps after ``iteration``."""
        while self._kept and self._kept[-1][0] > iteration:
            self._kept.pop()

    def clear(self) -> None:
        """Forget every step (a reset: back to the input)."""
        self._kept.clear()

    @property
    def oldest(self) -> int:
        """The earliest iteration one can step back to besides the input (0 when none)."""
        return self._kept[0][0] if self._kept else 0

    def rewind(self, smoother: Any, target: int) -> int:
        """Put ``smoother`` back to the positions of iteration ``target`` (the input for 0:
        ``smoother.V0``) and forget the steps after it; returns ``target``.

        Raises
        ------
        MeshError
            ``target`` is not kept (older than the last :attr:`capacity` steps, or not
            reached yet); the smoother is unchanged.
        """
        target = int(target)
        if target == 0:
            V = smoother.V0
        else:
            V = next((P for k, P in self._kept if k == target), None)
            if V is None:
                raise MeshError(self.missing(target, smoother.iteration))
        smoother.rewind(V, target)
        self.truncate(target)
        return target

    def missing(self, target: int, current: int) -> str:
        """Why iteration ``target`` cannot be gone back to from ``current``."""
        if target > current:
            return f"iteration {target} is not reached yet (the run is at {current})"
        return (
            f"iteration {target} is no longer kept: the last {self.capacity} steps are kept "
            f"(back to iteration {self.oldest}); reset goes back to the input"
        )
