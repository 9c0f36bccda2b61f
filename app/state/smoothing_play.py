"""Playing a smoothing run in the window: play / pause, one step, one step back (no polyscope).

:class:`SmoothingPlay` is the part of :class:`~.smoothing.SmoothingState` that moves a run
while the window draws, with the stepper in this process or in a child process
(:mod:`meshlap_app.smoother_process`, which runs ahead of the window: *play* asks for batches
of steps, several requests on their way). Three rules a user met on the 692k scan:

- *pause* shows the step that was on screen when it was pressed: the steps the child
  computed after it are thrown away (:meth:`RemoteSmoother.request_rewind`: it goes back to
  its kept positions of that step; before, pause applied four more steps);
- *play* on a run that diverged is refused with a message saying how to go on (before, it
  entered a dead "playing: 0.00 steps/s" state);
- ``←`` (and the *back* button) steps back through the kept positions
  (:class:`~.kept_steps.KeptSteps`: every step of a small mesh, the last 8 on the scan).

The run's ``lam_steps`` (what a saved session replays) always counts the steps of the
positions shown: a step back takes its step off.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError

from .kept_steps import KeptSteps
from .play_meter import PlayMeter

MAX_BATCH = 8
"""Most steps *play* asks a child-process stepper for at once (:meth:`SmoothingPlay.play_batch`)."""


class SmoothingPlay:
    """*play*, *pause*, *step*, *step back* of :class:`~.smoothing.SmoothingState` (a base
    class of it: the attributes below are the state's)."""

    smoother: Any
    playing: bool
    error: str
    last_move: float | None
    show_s: float
    meter: PlayMeter
    view: tuple[float, ...] | None
    lam_steps: list[list[Any]]
    kept: KeptSteps | None  # the in-process stepper's kept positions (a child keeps its own)
    # and the state's step(), _count_steps(lam, count), _stop_diverged()

    # ------------------------------------------------------------------ play / pause
    def toggle_play(self) -> None:
        """*play* / *pause* (the button and ``space``); *play* on a diverged run is refused
        (:attr:`error` says how to go on)."""
        if self.playing:
            self.pause()
            return
        s = self.smoother
        if s is not None and s.diverged:
            self.error = (
                f"the run diverged at iteration {s.iteration + 1}, so play would not move: "
                "lower lambda (or use implicit) to go on from the last good step, step back "
                "(left arrow), or press reset"
            )
            return
        self.playing = True
        self.last_move = None
        self.meter.start(time.perf_counter())

    def pause(self) -> None:
        """Stop *play* on the step shown now: a child-process stepper's steps computed ahead
        of it are thrown away (it goes back to its kept positions of the step shown)."""
        self.playing, self.last_move = False, None
        s = self.smoother
        if self.asynchronous and s.pending:
            s.request_rewind(s.iteration)

    def step_back(self) -> bool:
        """One step back (``←``, the *back* button): the positions of the step before the
        one shown, if they are kept (else :attr:`error` says how far back they go); pauses
        *play* first. A child-process stepper goes back when it answers (:meth:`poll`).

        Returns
        -------
        bool
            Whether a step back was made (or asked for).
        """
        s = self.smoother
        if s is None:
            return False
        if self.playing:
            self.pause()
        target = s.iteration - 1
        if target < 0:
            self.error = "this is the input (iteration 0): there is no step to go back to"
            return False
        if self.asynchronous:
            s.request_rewind(target)
            return True
        assert self.kept is not None
        try:
            self.kept.rewind(s, target)
        except MeshError as exc:
            self.error = str(exc)
            return False
        self._recount()
        return True

    def kept_steps(self) -> tuple[int, int]:
        """``(how many steps are kept for stepping back, the oldest kept iteration)``."""
        s = self.smoother
        if s is None:
            return 0, 0
        if self.asynchronous:
            return int(getattr(s, "kept", 0)), int(getattr(s, "kept_from", 0))
        kept = self.kept
        return (kept.capacity, kept.oldest) if kept is not None else (0, 0)

    # ------------------------------------------------------------------ stepping
    def play_step(self) -> bool:
        """One step of *play*. Beyond the stable ``λ`` (the stability warning is shown), *play*
        stops at the first step that moves the vertices farther (RMS) than the step before (the
        unstable high-frequency modes have taken over: the flow grows from there) and says why;
        that step stays on screen and the run counts as diverged (``smoother.diverged``: a
        smaller ``λ`` goes on from there, as after any divergence).

        With a stepper in a child process (:mod:`meshlap_app.smoother_process`) the step is
        only asked for here (unless one is on its way); :meth:`poll` takes it and checks it.

        Returns
        -------
        bool
            Whether *play* goes on.
        """
        s = self.smoother
        if s is None:
            return False
        if self.asynchronous:
            self.advance(self.play_batch())
            return self.playing
        before = np.array(s.V, dtype=float)
        if not self.step():
            return False
        self.meter.stepped(time.perf_counter(), 1)
        move = float(np.sqrt(np.mean(np.sum((np.asarray(s.V) - before) ** 2, axis=1))))
        return self._check_growth(move)

    def _check_growth(self, move: float) -> bool:
        """*play*'s rule after a step that moved the vertices ``move`` (RMS): go on, or stop
        beyond the stable λ when the move grew (see :meth:`play_step`)."""
        s = self.smoother
        assert s is not None
        stab = s.stability
        if stab.stable or self.last_move is None or move <= self.last_move:
            self.last_move = move
            return True
        limit = "" if stab.max_stable_lam is None else f" {stab.max_stable_lam:.4g}"
        if self.asynchronous and s.pending:  # the steps computed after this one: not shown
            s.request_rewind(s.iteration)
        self.playing, self.last_move = False, None
        s.diverged = True  # a growing step beyond the limit: the run diverges from here on
        self.error = (
            f"play stopped at iteration {s.iteration}: the run diverged (that step moved the "
            f"vertices {move:.3g} RMS, more than the step before) because lam = {s.lam:g} is "
            f"beyond the stable limit{limit}: the highest mode grows "
            f"x{abs(stab.high_freq_gain):.3g} per step and the mesh would blow up. Lower lambda "
            "(or use implicit) to go on, or press reset"
        )
        return False

    @property
    def asynchronous(self) -> bool:
        """The stepper runs in a child process and takes steps asked for ahead
        (:meth:`advance`, :meth:`poll`)."""
        return bool(getattr(self.smoother, "asynchronous", False))

    def play_batch(self) -> int:
        """Steps *play* asks a child-process stepper for at once: as many as it solves while
        the window draws the last ones (:attr:`show_s` over the last step's own time, at most
        :data:`MAX_BATCH`), so neither side waits for the other on a big mesh; 1 when drawing
        is quicker than a step. Never more than the child keeps positions of, shared by the
        requests on their way: *pause* can always go back to the step on screen."""
        s = self.smoother
        last = s.history[-1] if s is not None and s.history else {}
        step_s = float(last.get("time_ms") or 0.0) / 1e3
        if step_s <= 0.0 or self.show_s <= step_s:
            return 1
        count = int(min(MAX_BATCH, round(self.show_s / step_s)))
        kept, depth = int(getattr(s, "kept", 0)), int(getattr(s, "depth", 1))
        if kept:
            count = min(count, max(1, (kept - 1) // max(depth, 1)))
        return count

    def advance(self, count: int = 1) -> None:
        """``count`` steps from the window (the *step* button, ``right``, *play*): asked for
        from a child-process stepper (taken by :meth:`poll`, the window keeps drawing
        meanwhile), else one done at once (:meth:`step`)."""
        s = self.smoother
        if s is None:
            return
        if not self.asynchronous:
            self.step()
        elif not s.diverged:
            try:
                s.request_step(count, self.view)
            except MeshError as exc:
                self.error, self.playing = str(exc), False

    def poll(self) -> bool:
        """Take what a child-process stepper answered, if anything (never waits): count the
        steps (a step back takes them off), stop on divergence, and apply *play*'s rule
        beyond the stable λ. True when the positions changed."""
        s = self.smoother
        if s is None or not self.asynchronous:
            return False
        try:
            arrived = s.poll()
        except MeshError as exc:
            self.error, self.playing = str(exc), False
            return False
        if not arrived:
            return False
        delta = self._recount()
        if delta > 0 and self.playing:
            self.meter.stepped(time.perf_counter(), delta)
        if s.diverged:
            self._stop_diverged()
        elif delta > 0 and self.playing:
            move = s.history[-1].get("step_rms", 0.0) if s.history else 0.0
            self._check_growth(float(move))
        return delta != 0

    def _recount(self) -> int:
        """Make :attr:`lam_steps` count the stepper's iterations: the new steps at its λ, or
        the steps stepped back taken off the end; returns the change."""
        s = self.smoother
        delta = s.iteration - sum(int(n) for _, n in self.lam_steps)
        if delta > 0:
            self._count_steps(s.lam, delta)
        elif delta < 0:
            left = -delta
            while left and self.lam_steps:
                take = min(left, int(self.lam_steps[-1][1]))
                self.lam_steps[-1][1] -= take
                left -= take
                if self.lam_steps[-1][1] == 0:
                    self.lam_steps.pop()
            self.error = ""  # a step back: the run goes on from a good step
        return delta
