"""The window's pause between two frames (:class:`FrameWait`; no polyscope import): how long
is :mod:`.pacing`'s decision, how it waits is this module's.

In the window the pause is GLFW's wait for the window's events (:func:`.window.wait_events`):
a key or a mouse move ends it at once, so input never waits out an idle frame period, and a
job's news ends it too (:func:`.window.wake` from the job's thread, set as
:attr:`~.jobs.Jobs.wake`). Without a GLFW window (tests, the animator, a headless render) it
is a nap that a job's news ends (:meth:`.jobs.Jobs.nap`).

``MESHLAP_PACING_TRACE=<file>``: the window appends one JSON line per frame (when its pause
began and ended, how long it was meant to last, the rate and whether the frame started with
input: :meth:`.pacing.Pacer.wait`), to see why a frame came late.
"""

from __future__ import annotations

import json
import os

from . import window
from .jobs import Jobs
from .pacing import Pacer

TRACE_ENV = "MESHLAP_PACING_TRACE"
"""The environment variable naming the pacing trace's file."""


class FrameWait:
    """The pause between two frames (call it with the seconds; see the module docstring).

    Parameters
    ----------
    jobs : Jobs
        The window's jobs: their news ends the pause.
    """

    def __init__(self, jobs: Jobs) -> None:
        self.jobs = jobs
        self.events = False  # GLFW's wait for events (set by listen, in the window)

    def __call__(self, seconds: float) -> None:
        if self.jobs.news.is_set():
            return  # a result waits: show it now
        if not (self.events and window.wait_events(seconds)):
            self.jobs.nap(seconds)

    def listen(self, pacer: Pacer) -> None:
        """Wait for the window's events from now on, woken by the jobs' news (once the window
        exists; nothing changes without a GLFW window), and write ``pacer``'s trace when
        :data:`TRACE_ENV` names a file."""
        if window.title_follows():
            self.events = True
            self.jobs.wake = window.wake
        trace = os.environ.get(TRACE_ENV)
        if trace:
            out = open(trace, "a", buffering=1, encoding="utf-8")  # open while the window is
            pacer.trace = lambda record: out.write(json.dumps(record) + "\n")
