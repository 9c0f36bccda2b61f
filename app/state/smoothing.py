"""Smoothing panel state: a :class:`meshlap_core.smoothing.Smoother` stepped live, optional
noise first, live figures and the amplification curve. No polyscope import.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError
from meshlap_core.noise import MAX_SEED, add_noise, check_noise, check_seed
from meshlap_core.options import LAPLACIAN_KINDS, MAX_COORDINATE, SMOOTHING_METHODS
from meshlap_core.smoothing import Smoother, amplification_curve, check_lam
from meshlap_core.types import FloatArray, IntArray

from ..panel_spec import PanelSpec
from .animation import RECORDER_WIDGETS, Animation, Option
from .kept_steps import KeptSteps
from .play_meter import PlayMeter
from .settings import (
    FLOAT_MAX,
    Choice,
    Custom,
    Flag,
    Integer,
    Number,
    Settings,
    number_problem,
    shown,
)
from .smoothing_play import MAX_BATCH as MAX_BATCH  # (where the tests read it)
from .smoothing_play import SmoothingPlay

MAX_FRAMES_ITERS = 5000
"""Most smoothing iterations an animation renders (one frame each), and the most a session may
hold (``smoothing.iterations``): opening a session replays every step before the first frame,
so ``meshlap view --session`` and ``meshlap animate --session`` share this one limit."""
_EMPTY_V = np.zeros((0, 3))
_EMPTY_F = np.zeros((0, 3), dtype=np.int64)


def _lam_steps(x: Any) -> str | None:
    """What is wrong with a ``lam_steps`` value (``null`` or a list of ``[λ > 0, count >= 1]``);
    the counts' sum is checked against ``iterations`` by :func:`check_section`."""
    if x is None:
        return None
    if not isinstance(x, list):
        return f"must be a list of [lam, steps] pairs or null, got {json.dumps(x)}"
    for k, run in enumerate(x):
        if not isinstance(run, list) or len(run) != 2:
            return f"entry {k} must be a [lam, steps] pair, got {json.dumps(run)}"
        problem = number_problem(run[0], 0.0, MAX_LAM, lo_open=True)
        if problem:
            return f"entry {k}: lam {problem}"
        n = run[1]
        if not isinstance(n, int) or isinstance(n, bool):
            return f"entry {k}: steps must be an integer, got {shown(n)}"
        if not 1 <= n <= MAX_FRAMES_ITERS:
            return f"entry {k}: steps must be >= 1 and <= {MAX_FRAMES_ITERS}, got {shown(n)}"
    return None


MAX_LAM = MAX_COORDINATE**2
"""The largest λ: with the cotangent Laplacian λ is in length², coordinates at most 1e75."""
# fmt: off
SETTINGS = Settings(
    Choice("method", "implicit", choices=SMOOTHING_METHODS, label="method",
           tooltip="explicit: x <- x + lam L x;  implicit: (I - lam L) x' = x (backward "
           "Euler);  taubin: lam step, then a negative nu step (no shrinkage)",
           animate=Flag("--method", "the smoothing method")),
    Choice("laplacian", "uniform", choices=LAPLACIAN_KINDS, label="Laplacian",
           tooltip="uniform: L = D^-1 A - I (lam dimensionless);  cotan: L = M^-1 C (lam in "
           "length^2)", animate=Flag("--laplacian", "the Laplacian")),
    Number("lam", 0.5, lo=0.0, lo_open=True, hi=MAX_LAM, widget="input", fmt="%.4g",
           label="lambda", example=0.25, animate=Flag("--lam", "the step λ", default=1.0),
           tooltip="step size lam > 0; type a number and press Enter (keeps the current mesh)"),
    Number("noise_alpha", 0.0, lo=0.0, hi=FLOAT_MAX,  # the mesh bounds it: check_mesh
           slider=(0.0, 0.05), fmt="%.4f", label="noise alpha", example=0.01,
           tooltip="isotropic Gaussian noise: every coordinate of every vertex moves by "
           "N(0, sigma^2), sigma = alpha x the bounding-box diagonal (rebuilds the input)",
           animate=Flag("--noise", "isotropic noise added before smoothing, σ = α × the "
                        "bounding-box diagonal")),
    Integer("seed", 0, lo=0, hi=MAX_SEED, label="noise seed",
            tooltip="seed of the noise (an integer >= 0)",
            animate=Flag("--seed", "the noise seed")),
    Integer("iterations", 0, lo=0, hi=MAX_FRAMES_ITERS, label="step", widget="button",
            tooltip="one iteration",
            quiet=0,  # another panel's animation replays no run
            above="the smoothing ran {x} iterations; an animation has at most "
            f"{MAX_FRAMES_ITERS}, and opening a session replays each one before the first frame"),
    Custom("lam_steps", None, check=_lam_steps, widget="none", added=True, quiet=None,
           example=[[0.5, 1]],
           refused=("0.5", {}, [0.5, 1], [[0, 1]], [[float("nan"), 1]], [[0.5, 1.5]])),
)
# fmt: on
"""The Smoothing panel's settings: a run is ``iterations`` steps, each at its λ of
``lam_steps`` (run-length encoded; missing: every step at ``lam``), from the noisy input."""


