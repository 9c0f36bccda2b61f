"""How often the window draws: full rate on input, a slower pace while a job runs, a low idle
rate when nothing happens (no polyscope, no imgui).

polyscope's own frame limit (``set_max_fps``) waits by spinning, so it costs a core whatever
the rate; the viewer therefore turns it off (``set_max_fps(-1)``) and the :class:`Pacer`
sleeps at the start of each frame instead (``time.sleep`` releases the GIL, so a job's worker
gets the core). The rule:

- *active* (input this frame or less than :data:`IDLE_AFTER_S` ago, something playing or
  recording): :data:`FULL_FPS`;
- a job runs: :data:`BUSY_FPS` (the progress line still moves several times a second);
- otherwise *idle*: :data:`IDLE_FPS`, and :data:`DEEP_IDLE_FPS` after :data:`DEEP_IDLE_AFTER_S`
  (each idle frame still costs tens of milliseconds of CPU with a software OpenGL).

Input is never kept waiting by the pause: in the window the pause is GLFW's wait for events
(:func:`.window.wait_events`), which ends as soon as input (or a job's news, posted as an
empty event) arrives, and a frame that starts with input pending (``wait(input_now=True)``:
the key or the mouse arrived during the last frame's drawing) does not pause at all. Before,
the pause was a plain sleep placed before the frame read its input: a key pressed at 2
frames/s waited out the rest of one pause, then a whole second one, and showed 1–2 s later.
With ``MESHLAP_PACING_TRACE=<file>`` the window appends one JSON line per frame (see
:meth:`Pacer.wait`), to see why a frame came late.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

FULL_FPS = 60.0
"""Frames per second with input (polyscope's default limit)."""
BUSY_FPS = 6.0
"""Frames per second while a job runs and the user does nothing: the render loop leaves the
cores to the worker (an eigenbasis takes about as long as ``meshlap spectral``)."""
IDLE_FPS = 4.0
"""Frames per second with nothing happening (< 10 % of a core on a 692k-vertex mesh)."""
IDLE_AFTER_S = 1.0
"""Seconds without input after which the window drops to the idle rate."""
DEEP_IDLE_FPS = 1.0
"""Frames per second after :data:`DEEP_IDLE_AFTER_S` without input (a few % of a core with
Mesa's llvmpipe at 1280×720). Input does not wait for the next idle frame (the pause is a
wait for events, see the module docstring), so this rate costs no answer time: it was 2 while
the first input waited out the pause."""
DEEP_IDLE_AFTER_S = 4.0


@dataclass
class Pacer:
    """Decides (and sleeps) the pause before each frame; records the longest gap between two
    frames while a job ran (the UI stall a user sees).

    Parameters
    ----------
    clock, sleep : callable
        ``time.monotonic`` and ``time.sleep`` (a test gives its own).
    """

    clock: Callable[[], float] = time.monotonic
    sleep: Callable[[float], None] = time.sleep
    full_fps: float = FULL_FPS
    busy_fps: float = BUSY_FPS
    idle_fps: float = IDLE_FPS
    idle_after: float = IDLE_AFTER_S
    deep_fps: float = DEEP_IDLE_FPS
    deep_after: float = DEEP_IDLE_AFTER_S
    last_input: float = field(default=-1e9)
    last_frame: float | None = None
    max_busy_gap: float = 0.0  # longest time between two frames while a job ran
    mode: str = "active"
    trace: Callable[[dict[str, float | str | bool]], None] | None = None  # one call per wait
    frames: int = 0  # waits so far (one per frame)

    def __post_init__(self) -> None:
        self.last_input = self.clock()

    def touch(self) -> None:
        """Input (or a change worth showing at full rate) happened now."""
        self.last_input = self.clock()

    def rate(self, busy: bool, animating: bool) -> float:
        """Frames per second for the next frame (and :attr:`mode` set to ``active``,
        ``busy`` or ``idle``)."""
        quiet = self.clock() - self.last_input
        if animating or quiet < self.idle_after:
            self.mode = "active"
            return self.full_fps
        self.mode = "busy" if busy else "idle"
        if busy:
            return self.busy_fps
        return self.deep_fps if quiet >= self.deep_after else self.idle_fps

    def wait(self, busy: bool, animating: bool = False, input_now: bool = False) -> float:
        """Sleep what is left of this frame's period; returns the pause asked of the sleep.

        ``input_now``: the frame starts with input to answer (it counts as :meth:`touch`, and
        nothing is slept: the answer is drawn in this frame). The sleep given to the pacer may
        end early (the window's ends on any input event); the next frame then reads that input.
        :attr:`trace`, when set, gets one record per call: ``frame`` (its number), ``start`` /
        ``end`` (the clock before and after the pause), ``pause`` (the seconds it was meant
        to last), ``fps``, ``mode`` and ``input`` (``input_now``).
        """
        if input_now:
            self.touch()
        fps = self.rate(busy, animating)
        start = self.clock()
        pause = 0.0
        if self.last_frame is not None and fps > 0 and not input_now:
            pause = max(0.0, 1.0 / fps - (start - self.last_frame))
            if pause > 0:
                self.sleep(pause)
        now = self.clock()
        if busy and self.last_frame is not None:
            self.max_busy_gap = max(self.max_busy_gap, now - self.last_frame)
        self.last_frame = now
        self.frames += 1
        if self.trace is not None:
            self.trace(
                {
                    "frame": self.frames,
                    "start": start,
                    "end": now,
                    "pause": pause,
                    "fps": fps,
                    "mode": self.mode,
                    "input": input_now,
                }
            )
        return pause
