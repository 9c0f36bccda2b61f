"""As-rigid-as-possible deformation: local rotations, global solve, one iteration at a time.

Sorkine & Alexa, "As-rigid-as-possible surface modeling", SGP 2007 (the energy, its
covariances and the global step's right-hand side: :mod:`~meshlap_core.deform.arap_energy`).
One iteration, as ``igl.arap_solve`` does it:

1. the handles are placed at their targets;
2. **local step**: each vertex's rotation ``R_i`` best maps its rest one-ring onto the current
   one (3×3 SVD with the reflection fix, :mod:`~meshlap_core.deform.rotations`);
3. **global step**: ``K x = b(R)`` on the free vertices, the handles and the fixed region
   known — the cotangent stiffness ``K`` factorized once per handle set.

Each step minimizes the same energy over one set of variables, so ``E(x_{k+1}, R_{k+1}) ≤
E(x_k, R_{k+1}) ≤ E(x_k, R_k)``: the energy reported after each iteration (that of the new
positions with the rotations that produced them) never increases while the targets stay. The
first iteration starts from the rest pose (libigl's tutorial passes ``U = V`` to
``arap_solve``), later ones from the last positions; :meth:`ArapDeformer.reset` goes back.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import MeshError, check_cancel
from ..linalg.common import ProgressCallback, report_progress
from ..options import (
    DEFAULT_ARAP_ENERGY,
    ROTATION_FITS,
    ArapEnergyKind,
    RotationFit,
    check_choice,
)
from ..types import FloatArray, as_vertices
from .arap_energy import ArapEnergy
from .base import Deformer, phase
from .rotations import fit_rotations_igl, svd_rotations
from .system import PinnedSystem

MAX_ITERS = 100_000
"""At most this many ARAP iterations per :meth:`ArapDeformer.run` call."""
HISTORY = 10_000
""":attr:`ArapDeformer.energies` keeps the latest this many values."""


def check_iters(iters: Any, name: str = "iters") -> int:
    """An iteration count as an int in ``0 … MAX_ITERS``."""
    if isinstance(iters, bool) or not isinstance(iters, int | np.integer):
        raise MeshError(f"must be an integer, got {iters!r}", name)
    if not 0 <= int(iters) <= MAX_ITERS:
        raise MeshError(f"must be between 0 and {MAX_ITERS}, got {iters}", name)
    return int(iters)


class ArapDeformer(Deformer):
    """As-rigid-as-possible deformation (module docstring).

    Parameters
    ----------
    V, F, handles, fixed :
        See :class:`~meshlap_core.deform.base.Deformer`.
    energy : {"spokes", "spokes-and-rims"}
        Sorkine & Alexa's one-ring spokes, or libigl's default (spokes and rims).
    rotations : {"exact", "igl"}
        The local step's SVD: this project's double-precision one, or libigl's
        single-precision ``fit_rotations`` (to reproduce ``igl.arap_solve``).
    progress, cancel :
        For the set-up, as :class:`~meshlap_core.deform.harmonic.HarmonicDeformer`.

    Attributes
    ----------
    iteration : int
        Iterations since the targets last changed (or :meth:`reset`).
    total_iterations : int
    energies : list of float
        The energy after each iteration since the targets last changed (the latest
        :data:`HISTORY`).

    Examples
    --------
    >>> from meshlap_core import ArapDeformer
    >>> from meshlap_core.primitives import icosphere
    >>> V, F = icosphere(2)
    >>> arap = ArapDeformer(V, F, handles=[0, 50, 100])
    >>> _ = arap.run(20)  # the targets are the rest positions: nothing moves
    >>> float(abs(arap.positions - V).max()) < 1e-12
    True
    >>> abs(arap.energies[-1]) < 1e-12 * arap.terms.rest  # 0 up to round-off of the terms
    True

    Two opposite sides of a flat grid moved by one translation: the iterations approach
    the translated grid, and the energy never rises:

    >>> import numpy as np
    >>> from meshlap_core import ArapDeformer, grid
    >>> V, F = grid(5, 5)
    >>> sides = np.flatnonzero((V[:, 0] == 0) | (V[:, 0] == 1))
    >>> arap = ArapDeformer(V, F, sides)
    >>> arap.set_targets(V[sides] + [0.5, 0, 0])
    >>> U = arap.run(20)
    >>> bool(np.abs(U - (V + [0.5, 0, 0])).max() < 0.01)
    True
    >>> bool(np.all(np.diff(arap.energies) <= 1e-12))
    True
    """

    method = "arap"

    def __init__(
        self,
        V: FloatArray,
        F: Any,
        handles: Any,
        fixed: Any = None,
        *,
        energy: ArapEnergyKind = DEFAULT_ARAP_ENERGY,
        rotations: RotationFit = "exact",
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> None:
        self.rotations = check_choice(rotations, ROTATION_FITS, "rotation fit", "rotations")
        super().__init__(V, F, handles, fixed)
        phase(progress, cancel, 0.0, "deformation: ARAP energy (cotangent weights, covariances)")
        self.terms = ArapEnergy(self.V, self.F, energy, solid=self.solid, l2=self.l2)
        self.energy_name = "sum_i sum_j w_ij |(x_i - x_j) - R_i (p_i - p_j)|^2" + (
            " over spokes" if self.terms.kind == "spokes" else " over spokes and rims"
        )
        c = self._constrain(self.terms.K)
        phase(progress, cancel, 0.3, f"deformation: factorizing K ({c.n_unknowns:,} unknowns)")
        self.system = PinnedSystem(self.terms.K, c.free, c.known)
        self._basis: FloatArray | None = None  # the last local step's right singular vectors
        self.reset()
        self._finish_setup(self.system.stats)
        phase(progress, cancel, 1.0, "deformation: ready")

    def reset(self, positions: FloatArray | None = None) -> None:
        """Start again from the rest pose (or ``positions`` ``(n,3)``), the current targets
        kept; the iteration count and the energies start again."""
        if positions is None:
            start = self.V.copy()
        else:
            start = as_vertices(positions, "positions")
            if start.shape != self.V.shape:
                raise MeshError(f"should have shape {self.V.shape}; got {start.shape}", "positions")
        self._U = start
        self._R: FloatArray | None = None
        self.iteration = 0
        self.total_iterations = getattr(self, "total_iterations", 0)
        self.energies: list[float] = []

    def _fit(self, S: FloatArray) -> FloatArray:
        """The local step's rotations for the covariances ``S`` ``(3,3,n)`` (the exact SVD
        starts from the last one's singular vectors)."""
        if self.rotations == "igl":
            return fit_rotations_igl(S)
        R, self._basis = svd_rotations(S, basis=self._basis)
        return R

    def set_targets(self, targets: Any) -> None:
        """Move the handles' targets to ``targets`` ``(h,3)`` (the next :meth:`step` places the
        handles there); a change restarts :attr:`iteration` and :attr:`energies`."""
        if self._set_targets(targets):
            self.iteration = 0
            self.energies = []

    def step(self) -> float:
        """One local/global iteration; returns the energy ``E(x, R)`` after it."""
        U = self._U.copy()  # a caller may hold the last positions (a read-only view)
        U[self.handles] = self._targets
        R = self._fit(self.terms.covariances(U))
        b = self.terms.rhs(R)
        self._U = self.system.solve(self._known(self._targets, self.V), b)
        self._R = R
        e = self.terms.energy(self._U, b)
        self.iteration += 1
        self.total_iterations += 1
        self.energies.append(e)
        if len(self.energies) > HISTORY:
            del self.energies[: len(self.energies) - HISTORY]
        return e

    def run(
        self,
        iters: int,
        *,
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> FloatArray:
        """Do ``iters`` iterations (at most :data:`MAX_ITERS`); the positions ``(n,3)``.

        ``progress(fraction, message)`` before each iteration; ``cancel`` is checked before
        each (the iterations done are kept).
        """
        iters = check_iters(iters)
        for i in range(iters):
            check_cancel(cancel, "ARAP iterations")
            report_progress(progress, i / max(iters, 1), f"ARAP iteration {i + 1} of {iters}")
            self.step()
        report_progress(progress, 1.0, f"ARAP: {self.iteration} iterations")
        return self.positions

    def update(self, targets: Any) -> FloatArray:
        """One drag: new ``targets`` ``(h,3)`` and one iteration; the positions ``(n,3)``."""
        self.set_targets(targets)
        self.step()
        return self.positions

    def energy(self) -> float:
        """The energy after the last iteration; before any, that of the handles placed at
        their targets with the best rotations (a local step)."""
        if self.energies:
            return self.energies[-1]
        U = self._U.copy()
        U[self.handles] = self._targets
        R = self._fit(self.terms.covariances(U))
        return self.terms.energy(U, self.terms.rhs(R))

    def vertex_energy(self) -> FloatArray:
        """Each vertex's share of :meth:`energy` ``(n,)`` (its rotation's terms)."""
        if self._R is None:
            return np.zeros(self.n)
        return self.terms.vertex_energy(self._U, self._R)

    def summary(self) -> dict[str, Any]:
        """:meth:`Deformer.summary` with the iterations and the energy's history."""
        out = super().summary()
        out.update(
            iterations=self.iteration,
            arap_energy=self.terms.kind,
            rotations=self.rotations,
        )
        return out