@dataclass
class SmoothingState(SmoothingPlay):
    """Options, the stepper built from them, and what the panel shows (*play*, *pause*,
    *step back*: :class:`~.smoothing_play.SmoothingPlay`).

    ``lam_steps`` is the ``λ`` of every step the stepper has taken since it was built or reset,
    run-length encoded: ``[[0.5, 10], [2.0, 5]]`` is 10 steps at 0.5, then 5 at 2.0. Only ``λ``
    can change during a run (:meth:`set_lam`); a new method, Laplacian, noise α or seed rebuilds
    the stepper (:meth:`configure`) and starts a new run at iteration 0. A saved session
    replays these runs (:func:`meshlap_app.session.apply`), so a run whose ``λ`` was changed
    mid-way comes back bit for bit.
    """

    method: str = SETTINGS.default("method")
    laplacian: str = SETTINGS.default("laplacian")
    lam: float = SETTINGS.default("lam")
    noise_alpha: float = SETTINGS.default("noise_alpha")
    seed: int = SETTINGS.default("seed")
    playing: bool = False
    error: str = ""
    smoother: Smoother | None = None
    version: int = 0  # bumped when the stepper is rebuilt (connectivity may need re-upload)
    lam_steps: list[list[Any]] = field(default_factory=list)  # [[λ, steps], ...] of this run
    last_move: float | None = None  # RMS displacement of the last step *play* took
    show_s: float = 0.0  # how long the window's last frame showing a new step took
    meter: PlayMeter = field(default_factory=PlayMeter)  # steps/s and frames/s of play
    view: tuple[float, ...] | None = None  # the window's display transform, for the child
    kept: KeptSteps | None = None  # the last steps' positions (an in-process stepper's)

    def drop(self) -> None:
        """Forget the stepper (a new mesh); a child process's ends."""
        old, self.smoother, self.playing = self.smoother, None, False
        if hasattr(old, "close"):
            old.close()

    def rebuild(self, V: FloatArray, F: IntArray, build: Any = None) -> bool:
        """Build the stepper for the current options from the clean mesh ``V`` (+ noise).

        ``V`` and ``F`` are passed on once: the smoother keeps its own validated copies
        (``V0``, ``F``, ``reference``) and this state reads them from there. ``build``: how
        (``build(V, F, options)``; default :meth:`build`, in this process).
        """
        try:
            smoother = (build or self.build)(V, F, self.options())
        except MeshError as exc:
            self.error = str(exc)
            self.playing = False
            return False
        self.adopt(smoother)
        return True

    def options(self) -> tuple[str, str, float, float, int]:
        """``(method, laplacian, lam, noise_alpha, seed)``: what a stepper is built from."""
        return (self.method, self.laplacian, self.lam, self.noise_alpha, self.seed)

    @staticmethod
    def build(
        V: FloatArray,
        F: IntArray,
        options: tuple[str, str, float, float, int],
        progress: Any = None,
    ) -> Smoother:
        """A stepper for ``options`` (:meth:`options`), any thread (touches no state): the
        noise, the operators, the implicit factorization and the stability estimate.
        ``progress``: a job's reporter, told each phase."""
        method, laplacian, lam, alpha, seed = options
        if progress is not None:
            progress.phase_only("adding noise" if alpha else "operators")
        start = add_noise(V, F, alpha, seed=seed) if alpha else V
        if progress is not None:
            what = "factorizing the implicit system" if method == "implicit" else "operators"
            progress.phase_only(f"{what} and the stable lambda ({len(V):,} vertices)")
        smoother = Smoother(
            start,
            F,
            method,
            laplacian,
            lam,
            reference=V,
            warn=False,
            history_limit=1000,  # the panel reads only the last entry; playing never grows
        )
        smoother.prepare()  # the factorization here, not in the first step on the UI thread
        smoother.stability  # noqa: B018 -- its eigensolve here, not in the panel's first draw
        return smoother

    def adopt(self, smoother: Smoother) -> None:
        """Step ``smoother`` from now on (built by :meth:`build`, maybe in a job, maybe in a
        child process); the one it replaces is closed (its child process ends)."""
        old, self.smoother = self.smoother, smoother
        if old is not smoother and hasattr(old, "close"):
            old.close()
        # a child-process stepper keeps its own (in the child, where the positions are)
        asynchronous = getattr(smoother, "asynchronous", False)
        self.kept = None if asynchronous else KeptSteps(len(smoother.V0))
        self.error = ""
        self.version += 1
        self.lam_steps = []

    def plan(
        self,
        *,
        method: str | None = None,
        laplacian: str | None = None,
        noise_alpha: float | None = None,
        seed: int | None = None,
    ) -> tuple[str, str, float, float, int]:
        """The options with these changes, checked (nothing changes here).

        Raises
        ------
        MeshError
            A bad seed (named); the method, Laplacian and α are checked by the build.
        """
        if seed is not None and not (isinstance(seed, int) and seed >= 0):
            raise MeshError(f"must be an integer >= 0, got {seed!r}", "noise seed")
        m, lap, lam, alpha, sd = self.options()
        return (
            m if method is None else method,
            lap if laplacian is None else laplacian,
            lam,
            alpha if noise_alpha is None else float(noise_alpha),
            sd if seed is None else seed,
        )

    def adopt_built(self, options: tuple[str, str, float, float, int], smoother: Smoother) -> None:
        """Take the options a job built ``smoother`` from, and the stepper (UI thread)."""
        self.method, self.laplacian, _, self.noise_alpha, self.seed = options
        self.playing = False
        if smoother.lam != self.lam:  # lambda typed while it was being built
            smoother.set_lam(self.lam)
        self.adopt(smoother)

    def set_lam(self, lam: float) -> None:
        """Change ``λ`` keeping the current positions, noise and iteration count
        (:meth:`Smoother.set_lam`: the implicit system is refactorized, nothing else).

        Raises
        ------
        MeshError
            ``λ`` is not a finite number > 0 (the state keeps the previous ``λ``).
        """
        lam = check_lam(lam, "lambda")
        if self.asynchronous:  # steps on their way were taken at the old λ: counted first
            self.smoother.finish()  # type: ignore[union-attr]
            self.poll()
        if self.smoother is not None:
            self.smoother.set_lam(lam)
        self.lam = lam
        self.error = ""

    def configure(
        self,
        V: FloatArray,
        F: IntArray,
        *,
        method: str | None = None,
        laplacian: str | None = None,
        noise_alpha: float | None = None,
        seed: int | None = None,
    ) -> None:
        """Rebuild the stepper with new options; on bad options nothing changes.

        Raises
        ------
        MeshError
            A bad option (named), e.g. a negative noise α or seed, a seed beyond
            ``noise.MAX_SEED`` or an α whose noise would overflow the coordinates
            (:func:`meshlap_core.noise.check_seed`, :func:`~meshlap_core.noise.check_noise`);
            the previous options and stepper stay.
        """
        if seed is not None:
            seed = check_seed(seed, "noise seed")  # what the field and a session can hold
        if noise_alpha is not None:
            check_noise(V, noise_alpha, "noise alpha")  # finite noisy coordinates
        old = (self.method, self.laplacian, self.noise_alpha, self.seed)
        if method is not None:
            self.method = method
        if laplacian is not None:
            self.laplacian = laplacian
        if noise_alpha is not None:
            self.noise_alpha = float(noise_alpha)
        if seed is not None:
            self.seed = seed
        if not self.rebuild(V, F):
            message = self.error
            self.method, self.laplacian, self.noise_alpha, self.seed = old
            self.error = ""
            raise MeshError(message)

    @property
    def V_original(self) -> FloatArray:
        """The clean mesh the smoother measures its RMSE against ``(n,3)``."""
        s = self.smoother
        return s.reference if s is not None and s.reference is not None else _EMPTY_V

    @property
    def V_start(self) -> FloatArray:
        """The smoother's input: the clean mesh plus the noise ``(n,3)``."""
        return self.smoother.V0 if self.smoother is not None else _EMPTY_V

    @property
    def F(self) -> IntArray:
        """Faces of the smoothed mesh ``(m,3)``."""
        return self.smoother.F if self.smoother is not None else _EMPTY_F

    def step(self) -> bool:
        """One iteration; stops (and says why, with the stable λ) when the flow diverges.

        Divergence is the smoother's own rule (:meth:`Smoother.divergence_message`): an explicit
        step that moves the vertices farther (RMS) than the bounding-box diagonal from the
        input, or any step that blows up, is discarded, so the last good mesh stays on screen.
        """
        s = self.smoother
        if s is None:
            return False
        if not s.diverged:
            done = s.iteration
            s.step()
            self._count_steps(s.lam, s.iteration - done)  # a diverging step is discarded
            if self.kept is not None and s.iteration > done:
                self.kept.record(s.iteration, s.V)
        if s.diverged:
            self._stop_diverged()
            return False
        return True

    def run(self, count: int) -> bool:
        """``count`` steps at once (a saved session's replay), stopping where the flow
        diverges (:meth:`step`); a child-process stepper takes them in one request.

        Returns
        -------
        bool
            False when the run stopped (diverged).
        """
        s = self.smoother
        if s is None:
            return False
        many = getattr(s, "steps", None)
        if many is None or s.diverged:
            return all(self.step() for _ in range(count))
        done = s.iteration
        many(count)
        self._count_steps(s.lam, s.iteration - done)
        if s.diverged:
            self._stop_diverged()
            return False
        return True

    def _count_steps(self, lam: float, count: int) -> None:
        """Add ``count`` steps at ``lam`` to :attr:`lam_steps` (none when ``count`` is 0)."""
        if count <= 0:
            return
        if self.lam_steps and self.lam_steps[-1][0] == lam:
            self.lam_steps[-1][1] += count
        else:
            self.lam_steps.append([lam, count])

    def _stop_diverged(self) -> None:
        """The stepper diverged: *play* stops and the panel says why."""
        s = self.smoother
        assert s is not None
        self.playing = False
        self.error = f"{s.divergence_message()}; press reset"

    def reset(self) -> None:
        """Back to the noisy input (the noise itself stays)."""
        if self.smoother is not None:
            self.smoother.reset()
        if self.kept is not None:
            self.kept.clear()
        self.lam_steps = []
        self.playing = False
        self.error = ""

    @property
    def V(self) -> FloatArray:
        return self.smoother.V if self.smoother is not None else self.V_original

    def figures(self) -> dict[str, Any]:
        """Iteration, volume change (or why it is undefined), RMSE against the original, and
        the solver line (which factorization answers the implicit steps, and why)."""
        s = self.smoother
        if s is None:
            return {}
        last = s.history[-1] if s.history else {}
        return {
            "iteration": s.iteration,
            "volume_change_pct": last.get("volume_change_pct"),
            "volume_note": s.volume_note,
            "rmse": last.get("rmse"),
            "warning": s.stability.message(),
            "stable_limit": s.stability.max_stable_lam,
            "solver": s.solver_line() if s.method == "implicit" else None,
        }

    def amplification(self, n: int = 200) -> tuple[FloatArray, FloatArray]:
        """``g(μ)`` over ``μ ∈ [μ_min, 0]`` of this mesh's Laplacian for the current λ."""
        s = self.smoother
        if s is None:
            mu = np.linspace(-2.0, 0.0, n)
            return mu, amplification_curve(self.method, self.lam, mu)
        mu = np.linspace(s.stability.mu_min, 0.0, n)
        return mu, amplification_curve(self.method, self.lam, mu, k_pb=s.k_pb)


