"""Background jobs of the viewer: long computations off the UI thread (no polyscope, no imgui).

A *job* runs ``work(reporter)`` in a worker thread (numpy, scipy and libigl release the GIL,
so the window keeps drawing) and hands its result to ``apply(result)`` **on the UI thread**, in
:meth:`Jobs.poll`, which the host calls once per frame. Nothing a job computes touches the
state before ``poll``: a cancelled or failed job leaves the previous state exactly as it was
(its ``fail(message)`` says why, on the UI thread too).

The reporter (:class:`Reporter`) is what the core's ``progress=`` arguments expect
(``progress(fraction, message)``); it records the phase, the fraction when known and the time,
and raises :class:`Cancelled` as soon as the job's cancel event is set, so even a core function
without a ``cancel=`` argument stops at its next progress report.

**One job per owner** (a panel's name): starting a job for an owner whose job still runs
cancels the old one (its result is thrown away, never applied) unless ``replace=False``, which
refuses the new one instead (``start`` returns ``None``).

:func:`in_child` runs a job's work in a child process instead (:func:`meshlap_app.ipc.call`;
the load and the curvature fields: scipy's sparse conversions hold the GIL for seconds on a
big mesh, which would stall the window; a child process shares no GIL, and Cancel ends it at
once).

:func:`call_hooked` is the one adapter to the core's ``progress=`` / ``cancel=`` keywords: it
passes each only when the callee accepts it (``inspect.signature``), so the viewer works with
a core that has them and with one that does not.
"""

from __future__ import annotations

import inspect
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from meshlap_core import errors as core_errors

from . import ipc

Cancelled: type[Exception] = getattr(core_errors, "Cancelled", None) or type(
    "Cancelled", (Exception,), {"__doc__": "A job stopped because it was cancelled."}
)
"""The core's :class:`meshlap_core.errors.Cancelled` (or a stand-in when the core has none)."""

RUNNING, DONE, FAILED, CANCELLED = "running", "done", "failed", "cancelled"


class Reporter:
    """The progress reporter a job's ``work`` is given (callable as ``progress(fraction,
    message)``).

    Parameters
    ----------
    cancel : threading.Event
        Set to ask the job to stop.
    clock : callable
        Seconds (monotonic).
    on_report : callable, optional
        Called (from the worker thread) after each report: the host's "something moved".
    on_partial : callable, optional
        Called (from the worker thread) after each partial result: something to show.
    """

    def __init__(
        self,
        cancel: threading.Event,
        clock: Callable[[], float] = time.monotonic,
        on_report: Callable[[], None] | None = None,
        on_partial: Callable[[], None] | None = None,
    ) -> None:
        self.cancel = cancel
        self.clock = clock
        self.on_report = on_report
        self.on_partial = on_partial
        self.phase = "starting"
        self.fraction: float | None = None
        self.reports = 0
        self.at = clock()
        self._partial: list[Any] = []  # the latest partial result not yet shown (0 or 1 item)
        self.last_partial: Any = None  # the latest partial result, shown or not

    def __call__(self, fraction: float | None, message: str = "") -> None:
        """Report a phase (``message``, kept when empty) and a fraction in [0, 1] (``None``:
        unknown); raises :class:`Cancelled` when the job was cancelled."""
        self.check()
        if message:
            self.phase = str(message)
        self.fraction = None if fraction is None else min(max(float(fraction), 0.0), 1.0)
        self.reports += 1
        self.at = self.clock()
        if self.on_report is not None:
            self.on_report()

    def phase_only(self, message: str) -> None:
        """A new phase whose share of the work is unknown (the fraction is kept)."""
        self(self.fraction, message)

    def check(self) -> None:
        """Raise :class:`Cancelled` when the job was cancelled."""
        if self.cancel.is_set():
            raise Cancelled("cancelled")

    def partial(self, value: Any) -> None:
        """Hand a partial result to the UI thread (the job's ``preview``, called in
        :meth:`Jobs.poll` while the job still runs; a newer one replaces one not yet shown)."""
        self.check()
        self.last_partial = value
        self._partial[:] = [value]
        if self.on_report is not None:
            self.on_report()
        if self.on_partial is not None:
            self.on_partial()

    def take_partial(self) -> list[Any]:
        """The partial result waiting to be shown (``[]``: none), forgotten once taken."""
        taken, self._partial = self._partial, []
        return taken


