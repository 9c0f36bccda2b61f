"""What every deformation method shares: one object per handle set, one cheap call per drag.

A :class:`Deformer` is built once for a mesh and a handle set (checks, operators, the
factorization: the slow part, which reports ``progress`` and honours ``cancel`` between its
phases), then :meth:`Deformer.update` takes the handles' target positions and returns the
deformed shape: one back-substitution for the linear methods, one iteration for ARAP. Nothing
but the handles and the fixed region is held (and components that hold neither stay at rest:
:mod:`~meshlap_core.deform.constraints`).
"""

from __future__ import annotations

import time
from typing import Any

import igl
import numpy as np

from ..errors import check_cancel
from ..linalg.common import ProgressCallback, report_progress
from ..types import FloatArray, as_mesh
from .constraints import (
    Constraints,
    check_sets,
    check_targets,
    make_constraints,
    solid_from_lengths,
)
from .rigidity import rotation_error_checked
from .system import SystemStats


def phase(progress: ProgressCallback | None, cancel: Any, fraction: float, message: str) -> None:
    """Between two phases of a precomputation: stop if ``cancel`` asks, else report."""
    check_cancel(cancel, "deformation set-up")
    report_progress(progress, fraction, message)


class Deformer:
    """Base class of the deformation methods (see the module docstring).

    Parameters
    ----------
    V : (n,3) float
        Rest positions (copied; never modified).
    F : (m,3) int
    handles : (h,) int
        Every handle vertex (grow discs first with
        :func:`~meshlap_core.deform.regions.grow_handles`).
    fixed : (f,) int, optional
        Vertices held at rest; none by default.

    Attributes
    ----------
    method : str
    energy_name : str
        What the method minimizes, as a formula.
    constraints : Constraints
    handles, fixed : (h,) int, (f,) int
        Sorted; :meth:`update` takes targets in the order of ``handles``.
    l2 : (m,3) float
        Squared edge lengths (column ``k`` opposite corner ``k``), computed once: the
        degenerate-face test (:attr:`solid`) and, on a mesh with a degenerate face, the
        guarded cotangent weights share them.
    solid : (m,) bool
        The faces that are not degenerate.
    stats : SystemStats
        The factorized system's size, entries, factorization time and back end.
    setup_seconds : float
        The whole precomputation (operators and factorization).
    """

    method = ""
    energy_name = ""

    def __init__(self, V: FloatArray, F: Any, handles: Any, fixed: Any = None) -> None:
        self._t0 = time.perf_counter()
        self.V, self.F = as_mesh(V, F)
        self.n = len(self.V)
        self.l2 = igl.squared_edge_lengths(self.V, self.F)  # the degenerate test's, kept
        self.solid = solid_from_lengths(self.l2)
        self.handles, self.fixed = check_sets(self.n, handles, fixed)
        self._targets = self.V[self.handles].copy()
        self._U = self.V.copy()
        self.stats = SystemStats(0, 0, 0.0, "")
        self.setup_seconds = 0.0
        self._abs_terms: Any = None

    def _constrain(self, K: Any) -> Constraints:
        """Partition the vertices (:attr:`constraints`), the components read off the pattern
        of the stiffness ``K`` just built (:func:`make_constraints`)."""
        self.constraints = make_constraints(
            self.F, self.n, self.solid, self.handles, self.fixed, graph=K
        )
        self._slot = np.searchsorted(self.constraints.known, self.handles)
        return self.constraints

    def _finish_setup(self, stats: SystemStats) -> None:
        """Record the system's figures and the precomputation's wall time."""
        self.stats = stats
        self.setup_seconds = time.perf_counter() - self._t0

    # ------------------------------------------------------------------ state

    @property
    def positions(self) -> FloatArray:
        """The current deformed positions ``(n,3)`` (a read-only view; copy to keep)."""
        view = self._U.view()
        view.flags.writeable = False
        return view

    @property
    def targets(self) -> FloatArray:
        """The handles' current targets ``(h,3)`` (a copy)."""
        return self._targets.copy()

    def _known(self, values_at_handles: FloatArray, rest: FloatArray | None = None) -> FloatArray:
        """The known rows' values ``(k,3)``: ``rest`` (zero when ``None``) for the fixed and
        still vertices, the handles' values in their slots."""
        known = (
            np.zeros((len(self.constraints.known), 3))
            if rest is None
            else rest[self.constraints.known]
        )
        known[self._slot] = values_at_handles
        return known

    def _set_targets(self, targets: Any) -> bool:
        """Check and store new targets; whether they differ from the current ones."""
        t = check_targets(targets, len(self.handles))
        changed = not np.array_equal(t, self._targets)
        self._targets = t
        return changed

    # ------------------------------------------------------------------ the drag

    def update(self, targets: Any) -> FloatArray:
        """Move the handles to ``targets`` ``(h,3)`` and return the deformed positions."""
        raise NotImplementedError

    def energy(self) -> float:
        """The method's energy (:attr:`energy_name`) at the current positions."""
        raise NotImplementedError

    # ------------------------------------------------------------------ numbers to show

    def handle_error(self) -> float:
        """The largest distance of a handle vertex from its target (0 for exact constraints)."""
        if len(self.handles) == 0:
            return 0.0
        return float(np.linalg.norm(self._U[self.handles] - self._targets, axis=1).max())

    def displacement(self) -> FloatArray:
        """Each vertex's distance from its rest position ``(n,)``."""
        return np.linalg.norm(self._U - self.V, axis=1)

    def rotation_error(self) -> FloatArray:
        """Each vertex's deviation from a rotation of its one-ring ``(n,)``
        (:func:`~meshlap_core.deform.rigidity.rotation_error`)."""
        err, self._abs_terms = rotation_error_checked(self.V, self.F, self._U, self._abs_terms)
        return err

    def summary(self) -> dict[str, Any]:
        """The figures a teacher shows, as plain data (the CLI's JSON and the panel's table)."""
        c = self.constraints
        return {
            "method": self.method,
            "energy_name": self.energy_name,
            "energy": self.energy(),
            "n_vertices": self.n,
            "n_handles": len(c.handles),
            "n_fixed": len(c.fixed),
            "n_still": len(c.still),
            "n_components": c.n_components,
            "n_unknowns": self.stats.n_unknowns,
            "nnz": self.stats.nnz,
            "factor_seconds": self.stats.factor_seconds,
            "setup_seconds": self.setup_seconds,
            "backend": self.stats.backend,
            "handle_error": self.handle_error(),
        }