def caption(st: SmoothingState, iters: int | None = None) -> str:
    """``implicit (uniform L), λ = 1   iteration 3/30   RMSE 0.0012`` for a smoothing state
    (read from the stepper's history: never the lazy stability estimate, an eigensolve); the
    caption of ``meshlap animate``'s frames and of the window's recording."""
    s = st.smoother
    last = s.history[-1] if s is not None and s.history else {}
    rmse = last.get("rmse")
    it = s.iteration if s is not None else 0
    of = f"/{iters}" if iters is not None else ""
    noise = f", noise α = {st.noise_alpha:g}" if st.noise_alpha else ""
    return f"{st.method} ({st.laplacian} L), λ = {st.lam:g}{noise}   iteration {it}{of}" + (
        f"   RMSE {rmse:.4g}" if rmse is not None else ""
    )


# ---------------------------------------------------------------- saved sessions
def check_section(sm: dict[str, Any], source: Any) -> None:
    """Check that ``lam_steps`` counts ``iterations`` steps; λ as floats, counts as ints.

    Raises
    ------
    MeshError
        The counts do not sum to ``iterations``.
    """
    runs = sm["lam_steps"]
    if runs is None:
        return
    total = sum(int(n) for _, n in runs)
    if total != sm["iterations"]:
        raise MeshError(
            f'"smoothing.lam_steps" counts {total} steps but "smoothing.iterations" is '
            f"{sm['iterations']}",
            source,
        )
    sm["lam_steps"] = [[float(lam), int(n)] for lam, n in runs]