@dataclass
class Job:
    """One background computation: its owner, title, progress and outcome."""

    owner: str
    title: str
    work: Callable[[Reporter], Any]
    apply: Callable[[Any], None]
    fail: Callable[[str], None] | None
    reporter: Reporter
    started: float
    clock: Callable[[], float] = time.monotonic
    preview: Callable[[Any], None] | None = None  # shows a partial result (UI thread)
    status: str = RUNNING  # until Jobs.poll handled it (or it was cancelled)
    outcome: str = RUNNING  # what the worker ended with: done, failed or cancelled
    result: Any = None
    error: str = ""
    finished: float | None = None
    thread: threading.Thread | None = field(default=None, repr=False)

    @property
    def cancel_event(self) -> threading.Event:
        return self.reporter.cancel

    @property
    def running(self) -> bool:
        """Still working (or finished and not yet picked up by :meth:`Jobs.poll`)."""
        return self.status == RUNNING

    def elapsed(self) -> float:
        """Seconds since the job started (until it finished)."""
        end = self.finished if self.finished is not None else self.clock()
        return max(0.0, end - self.started)

    def line(self) -> str:
        """``title: phase, 3.2 s (40 %)``: the progress line (the tenths make it move on every
        frame)."""
        head, tail = self.line_parts()
        return head + tail

    def line_parts(self) -> tuple[str, str]:
        """The progress line as ``("title: phase", ", 3.2 s (40 %)")``: what the job does,
        and what moves (a bar too narrow for both cuts the first at its end)."""
        r = self.reporter
        frac = f" ({100 * r.fraction:.0f} %)" if r.fraction is not None else ""
        phase = f": {r.phase}" if r.phase else ""
        return f"{self.title}{phase}", f", {self.elapsed():.1f} s{frac}"

    def run(self) -> None:
        """The worker's body: ``work(reporter)``, its outcome kept for :meth:`Jobs.poll`."""
        try:
            result = self.work(self.reporter)
            self.reporter.check()  # cancelled at the very end: discarded all the same
        except Cancelled:
            self.outcome = CANCELLED
        except Exception as exc:  # a worker reports, never dies silently
            self.error, self.outcome = ipc.error_message(exc), FAILED
        else:
            self.result, self.outcome = result, DONE
        self.finished = self.clock()
        if self.reporter.on_report is not None:
            self.reporter.on_report()


