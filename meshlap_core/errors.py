"""The project's exception and warning types.

Every problem with user input is reported as a :class:`MeshError` whose message names the
file (or argument) and the problem, e.g. ``"bunny.obj: face 12 has index 40 but the mesh has
35 vertices"``. The CLI turns it into one line ``meshlap: error: <message>`` and exit code 2.
"""

from __future__ import annotations

import os


class MeshError(ValueError):
    """A mesh (or an argument) that meshlap cannot work with.

    Parameters
    ----------
    problem : str
        What is wrong, in words a user understands.
    source : str or os.PathLike, optional
        The file or argument the problem is in; prefixed to the message.
    """

    def __init__(self, problem: str, source: str | os.PathLike | None = None) -> None:
        self.problem = problem
        self.source = None if source is None else os.fspath(source)
        super().__init__(f"{self.source}: {problem}" if self.source else problem)

    def with_source(self, source: str | os.PathLike) -> MeshError:
        """Return the same error attributed to ``source`` (keeps an existing source)."""
        if self.source is not None:
            return self
        return MeshError(self.problem, source)


class MeshWarning(UserWarning):
    """Something was repaired or is numerically doubtful; the result is still usable."""