def check_mesh(sm: dict[str, Any], mesh: Any, source: Any) -> None:
    """Refuse a saved noise α whose noise would push this mesh's coordinates past the
    coordinate limit (:func:`meshlap_core.noise.check_noise`); without it, 1e308 passes the
    section's check and the noisy mesh is then blamed ("vertex 0 has a NaN ...").

    Raises
    ------
    MeshError
        Naming ``"smoothing.noise_alpha"`` and the largest usable α.
    """
    if sm["noise_alpha"]:
        try:
            check_noise(mesh.V, sm["noise_alpha"], '"smoothing.noise_alpha"')
        except MeshError as exc:
            raise MeshError(f"{exc.source}: {exc.problem}", source) from None


def encode_lam_steps(runs: list[list[Any]], lam: float) -> list[list[Any]] | None:
    """``lam_steps`` to save for a run of ``runs`` (``[[λ, steps], ...]``) with ``lam`` set
    now: ``None`` when it says nothing that ``lam`` and ``iterations`` do not (no step, or every
    step at ``lam``), else a copy of ``runs``."""
    if not runs or (len(runs) == 1 and runs[0][0] == lam):
        return None
    return [[float(x), int(n)] for x, n in runs]


def replay_steps(sm: dict[str, Any]) -> list[list[Any]]:
    """The runs ``[[λ, steps], ...]`` that reproduce a saved ``smoothing`` section: its
    ``lam_steps``, or (missing, as in older files) ``iterations`` steps at ``lam``."""
    if sm.get("lam_steps") is not None:
        return [[float(x), int(n)] for x, n in sm["lam_steps"]]
    return [[float(sm["lam"]), int(sm["iterations"])]] if sm["iterations"] else []