class Jobs:
    """The viewer's background jobs, at most one per owner; results applied in :meth:`poll`.

    Parameters
    ----------
    clock : callable
        Seconds (monotonic); a test gives its own.
    background : bool
        Run jobs in worker threads (``False``: run in :meth:`start` itself, still applied only
        by :meth:`poll`; headless renders and tests).
    """

    def __init__(self, clock: Callable[[], float] = time.monotonic, background: bool = True):
        self.clock = clock
        self.background = background
        self._jobs: dict[str, Job] = {}  # the current job of each owner
        self._finished: list[Job] = []  # done / failed / cancelled, waiting for poll
        self._lock = threading.Lock()
        self.last_report = clock()  # when a job last reported or finished (the pacer reads it)
        self.cancelled = 0  # jobs cancelled so far (superseded or by the user)
        self.processes = False  # offload() may use child processes (the window sets it)
        self.news = threading.Event()  # a result or a partial result waits for poll()
        # owner -> (title, how it ended, seconds it ran, when): the last job of each owner
        self.ended: dict[str, tuple[str, str, float, float]] = {}
        # also told of news, from the job's thread: the window's wait for events ends on it
        self.wake: Callable[[], None] | None = None

    # ------------------------------------------------------------------ start / cancel
    def start(
        self,
        owner: str,
        title: str,
        work: Callable[[Reporter], Any],
        apply: Callable[[Any], None],
        fail: Callable[[str], None] | None = None,
        replace: bool = True,
        background: bool | None = None,
        preview: Callable[[Any], None] | None = None,
    ) -> Job | None:
        """Start ``work`` for ``owner``; ``apply(result)`` (or ``fail(message)``) runs later in
        :meth:`poll`.

        Returns
        -------
        Job or None
            The new job; ``None`` when ``owner`` has a running job and ``replace`` is false.

        ``background=False`` (default: the ``background`` given to the constructor) runs the
        job right here and applies it at once: the caller is on the UI thread.
        ``preview(value)`` shows each partial result the work hands over
        (:meth:`Reporter.partial`) while the job runs, in :meth:`poll`; a job run right here
        applies its result at once and previews nothing.
        """
        old = self._jobs.get(owner)
        if old is not None and old.running:
            if not replace:
                return None
            self.cancel(owner)
        reporter = Reporter(threading.Event(), self.clock, self._reported, self._news)
        job = Job(owner, title, work, apply, fail, reporter, self.clock(), self.clock, preview)
        self._jobs[owner] = job
        if self.background if background is None else background:
            job.thread = threading.Thread(target=self._run, args=(job,), daemon=True)
            job.thread.start()
        else:
            job.run()
            self._settle(job)
        return job

    def _run(self, job: Job) -> None:
        job.run()
        with self._lock:
            self._finished.append(job)
        self._news()

    def _news(self) -> None:
        """Something waits for :meth:`poll` (any thread): set :attr:`news`, call :attr:`wake`."""
        self.news.set()
        if self.wake is not None:
            self.wake()

    def _reported(self) -> None:
        self.last_report = self.clock()

    def cancel(self, owner: str) -> bool:
        """Ask ``owner``'s running job to stop; it is forgotten at once (its result, if it
        still arrives, is never applied). True when there was one."""
        job = self._jobs.get(owner)
        if job is None or not job.running:
            return False
        job.cancel_event.set()
        job.status = CANCELLED
        self.ended[owner] = (job.title, CANCELLED, job.elapsed(), self.clock())
        self.cancelled += 1
        self._jobs.pop(owner, None)
        return True

    def cancel_all(self) -> None:
        """Cancel every running job (a new mesh makes them all obsolete)."""
        for owner in list(self._jobs):
            self.cancel(owner)

    def offload(self, fn: Callable[..., Any], *args: Any) -> Callable[[Reporter], Any]:
        """A job's ``work`` calling ``fn(*args, progress=reporter)``: in a child process
        (:func:`in_child`) when :attr:`processes` is set, else in the job's thread."""
        if self.processes:
            return in_child(fn, *args)
        return lambda reporter: fn(*args, progress=reporter)

    # ------------------------------------------------------------------ UI thread
    def poll(self) -> list[Job]:
        """Apply the results of the jobs that finished (UI thread, once per frame): ``apply``
        for a result, ``fail`` for an error; a cancelled job changes nothing. Returns the jobs
        handled (a running job's partial result is shown by its ``preview`` after them; it
        does not count as handled)."""
        self.news.clear()
        with self._lock:
            finished, self._finished = self._finished, []
        handled = [job for job in finished if self._settle(job)]
        for job in list(self._jobs.values()):
            if job.running and job.preview is not None and job.outcome == RUNNING:
                for value in job.reporter.take_partial():
                    job.preview(value)
        return handled

    def _settle(self, job: Job) -> bool:
        """Apply a finished job's outcome (UI thread); False when it was superseded or
        cancelled meanwhile (thrown away)."""
        if self._jobs.get(job.owner) is not job:
            return False
        del self._jobs[job.owner]
        job.status = job.outcome
        self.ended[job.owner] = (job.title, job.status, job.elapsed(), self.clock())
        if job.outcome == DONE:
            job.apply(job.result)
        elif job.outcome == FAILED and job.fail is not None:
            job.fail(job.error)
        return True

    def last_outcome(self, *owners: str) -> str:
        """How the last job of ``owners`` ended, as the row it had says it
        (``done: title (1.2 s)``, ``cancelled: title (after 2.0 s)``); ``""`` when none ran."""
        ends = [self.ended[o] for o in owners if o in self.ended]
        if not ends:
            return ""
        title, how, seconds, _ = max(ends, key=lambda e: e[3])
        return f"{how}: {title} ({'after ' if how != DONE else ''}{seconds:.1f} s)"

    def running(self, owner: str | None = None) -> Job | None:
        """``owner``'s running job (any owner's when ``None``), else ``None``."""
        if owner is not None:
            job = self._jobs.get(owner)
            return job if job is not None and job.running else None
        return next((j for j in self._jobs.values() if j.running), None)

    def all_running(self) -> list[Job]:
        """Every job not yet applied, oldest first."""
        return sorted(self._jobs.values(), key=lambda j: j.started)

    @property
    def busy(self) -> bool:
        """A job runs (or waits for :meth:`poll`)."""
        return bool(self._jobs)

    def nap(self, seconds: float) -> None:
        """Sleep up to ``seconds``, woken as soon as a job finishes or hands over a partial
        result (the window's pause between frames: what a job sends is shown on the next
        frame, not a busy frame period later)."""
        self.news.wait(seconds)

    def wait(self, owner: str | None = None, timeout: float | None = None) -> bool:
        """Block until ``owner``'s job (every job when ``None``) finished, then :meth:`poll`
        (tests, headless renders). True when none is left running."""
        deadline = None if timeout is None else time.monotonic() + timeout
        for job in [j for o, j in list(self._jobs.items()) if owner in (None, o)]:
            if job.thread is not None:
                left = None if deadline is None else max(0.0, deadline - time.monotonic())
                job.thread.join(left)
        self.poll()
        return self.running(owner) is None


