"""Spectral panel state: the eigenbasis (computed in a worker thread), the eigenmode browser and
the k slider. No polyscope import.

The basis is computed once per mesh (and cached on disk by ``meshlap_core.spectral``); the
k slider then only calls :meth:`SpectralBasis.reconstruct`, which updates incrementally from
the previous k.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError
from meshlap_core.io.animation import parse_range
from meshlap_core.spectral import SpectralBasis
from meshlap_core.types import FloatArray, IntArray

from ..panel_spec import PanelSpec
from .animation import RECORDER_WIDGETS, Animation, Option
from .isolines import isoline_fields
from .settings import MAX_INT, Choice, Flag, Integer, Settings, Toggle

PLAY_KINDS: tuple[str, ...] = ("k sweep", "modes")
"""What the Spectral panel plays: k = 1, 2, ... (one per frame) or the eigenmodes 1, 2, ..."""

SCREENSHOT_K = 30
"""k of ``meshlap view --panel spectral --screenshot`` without ``--k``."""


MODES_PER_SECOND = 1.5
"""Pace of the eigenmodes played on screen (a mode must be readable); the k sweep is one k
per frame."""

# fmt: off
SETTINGS = Settings(
    Toggle("computed", False, label="compute eigenbasis", widget="button",
           tooltip="solve for the modes in the background (progress, Cancel)",
           quiet=False),  # another panel's animation reads no basis
    Integer("k_request", 100, lo=2, hi=MAX_INT, label="modes to compute",
            tooltip="number of eigenpairs of -C u = lambda M u to compute; Enter applies"),
    Integer("k", 10, lo=1, hi=MAX_INT, label="k (reconstruct)", widget="slider",
            tooltip="x_k = sum_{i<k} u_i (u_i^T M x): the shape from its first k modes",
            view=Flag("--k", "reconstruct from k eigenvectors (computed at start)")),
    Integer("mode", 1, lo=0, hi=MAX_INT, label="eigenmode i", widget="slider",
            tooltip="eigenfunction u_i shown as a colour map (i = 0 is constant)"),
    Choice("play", "k sweep", choices=PLAY_KINDS, label="play what", added=True,
           tooltip="k sweep: k = 1, 2, ... one per frame (as meshlap animate --k); modes: the "
           "eigenmodes 1, 2, ... at 1.5 per second (as --modes); playing stops at the end"),
    isoline_fields(("eigenfunction", "error"), labels=(
        "isolines (mode)", "isoline count (mode)", "isolines (error)", "isoline count (error)",
    )),
)
# fmt: on
"""The Spectral panel's settings (the basis, k and mode are bounded by the mesh where they
are applied: the requested modes clamped to the vertices, k and mode to the basis)."""


def _finish_basis(basis: SpectralBasis, k: int, progress: Any) -> tuple[SpectralBasis, Any]:
    """The errors for every k and the slider's checkpoints of a new basis (off the UI
    thread); ``(basis, errors)``."""
    if progress is not None:
        progress.phase_only("reconstruction errors for every k")
    errors = basis.errors()  # every k at once (cumulative sums)
    basis.reconstruct(max(1, k // 2))  # builds the slider's checkpoints
    return basis, errors


def solve_basis(V: FloatArray, F: IntArray, k: int, progress: Any = None) -> tuple[Any, ...]:
    """The eigenbasis job's work in a child process (:func:`meshlap_app.jobs.in_child`, which
    ends the process on Cancel): ``k`` eigenpairs, the errors for every k and the slider's
    checkpoints, as ``(basis, errors)``. Module level, so it pickles; the eigenvectors (550 MB
    at 692k vertices, k = 100) reach the window mapped from shared memory, not unpickled
    (:func:`meshlap_app.ipc.pack`)."""
    basis = SpectralBasis.compute(V, F, k, progress=progress)
    return _finish_basis(basis, k, progress)


@dataclass
class SpectralState:
    """Basis, selected eigenmode ``mode`` and reconstruction order ``k``."""

    k_request: int = SETTINGS.default("k_request")
    mode: int = SETTINGS.default("mode")
    k: int = SETTINGS.default("k")
    progress: float = 0.0
    message: str = ""
    error: str = ""
    basis: SpectralBasis | None = None
    errors: Any = None  # ReconstructionErrors for every k of the basis
    reconstruction: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    vertex_error: FloatArray = field(default_factory=lambda: np.zeros(0))
    _job: Any = None  # the running job (meshlap_app.jobs.Job) computing the basis
    _jobs: Any = None  # the Jobs it runs in (the app's, or a private one)
    _fresh: bool = False  # a basis arrived that poll() has not reported yet
    play_what: str = SETTINGS.default("play")  # one of PLAY_KINDS
    playing: bool = False
    clock: Callable[[], float] = time.monotonic  # seconds (a test gives its own)
    _due: float = 0.0  # when the next mode is due
    _paused: bool = False  # paused mid-way: play resumes instead of starting over

    @property
    def busy(self) -> bool:
        """The eigenbasis job runs (or its result waits for the host's poll)."""
        return self._job is not None and self._job.running

    def clear(self) -> None:
        """Forget the basis (a new mesh was loaded); a running job is cancelled."""
        self.cancel()
        self.basis, self.errors, self._fresh = None, None, False
        self.playing = self._paused = False
        self.reconstruction = np.zeros((0, 3))
        self.vertex_error = np.zeros(0)
        self.progress, self.message, self.error = 0.0, "", ""

    def _progress(self, fraction: float, message: str) -> None:
        self.progress, self.message = float(fraction), message

    def solve(self, V: FloatArray, F: IntArray, k: int, progress: Any = None) -> tuple[Any, Any]:
        """The job's work (any thread): ``k`` eigenpairs, the errors for every k and the
        slider's checkpoints; touches no state. ``progress``: a job's reporter (progress and
        cancel handed to the core where it takes them)."""
        from ..jobs import call_hooked

        if progress is not None:
            basis = call_hooked(SpectralBasis.compute, V, F, k, reporter=progress)
        else:
            basis = SpectralBasis.compute(V, F, k, progress=self._progress)
        return _finish_basis(basis, k, progress)

    def _failed(self, message: str) -> None:
        self.error, self.message = message, ""

    def start(
        self,
        V: FloatArray,
        F: IntArray,
        background: bool = True,
        jobs: Any = None,
        owner: str = "eigenbasis",
    ) -> None:
        """Compute ``k_request`` eigenpairs (at most n) as a job of ``jobs`` (a private
        :class:`~meshlap_app.jobs.Jobs` when ``None``), or right here (``background=False``).
        The basis is adopted on the UI thread (:meth:`poll`, or the host's ``jobs.poll()``)."""
        from ..jobs import Jobs

        if self.busy:
            return
        self.clear()
        k = int(min(max(self.k_request, 2), len(V)))
        self.message = f"computing {k} eigenpairs ..."
        if jobs is None:
            jobs = self._jobs if self._jobs is not None else Jobs()
        self._jobs = jobs
        if getattr(jobs, "processes", False):
            # (the window: a child process, where the eigensolver may use CHOLMOD, which
            # holds the GIL, with METIS ordering; in a thread it would freeze the frames, so
            # there it keeps to QDLDL: 147 s instead of about 60 s at 692k vertices)
            from ..jobs import in_child

            work = in_child(solve_basis, V, F, k)
        else:
            work = lambda reporter: self.solve(V, F, k, reporter)  # noqa: E731
        self._job = jobs.start(
            owner,
            f"eigenbasis ({k} modes)",
            work,
            self._adopt,
            self._failed,
            background=background,
        )

    def cancel(self) -> bool:
        """Stop the running eigenbasis job (the basis on screen, if any, stays)."""
        job, self._job = self._job, None
        if job is None or not job.running or self._jobs is None:
            return False
        self.message = "eigenbasis cancelled"
        return bool(self._jobs.cancel(job.owner))

    def poll(self) -> bool:
        """Adopt a basis finished by the job; True (once) when a new one arrived (UI
        thread)."""
        if self._jobs is not None and self.busy:
            self._jobs.poll()
        fresh, self._fresh = self._fresh, False
        return fresh

    def _adopt(self, result: tuple[Any, ...]) -> None:
        basis, self.errors = result
        self._job = None
        self.basis = basis
        self._fresh = True
        self.k = min(self.k, basis.k_max)
        self.mode = min(max(self.mode, 0), basis.k_max - 1)
        info = basis.info
        total = info.timings.get("total", info.timings.get("eigensolve", 0.0))
        how = "from the cache" if info.from_cache else f"in {total:.2f} s"
        self.message = f"{basis.k_max} eigenpairs {how}"
        self.set_k(self.k)

    def eigenfunction(self) -> tuple[FloatArray, float]:
        """The selected eigenfunction (a scalar field) and its frequency λ ≥ 0."""
        if self.basis is None:
            raise MeshError("no eigenbasis computed yet", "spectral")
        return self.basis.eigenfunction(self.mode), float(self.basis.eigenvalues[self.mode])

    def set_k_request(self, k: int, n: int) -> None:
        """How many eigenpairs the next computation asks for, clamped to ``[2, n]``."""
        self.k_request = int(np.clip(int(k), 2, max(n, 2)))

    def set_mode(self, mode: int) -> None:
        """Select eigenmode ``mode`` (clamped to the basis)."""
        top = self.basis.k_max - 1 if self.basis is not None else 0
        self.mode = int(np.clip(int(mode), 0, top))

    def set_k(self, k: int) -> None:
        """Rebuild the shape from the first ``k`` eigenvectors (incremental, O(n·|Δk|))."""
        if self.basis is None:
            return
        self.k = int(np.clip(k, 1, self.basis.k_max))
        self.reconstruction = self.basis.reconstruct(self.k)
        self.vertex_error = np.linalg.norm(self.reconstruction - self.basis.V, axis=1)

    # ------------------------------------------------------------------ captions (CLI and record)
    def k_caption(self, k: int | None = None) -> str:
        """``k = 12 modes   mean error 0.0123 (1.2% of the diagonal)   max 0.05``: the caption of
        a k-sweep frame (``meshlap animate --k`` and the viewer's recording)."""
        e = self.errors
        k = self.k if k is None else int(k)
        return (
            f"k = {k} modes   mean error {e.mean[k]:.3g} "
            f"({100 * e.relative_mean[k]:.3g}% of the diagonal)   max {e.max[k]:.3g}"
        )

    def mode_caption(self, mode: int | None = None) -> str:
        """``eigenmode u_3   λ_3 = 7.21   (-C u = λ M u)``: the caption of an eigenmode frame."""
        if self.basis is None:
            raise MeshError("no eigenbasis computed yet", "spectral")
        m = self.mode if mode is None else int(mode)
        lam = float(self.basis.eigenvalues[m])
        return f"eigenmode u_{m}   λ_{m} = {lam:.5g}   (-C u = λ M u)"

    # ------------------------------------------------------------------ play
    def set_play_what(self, what: str) -> None:
        """Choose what *play* plays (stops a sweep that is playing).

        Raises
        ------
        MeshError
            ``what`` is not one of :data:`PLAY_KINDS`.
        """
        if what not in PLAY_KINDS:
            raise MeshError(f"{what!r} is not one of {', '.join(PLAY_KINDS)}", "play")
        if what != self.play_what:
            self.play_what, self.playing, self._paused = what, False, False

    def _at_end(self) -> bool:
        top = self.basis.k_max if self.basis is not None else 0
        return self.k >= top if self.play_what == "k sweep" else self.mode >= top - 1

    def toggle_play(self) -> bool:
        """*play* / *pause*: play starts from k = 1 (or mode 1), or resumes where a pause left
        it; it stops by itself at the last k (or mode). True when a play started over.

        Raises
        ------
        MeshError
            No eigenbasis yet.
        """
        if self.playing:
            self.playing, self._paused = False, True
            return False
        if self.basis is None:
            raise MeshError("compute the eigenbasis first", "play")
        over = not self._paused or self._at_end()
        if over and self.play_what == "k sweep":
            self.set_k(1)
        elif over:
            self.set_mode(min(1, self.basis.k_max - 1))
        self.playing, self._paused = True, False
        self._due = self.clock() + self.play_interval
        return over

    @property
    def play_interval(self) -> float:
        """Seconds between two steps of what plays (0: one per frame)."""
        return 1.0 / MODES_PER_SECOND if self.play_what == "modes" else 0.0

    def tick(self) -> bool:
        """Advance what plays when its next step is due (called every frame); True when k or
        the mode changed. Playing stops at the end."""
        if not self.playing:
            return False
        if self.basis is None or self._at_end():
            self.playing = False
            return False
        now = self.clock()
        if now < self._due:
            return False
        self._due = now + self.play_interval
        if self.play_what == "k sweep":
            self.set_k(self.k + 1)
        else:
            self.set_mode(self.mode + 1)
        if self._at_end():
            self.playing = False
        return True


# ---------------------------------------------------------------- meshlap animate
def _animation_from_session(opts: dict[str, Any], sp: dict[str, Any], source: Any) -> None:
    """Without ``--k``/``--modes``: the k sweep up to the session's k."""
    if opts.get("k") is None and opts.get("modes") is None:
        opts["k"] = f"1:{sp['k']}"


def _animation_check(opts: dict[str, Any]) -> None:
    if (opts.get("k") is None) == (opts.get("modes") is None):
        raise MeshError("give exactly one of --k A:B (reconstruction) or --modes A:B", "--panel")
    if isinstance(opts.get("k"), str):
        opts["k"] = parse_range(opts["k"], "--k", lo=1)
    if isinstance(opts.get("modes"), str):
        opts["modes"] = parse_range(opts["modes"], "--modes", lo=0)


def _animation_check_mesh(opts: dict[str, Any], mesh: Any) -> None:
    n = len(mesh.V)
    if opts.get("k") is not None and opts["k"][1] > n:
        raise MeshError(f"must end at {n} or less (the mesh has {n} vertices)", "--k")
    if opts.get("modes") is not None and opts["modes"][1] > n - 1:
        raise MeshError(f"must end at {n - 1} or less (the mesh has {n} vertices)", "--modes")


def _frames(opts: dict[str, Any]) -> int:
    a, b = opts["k"] if opts.get("k") is not None else opts["modes"]
    return b - a + 1


ANIMATION = Animation(
    summary="the spectral k sweep (--k A:B) or the eigenmodes one by one (--modes A:B)",
    options=(
        Option("--k", "spectral: reconstruct from k = A..B modes", metavar="A:B"),
        Option("--modes", "spectral: show eigenmodes A..B one by one", metavar="A:B"),
    ),
    session_help=(
        "spectral   without --k/--modes: the k sweep 1:k up to the session's k (also when the\n"
        "           session showed an eigenmode: the modes are animated only with --modes); the\n"
        "           basis comes from the cache as in `meshlap view --session`"
    ),
    check=_animation_check,
    kind=lambda opts: "modes" if opts.get("modes") is not None else "k",
    fps={"k": 15.0, "modes": MODES_PER_SECOND},
    frame_count=_frames,
    from_session=_animation_from_session,
    check_mesh=_animation_check_mesh,
)
"""``meshlap animate --panel spectral``."""


SPEC = PanelSpec(
    name="spectral",
    title="Spectral",
    summary="the eigenbasis of -C u = lambda M u, an eigenmode browser and the shape rebuilt "
    "from its first k modes",
    panel="SpectralPanel",
    state=SpectralState,
    settings=SETTINGS,
    animation=ANIMATION,
    unsaved={
        "play": "an action: plays what 'play what' says (declared: play)",
        "pause": "an action: stops at the k or mode shown (declared: k, mode)",
        **RECORDER_WIDGETS,
    },
)
"""The Spectral panel."""
