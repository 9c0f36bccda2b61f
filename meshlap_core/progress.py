"""The one progress line of meshlap: work of ``total`` steps reported on stderr.

Every long loop that talks to a user (``meshlap smooth``, ``meshlap spectral``, ``meshlap
report``, ``meshlap animate`` and the viewer's recorder) uses :class:`Progress`. It owns *where
and when* a line is drawn; the caller says *what* the line reads (a ``describe`` function).

Where: on a terminal the line is redrawn in place (``\\r`` and the rest of the line cleared);
otherwise (a pipe, a log, a test capturing stderr) every drawn update is a line of its own, so
logs stay readable. ``in_place=True`` redraws in place on any stream.

When: by default every update is drawn. With a pace (``after_s``, ``every_s``) the first line
waits until ``after_s`` seconds have passed and later ones come at most every ``every_s``
seconds, so a short run prints nothing; a terminal may have its own pace (``tty_after_s``,
``tty_every_s``).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Literal, TextIO

ERASE_LINE = "\x1b[K"
"""ANSI: clear from the cursor to the end of the line."""


def bar(filled: int, width: int, full: str = "#", empty: str = ".") -> str:
    """A text bar of ``width`` characters, the first ``filled`` of them full: ``####......``."""
    filled = min(max(int(filled), 0), width)
    return full * filled + empty * (width - filled)


class Progress:
    """A progress line for work of ``total`` steps.

    Parameters
    ----------
    total : float
        The planned amount of work (steps, frames, or 1.0 for a fraction).
    describe : callable
        ``describe(progress) -> str``: the line, from :attr:`label`, :attr:`done`,
        :attr:`total`, :attr:`elapsed` and :attr:`message`.
    label : str, optional
        What is being done (e.g. ``"animate"``, ``"section 2/7 cotan"``).
    stream : text stream or None, optional
        Where to write; ``sys.stderr`` (looked up when the progress is made) by default;
        ``None`` writes nothing.
    in_place : bool, optional
        Redraw one line in place (``\\r``). Default: only when ``stream`` is a terminal.
    erase : bool, optional
        :meth:`close` erases an in-place line (the output that follows starts on a clean line)
        instead of ending it with a newline.
    after_s, every_s : float, optional
        Seconds before the first line, and at least between two lines (0: every update).
    tty_after_s, tty_every_s : float, optional
        The same on a terminal (default: ``after_s`` and ``every_s``).
    clock : callable, optional
        Seconds (``time.monotonic`` by default; tests pass a fake clock).
    """

    def __init__(
        self,
        total: float,
        describe: Callable[[Progress], str],
        label: str = "",
        *,
        stream: TextIO | Literal["stderr"] | None = "stderr",
        in_place: bool | None = None,
        erase: bool = False,
        after_s: float = 0.0,
        every_s: float = 0.0,
        tty_after_s: float | None = None,
        tty_every_s: float | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.stream: TextIO | None = sys.stderr if stream == "stderr" else stream  # type: ignore[assignment]
        self.total = total
        self.describe = describe
        self.clock = clock
        self.erase = erase
        try:
            self.tty = bool(self.stream is not None and self.stream.isatty())
        except (AttributeError, ValueError):
            self.tty = False
        self.in_place = self.tty if in_place is None else in_place
        first = tty_after_s if self.tty and tty_after_s is not None else after_s
        self.every_s = tty_every_s if self.tty and tty_every_s is not None else every_s
        self.done: float = 0
        self.message = ""
        self.drawn = False
        self._first_s = first
        self.restart(total, label)

    def restart(self, total: float, label: str | None = None) -> None:
        """Begin a new piece of work of ``total`` steps (and its ``label``): the clock, the
        count and the pace start again."""
        self.total, self.done, self.message = total, 0, ""
        if label is not None:
            self.label = label
        self.t0 = self.clock()
        self.elapsed = 0.0
        self._next_s = self._first_s

    @property
    def fraction(self) -> float:
        """``done / total`` (0 when ``total`` is 0)."""
        return self.done / self.total if self.total else 0.0

    def update(self, done: float, message: str | None = None) -> None:
        """Record that ``done`` of :attr:`total` are finished (and the ``message``), and draw
        the line if the pace allows (one clock read when it does not: ~50 ns)."""
        now = self.clock() - self.t0
        self.done = done
        if message is not None:
            self.message = message
        if now < self._next_s:
            return
        self._next_s = now + self.every_s
        self.elapsed = now
        self._draw()

    def step(self, message: str | None = None) -> None:
        """One more step done (never beyond :attr:`total`)."""
        self.update(min(self.done + 1, self.total), message)

    def _draw(self) -> None:
        if self.stream is None:
            return
        line = self.describe(self)
        if self.in_place:
            self.stream.write("\r" + line + (ERASE_LINE if self.tty else ""))
        else:
            self.stream.write(line + "\n")
        self.stream.flush()
        self.drawn = True

    def close(self) -> None:
        """End the work: an in-place line that was drawn is ended with a newline (or erased
        with ``erase=True``); separate lines need nothing."""
        if self.stream is None or not (self.in_place and self.drawn):
            return
        self.stream.write("\r" + ERASE_LINE if self.erase else "\n")
        self.stream.flush()
        self.drawn = False
