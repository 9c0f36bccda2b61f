"""Laplacian coordinates: keep every vertex's ``Δx``, solve for the positions.

Sorkine, Cohen-Or, Lipman, Alexa, Rössl & Seidel, "Laplacian surface editing", SGP 2004 (and
Lipman et al., "Differential coordinates for interactive mesh editing", 2004): the rest shape's
differential coordinates ``δ = Δp`` (here the cotangent Laplace–Beltrami ``Δ = M⁻¹C``, i.e.
``−2Hn`` per vertex) are kept as well as possible while the constrained vertices go where they
are told, in the least-squares sense:

    E(x) = ‖Δx − δ‖²_M + Σ_{c ∈ handles ∪ fixed} ω q_c ‖x_c − u_c‖²,

``‖y‖²_M = Σ_i A_i ‖y_i‖²`` (the integral over the surface; ``A_i`` the Voronoi areas),
``u_c`` the targets (the rest position for the fixed region), ``ω`` the constraint weight and
``q_c = (KM⁻¹K)_cc`` the vertex's own stiffness, so that ``ω`` is dimensionless (ω = 1: a
constraint as stiff as the vertex's tie to its neighbours). Since ``Δ`` is linear,
``Δx − δ = Δ(x − p)``: the energy is the Laplacian energy of the displacement, and

* **soft** constraints (the paper's; the default, ``ω`` = :data:`SOFT_WEIGHT`): every vertex
  is an unknown, ``(KM⁻¹K + ω Q_c) d = ω Q_c (u − p)``; the handles lag behind their targets
  (:meth:`~meshlap_core.deform.base.Deformer.handle_error` says by how much);
* **hard** constraints: the handles and the fixed region are exact, and the result is the
  biharmonic displacement (:class:`~meshlap_core.deform.harmonic.HarmonicDeformer`, k = 2)
  exactly — what "keeping δ" amounts to.

Either way ``δ`` keeps its rest *orientation*: rotate the handles and the details do not turn
with them (the paper adds per-vertex similarity transforms ``T_i`` for that; ARAP replaces them
by rotations fitted per vertex). :meth:`~meshlap_core.deform.base.Deformer.rotation_error`
shows where.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from ..laplacian import vertex_areas
from ..linalg.common import ProgressCallback
from ..options import CONSTRAINT_KINDS, DEFAULT_CONSTRAINTS, MASS_AREA, ConstraintKind, check_choice
from ..types import FloatArray
from .base import Deformer, phase
from .harmonic import k_harmonic_operator
from .stiffness import stiffness
from .system import PinnedSystem

SOFT_WEIGHT = 1.0
"""Default ``ω`` of the soft constraints: a single-vertex handle then reaches 98 % (bumpy
sphere, 642 vertices) to 99.999 % (armadillo_igl, 43k) of its move; the lag shrinks like
``1/ω`` (hard constraints in the limit)."""


def check_weight(weight: Any) -> float:
    """The constraint weight ``ω`` as a positive finite float."""
    try:
        w = float(weight)
    except (TypeError, ValueError):
        raise MeshError(f"expected a number, got {weight!r}", "weight") from None
    if not (np.isfinite(w) and w > 0):
        raise MeshError(f"must be positive and finite, got {weight!r}", "weight")
    return w


class LaplacianCoordinates(Deformer):
    """Laplacian-coordinates editing (module docstring): one back-substitution per drag.

    Parameters
    ----------
    V, F, handles, fixed :
        See :class:`~meshlap_core.deform.base.Deformer`.
    constraints : {"soft", "hard"}
    weight : float
        ``ω`` of the soft constraints (ignored when hard).
    progress, cancel :
        As :class:`~meshlap_core.deform.harmonic.HarmonicDeformer`.

    Examples
    --------
    With hard constraints, keeping ``δ = Δx`` of the rest shape is the biharmonic
    displacement (both minimize ``‖Δd‖²_M`` with the same handles):

    >>> import numpy as np
    >>> from meshlap_core import HarmonicDeformer, LaplacianCoordinates, grid
    >>> V, F = grid(5, 5)
    >>> left, right = np.flatnonzero(V[:, 0] == 0), np.flatnonzero(V[:, 0] == 1)
    >>> targets = V[right] + [0, 0, 0.3]
    >>> coords = LaplacianCoordinates(V, F, right, left, constraints="hard").update(targets)
    >>> biharmonic = HarmonicDeformer(V, F, right, left, k=2).update(targets)
    >>> bool(np.allclose(coords, biharmonic))
    True
    """

    method = "laplacian"

    def __init__(
        self,
        V: FloatArray,
        F: Any,
        handles: Any,
        fixed: Any = None,
        *,
        constraints: ConstraintKind = DEFAULT_CONSTRAINTS,
        weight: float = SOFT_WEIGHT,
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> None:
        self.kind = check_choice(constraints, CONSTRAINT_KINDS, "constraints", "constraints")
        self.weight = check_weight(weight)
        super().__init__(V, F, handles, fixed)
        self.energy_name = "||Delta x - delta||_M^2 = int |Delta d|^2" + (
            " + w sum_c q_c |x_c - u_c|^2" if self.kind == "soft" else ""
        )
        phase(progress, cancel, 0.0, "deformation: cotangent stiffness and mass")
        K = stiffness(self.V, self.F, self.solid, self.l2)
        self.Q = k_harmonic_operator(K, vertex_areas(self.V, self.F, MASS_AREA), 2)
        c = self._constrain(K)
        held = np.union1d(c.handles, c.fixed)
        self._held = held
        if self.kind == "hard":
            free, known = c.free, c.known
            self._penalty = np.zeros(self.n)
            self._lone = np.zeros(0, dtype=np.int64)
            A = self.Q
        else:
            q = self.Q.diagonal()
            # a held vertex in no solid face has no stiffness to weigh its penalty by: exact
            self._lone = held[~(q[held] > 0)]
            known = np.union1d(c.still, self._lone)
            free = np.setdiff1d(np.arange(self.n), known, assume_unique=True)
            self._penalty = np.zeros(self.n)
            self._penalty[held] = self.weight * q[held]
            A = (self.Q + sp.diags(self._penalty)).tocsr()
        self._known_rows = known
        phase(progress, cancel, 0.2, f"deformation: factorizing ({len(free):,} unknowns)")
        self.system = PinnedSystem(A, free, known)
        self._finish_setup(self.system.stats)
        phase(progress, cancel, 1.0, "deformation: ready")

    def _goal(self) -> FloatArray:
        """The wanted displacement ``u − p`` ``(n,3)``: the move at the handles, else 0."""
        g = np.zeros_like(self.V)
        g[self.handles] = self._targets - self.V[self.handles]
        return g

    def update(self, targets: Any) -> FloatArray:
        """Move the handles to ``targets`` ``(h,3)``; the deformed positions ``(n,3)``."""
        self._set_targets(targets)
        g = self._goal()
        b = None if self.kind == "hard" else self._penalty[:, None] * g
        d = self.system.solve(g[self._known_rows], b)
        self._U = self.V + d
        exact = self.handles if self.kind == "hard" else np.intersect1d(self.handles, self._lone)
        self._U[exact] = self._targets[np.searchsorted(self.handles, exact)]  # p + (u − p) ≈ u
        return self.positions

    def energy_parts(self) -> tuple[float, float]:
        """``(‖Δx − δ‖²_M, Σ ω q_c ‖x_c − u_c‖²)`` at the current positions."""
        d = self._U - self.V
        miss = d - self._goal()
        shape = max(float(np.einsum("ij,ij->", d, self.Q @ d)), 0.0)  # below 0: round-off
        return shape, float(np.einsum("i,ij,ij->", self._penalty, miss, miss))

    def energy(self) -> float:
        """The minimized energy (both parts of :meth:`energy_parts`)."""
        return float(sum(self.energy_parts()))