def prefer_gil_free_solvers() -> bool:
    """Ask the core to keep its eigensolver on a factorization that releases the GIL
    (``meshlap_core.linalg.spd.prefer_gil_free``, where the core has it), so the window keeps
    drawing while an eigenbasis job runs in a thread. True when the core has the switch."""
    try:
        from meshlap_core.linalg import spd
    except ImportError:
        return False
    switch = getattr(spd, "prefer_gil_free", None)
    if switch is None:
        return False
    switch(True)
    return True


def accepts(fn: Callable[..., Any], name: str) -> bool:
    """Whether ``fn`` takes the keyword argument ``name`` (or ``**kwargs``)."""
    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return False
    return name in params or any(p.kind is p.VAR_KEYWORD for p in params.values())


def call_hooked(fn: Callable[..., Any], *args: Any, reporter: Reporter, **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)`` with ``progress=reporter`` and ``cancel=reporter.cancel`` when
    ``fn`` accepts them (the core's hooks: ``load_mesh``, ``SpectralBasis.compute``,
    ``Smoother.run``); without them the job still stops at its next report."""
    if accepts(fn, "progress") and "progress" not in kwargs:
        kwargs["progress"] = reporter
    if accepts(fn, "cancel"):
        kwargs["cancel"] = reporter.cancel
    return fn(*args, **kwargs)


# ---------------------------------------------------------------------- child processes
def warm_up() -> None:
    """Start the fork server of :mod:`.ipc` now, then import matplotlib's colour maps (in a
    thread: the first job then starts at once, and the first coloured frame of a mesh does
    not import them on the UI thread, 0.5-1.5 s)."""

    def start() -> None:
        try:
            ipc.start_server()
        except ipc.NoChildProcess:  # in_child falls back to a thread
            pass
        try:
            from matplotlib import colormaps  # noqa: F401
        except ImportError:  # the panels that use it say so when they draw
            pass

    threading.Thread(target=start, daemon=True).start()


def in_child(fn: Callable[..., Any], *args: Any) -> Callable[[Reporter], Any]:
    """A job's ``work`` that runs ``fn(*args, progress=...)`` in a child process
    (:func:`meshlap_app.ipc.call`: ``fn`` a module-level function, its arguments and result
    picklable). Reports and partial results arrive through a pipe; Cancel ends the child.
    Where no child process can start, ``fn`` runs in the job's thread instead."""

    def work(reporter: Reporter) -> Any:
        try:
            return ipc.call(fn, *args, reporter=reporter)
        except ipc.NoChildProcess:
            return fn(*args, progress=reporter)  # no child process here (or fn not picklable)

    return work
