"""Smoothing panel state: a :class:`meshlap_core.smoothing.Smoother` stepped live, optional
noise first, live figures and the amplification curve. No polyscope import.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError
from meshlap_core.noise import add_noise
from meshlap_core.smoothing import Smoother, amplification_curve, check_lam
from meshlap_core.types import FloatArray, IntArray

METHODS = ("explicit", "implicit", "taubin")
_EMPTY_V = np.zeros((0, 3))
_EMPTY_F = np.zeros((0, 3), dtype=np.int64)


@dataclass
class SmoothingState:
    """Options, the stepper built from them, and what the panel shows.

    ``lam_steps`` is the ``λ`` of every step the stepper has taken since it was built or reset,
    run-length encoded: ``[[0.5, 10], [2.0, 5]]`` is 10 steps at 0.5, then 5 at 2.0. Only ``λ``
    can change during a run (:meth:`set_lam`); a new method, Laplacian, noise α or seed rebuilds
    the stepper (:meth:`configure`) and starts a new run at iteration 0. A saved session
    replays these runs (:func:`meshlap_app.session.apply`), so a run whose ``λ`` was changed
    mid-way comes back bit for bit.
    """

    method: str = "implicit"
    laplacian: str = "uniform"
    lam: float = 0.5
    noise_alpha: float = 0.0
    seed: int = 0
    playing: bool = False
    error: str = ""
    smoother: Smoother | None = None
    version: int = 0  # bumped when the stepper is rebuilt (connectivity may need re-upload)
    lam_steps: list[list[Any]] = field(default_factory=list)  # [[λ, steps], ...] of this run

    def rebuild(self, V: FloatArray, F: IntArray) -> bool:
        """Build the stepper for the current options from the clean mesh ``V`` (+ noise).

        ``V`` and ``F`` are passed on once: the smoother keeps its own validated copies
        (``V0``, ``F``, ``reference``) and this state reads them from there.
        """
        try:
            start = add_noise(V, F, self.noise_alpha, seed=self.seed) if self.noise_alpha else V
            smoother = Smoother(
                start,
                F,
                self.method,
                self.laplacian,
                self.lam,
                reference=V,
                warn=False,
                history_limit=1000,  # the panel reads only the last entry; playing never grows
            )
        except MeshError as exc:
            self.error = str(exc)
            self.playing = False
            return False
        self.smoother = smoother
        self.error = ""
        self.version += 1
        self.lam_steps = []
        return True

    def set_lam(self, lam: float) -> None:
        """Change ``λ`` keeping the current positions, noise and iteration count
        (:meth:`Smoother.set_lam`: the implicit system is refactorized, nothing else).

        Raises
        ------
        MeshError
            ``λ`` is not a finite number > 0 (the state keeps the previous ``λ``).
        """
        lam = check_lam(lam, "lambda")
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
            A bad option (named), e.g. a negative noise α or seed; the previous options and
            stepper stay.
        """
        if seed is not None and not (isinstance(seed, int) and seed >= 0):
            raise MeshError(f"must be an integer >= 0, got {seed!r}", "noise seed")
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
            if s.iteration > done:  # a step taken (a diverging one is discarded)
                self._count_step(s.lam)
        if s.diverged:
            self.playing = False
            self.error = f"{s.divergence_message()}; press reset"
            return False
        return True

    def _count_step(self, lam: float) -> None:
        """Add one step at ``lam`` to :attr:`lam_steps`."""
        if self.lam_steps and self.lam_steps[-1][0] == lam:
            self.lam_steps[-1][1] += 1
        else:
            self.lam_steps.append([lam, 1])

    def reset(self) -> None:
        """Back to the noisy input (the noise itself stays)."""
        if self.smoother is not None:
            self.smoother.reset()
        self.lam_steps = []
        self.playing = False
        self.error = ""

    @property
    def V(self) -> FloatArray:
        return self.smoother.V if self.smoother is not None else self.V_original

    def figures(self) -> dict[str, Any]:
        """Iteration, volume change (or why it is undefined), RMSE against the original."""
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
        }

    def amplification(self, n: int = 200) -> tuple[FloatArray, FloatArray]:
        """``g(μ)`` over ``μ ∈ [μ_min, 0]`` of this mesh's Laplacian for the current λ."""
        s = self.smoother
        if s is None:
            mu = np.linspace(-2.0, 0.0, n)
            return mu, amplification_curve(self.method, self.lam, mu)
        mu = np.linspace(s.stability.mu_min, 0.0, n)
        return mu, amplification_curve(self.method, self.lam, mu, k_pb=s.k_pb)
