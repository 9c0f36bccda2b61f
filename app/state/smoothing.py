"""Smoothing panel state: a :class:`meshlap_core.smoothing.Smoother` stepped live, optional
noise first, live figures and the amplification curve. No polyscope import.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError
from meshlap_core.noise import add_noise
from meshlap_core.smoothing import Smoother, amplification_curve
from meshlap_core.types import FloatArray, IntArray

METHODS = ("explicit", "implicit", "taubin")
_EMPTY_V = np.zeros((0, 3))
_EMPTY_F = np.zeros((0, 3), dtype=np.int64)


@dataclass
class SmoothingState:
    """Options, the stepper built from them, and what the panel shows."""

    method: str = "implicit"
    laplacian: str = "uniform"
    lam: float = 0.5
    noise_alpha: float = 0.0
    seed: int = 0
    playing: bool = False
    error: str = ""
    smoother: Smoother | None = None
    version: int = 0  # bumped when the stepper is rebuilt (connectivity may need re-upload)

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
        return True

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
        """One iteration; stops playing (and says why) when the explicit flow diverges."""
        s = self.smoother
        if s is None:
            return False
        if s.diverged:
            self.playing = False
            return False
        s.step()
        if s.diverged:
            self.playing = False
            self.error = "diverged: this explicit λ is above the stable limit (see below)"
            return False
        return True

    def reset(self) -> None:
        if self.smoother is not None:
            self.smoother.reset()
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
