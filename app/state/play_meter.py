"""*play*'s two rates, counted apart: steps computed per second and frames showing a step per
second (:class:`PlayMeter`, the smoothing panel's; no polyscope import)."""

from __future__ import annotations

from dataclasses import dataclass, field

METER_WINDOW_S = 5.0
"""The span over which :class:`PlayMeter` counts (the last seconds of *play*)."""


@dataclass
class PlayMeter:
    """Two rates of *play*, counted apart: the steps the stepper computed per second and the
    frames that showed a new step per second. With a stepper in a child process the two
    differ: the child runs ahead (several steps per request) while the window draws, and a
    frame shows the newest step that is done.

    Events older than :data:`METER_WINDOW_S` before the latest are forgotten; a rate is the
    events of that span over the span since the first of them (or since *play* started)."""

    started: float | None = None
    stopped: float | None = None  # when *play* paused: the rates stay as they were then
    steps: list[tuple[float, int]] = field(default_factory=list)
    frames: list[float] = field(default_factory=list)

    def start(self, now: float) -> None:
        self.started, self.stopped, self.steps, self.frames = now, None, [], []

    def stop(self, now: float) -> None:
        if self.started is not None and self.stopped is None:
            self.stopped = now

    def stepped(self, now: float, count: int) -> None:
        if self.started is not None:
            self.steps.append((now, count))
            self._trim(now)

    def shown(self, now: float) -> None:
        if self.started is not None:
            self.frames.append(now)
            self._trim(now)

    def _trim(self, now: float) -> None:
        cut = now - METER_WINDOW_S
        self.steps = [e for e in self.steps if e[0] >= cut]
        self.frames = [t for t in self.frames if t >= cut]

    def rates(self, now: float) -> tuple[float, float]:
        """``(steps computed per second, frames showing a step per second)`` (0 before
        *play*)."""
        if self.started is None:
            return 0.0, 0.0
        if self.stopped is not None:
            now = self.stopped
        span = now - max(self.started, now - METER_WINDOW_S)
        if span <= 0:
            return 0.0, 0.0
        steps = sum(n for t, n in self.steps if t >= now - METER_WINDOW_S)
        frames = sum(1 for t in self.frames if t >= now - METER_WINDOW_S)
        return steps / span, frames / span
