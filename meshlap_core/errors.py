"""The project's exception and warning types.

Every problem with user input is reported as a :class:`MeshError` whose message names the
file (or argument) and the problem, e.g. ``"bunny.obj: face 12 has index 40 but the mesh has
35 vertices"``. The CLI turns it into one line ``meshlap: error: <message>`` and exit code 2.
"""

from __future__ import annotations

import os
from typing import Any

#: the short escapes of :func:`printable` (the other non-printable characters get ``\\xNN``)
_ESCAPES = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def printable(text: str) -> str:
    """``text`` with every non-printable character escaped, for a message on a terminal.

    A file name may hold a NUL byte, ANSI escape sequences (which would recolour or clear the
    user's terminal), bidirectional overrides or bytes that are not valid in the file-system
    encoding (surrogates after :func:`os.fsdecode`, which no stream can encode): each becomes
    ``\\n``, ``\\t``, ``\\xNN``, ``\\uNNNN`` as in Python's ``repr``; everything else
    (letters of any script, ``χ``, spaces) is kept.

    Parameters
    ----------
    text : str

    Returns
    -------
    str

    Examples
    --------
    >>> printable("a\x1b[31mb.obj")
    'a\\x1b[31mb.obj'
    """
    if text.isprintable():
        return text
    out = []
    for ch in text:
        if ch.isprintable():
            out.append(ch)
        elif ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        else:
            out.append(repr(ch)[1:-1])  # \\x00, \\x1b, \\u202e, \\udcff
    return "".join(out)


class MeshError(ValueError):
    """A mesh (or an argument) that meshlap cannot work with.

    Parameters
    ----------
    problem : str
        What is wrong, in words a user understands.
    source : str or os.PathLike, optional
        The file or argument the problem is in; prefixed to the message with its non-printable
        characters escaped (:func:`printable`); :attr:`source` keeps it as given.

    Examples
    --------
    >>> from meshlap_core import MeshError, validate_mesh
    >>> try:
    ...     validate_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 5]])
    ... except MeshError as error:
    ...     print(error)
    F: face 0 has index 5 but the mesh has 3 vertices (valid indices 0..2)
    >>> issubclass(MeshError, ValueError)
    True
    """

    def __init__(self, problem: str, source: str | os.PathLike | None = None) -> None:
        self.problem = problem
        self.source = None if source is None else os.fspath(source)
        shown = None if self.source is None else printable(os.fsdecode(self.source))
        super().__init__(f"{shown}: {problem}" if shown else problem)

    def with_source(self, source: str | os.PathLike) -> MeshError:
        """Return the same error attributed to ``source`` (keeps an existing source)."""
        if self.source is not None:
            return self
        return MeshError(self.problem, source)


class MeshWarning(UserWarning):
    """Something was repaired or is numerically doubtful; the result is still usable.

    Examples
    --------
    An explicit step above the stability limit still runs, with a warning:

    >>> import warnings
    >>> from meshlap_core import MeshWarning, Smoother, icosphere
    >>> V, F = icosphere(2)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     smoother = Smoother(V, F, "explicit", "uniform", lam=1.5)
    >>> [w.category is MeshWarning for w in caught]
    [True]
    >>> "largest stable lam 1.346" in str(caught[0].message)
    True
    """


class Cancelled(Exception):
    """A long operation stopped because its caller asked it to (the ``cancel`` argument).

    Raised between steps (Lanczos blocks, smoothing iterations, load phases), never in the
    middle of one; the operation's inputs and any object it belongs to are left as they were
    before the cancelled call (a :class:`~meshlap_core.Smoother` keeps the steps it finished).
    """


#: what a ``cancel=`` argument accepts: a ``threading.Event`` (set to cancel), a callable
#: returning ``True`` to cancel, or ``None``
Cancel = Any


def cancelled(cancel: Cancel) -> bool:
    """Whether ``cancel`` (an object with ``is_set()``, a callable, or ``None``) asks to stop."""
    if cancel is None:
        return False
    is_set = getattr(cancel, "is_set", None)
    return bool(is_set() if is_set is not None else cancel())


def check_cancel(cancel: Cancel, what: str) -> None:
    """Raise :class:`Cancelled` (``"<what> cancelled"``) when ``cancel`` asks to stop."""
    if cancelled(cancel):
        raise Cancelled(f"{what} cancelled")