# ---------------------------------------------------------------- meshlap animate
def _animation_from_session(opts: dict[str, Any], sm: dict[str, Any], source: Any) -> None:
    """From the saved section (the settings' flags take method, Laplacian, λ, noise and seed
    after this): the λ of every saved step unless ``--lam`` is typed, and the iterations (the
    last frame is then the saved view; 0: the built-in default)."""
    opts["lam_steps"] = sm.get("lam_steps") if opts.get("lam") is None else None
    if opts.get("iters") is None:
        opts["iters"] = sm["iterations"] or None


def _animation_check(opts: dict[str, Any]) -> None:
    if not 0 <= opts["iters"] <= MAX_FRAMES_ITERS:
        raise MeshError(f"must be 0 to {MAX_FRAMES_ITERS}, got {opts['iters']}", "--iters")


def _animation_check_mesh(opts: dict[str, Any], mesh: Any) -> None:
    if opts["noise"]:
        check_noise(mesh.V, opts["noise"], "--noise")  # before the renderer: it names --noise


ANIMATION = Animation(
    summary="smoothing: one frame per iteration, the input beside the smoothed copy",
    options=(Option("--iters", "smoothing iterations (frames: iters+1; default 30)", 30, int),),
    session_help=(
        "smoothing  method, laplacian, lambda, noise alpha and seed from the session; --iters\n"
        "           defaults to the session's iteration count when it is > 0 (else 30): the\n"
        "           frames are iterations 0..iters, so the last frame is the saved view"
    ),
    check=_animation_check,
    kind=lambda opts: "smoothing",
    fps={"smoothing": 10.0},
    frame_count=lambda opts: int(opts["iters"]) + 1,
    from_session=_animation_from_session,
    check_mesh=_animation_check_mesh,
    session_overrides={"iterations": 0},  # the frames run the smoothing from iteration 0
    colorbar=False,  # no colour map: the input and its smoothed copy
)
"""``meshlap animate --panel smoothing``."""


SPEC = PanelSpec(
    name="smoothing",
    title="Smoothing",
    summary="explicit, implicit or Taubin smoothing stepped live from a (noisy) input, with its "
    "stability limit and amplification curve",
    panel="SmoothingPanel",
    state=SmoothingState,
    settings=SETTINGS,
    check_section=check_section,
    check_mesh=check_mesh,
    animation=ANIMATION,
    unsaved={
        "play": "an action: steps on each frame (the steps are kept as iterations, lam_steps)",
        "pause": "an action: stops playing (the steps made are kept)",
        "reset": "an action: back to the input (iterations 0)",
        "back": "an action: one step back through the kept positions (iterations − 1)",
        **RECORDER_WIDGETS,
    },
)
"""The Smoothing panel."""
