"""k-harmonic displacement: the smoothest displacement that moves the handles (k = 1, 2, 3).

The displacement ``d = x − p`` (not the positions: the rest pose is reproduced exactly when the
handles do not move, and details ride along unchanged in orientation) solves ``Δᵏ d = 0`` on
the free vertices, with ``d`` given on the handles (their move) and the fixed region (0). In
weak form with the cotangent stiffness ``K = −C`` and the lumped Voronoi mass ``M``
(``Δ = M⁻¹C = −M⁻¹K``), it minimizes

    E_k(d) = Σ_coords dᵀ Q_k d,     Q_k = K (M⁻¹K)ᵏ⁻¹:

* k = 1, ``dᵀKd = ∫|∇d|²`` (Dirichlet energy; harmonic: the handles' pull is felt as a
  kink at them);
* k = 2, ``dᵀKM⁻¹Kd = ∫(Δd)²`` (Laplacian energy; biharmonic, Botsch & Kobbelt 2004,
  Jacobson et al. 2010: smooth at the handles);
* k = 3, ``dᵀK M⁻¹K M⁻¹K d = ∫|∇Δd|²`` (triharmonic: curvature continuous too).

``Q_k`` is libigl's ``harmonic`` operator (``igl.harmonic(V, F, b, bc, k)`` builds
``−L (M⁻¹L)ᵏ⁻¹`` from ``cotmatrix`` and the Voronoi ``massmatrix``; the sign does not change
the minimizer), so the displacement equals ``igl.harmonic(V, F, b, d_b, k)``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from ..laplacian import vertex_areas
from ..linalg.common import ProgressCallback
from ..options import HARMONIC_ORDERS, MASS_AREA
from ..types import FloatArray
from .base import Deformer, phase
from .stiffness import stiffness
from .system import PinnedSystem

ENERGY_NAMES = {
    1: "Dirichlet energy of the displacement: sum d^T K d = int |grad d|^2",
    2: "Laplacian energy of the displacement: sum d^T K M^-1 K d = int (Delta d)^2",
    3: "sum d^T K M^-1 K M^-1 K d = int |grad Delta d|^2",
}


def k_harmonic_operator(K: sp.csr_matrix, mass: FloatArray, k: int) -> sp.csr_matrix:
    """``Q_k = K (M⁻¹K)ᵏ⁻¹`` ``(n,n)``, symmetric positive semidefinite.

    Parameters
    ----------
    K : (n,n) scipy.sparse matrix
        The cotangent stiffness ``−C`` (positive semidefinite).
    mass : (n,) float
        Lumped vertex areas; a vertex of zero area (in no face of positive area) gets
        ``M⁻¹ = 0`` (its row of ``K`` is zero anyway).
    k : int
        1, 2 or 3.

    Returns
    -------
    Q : (n,n) scipy.sparse.csr_matrix
    """
    K = sp.csr_matrix(K)
    if k == 1:
        return K
    inv = np.divide(1.0, mass, out=np.zeros_like(mass, dtype=np.float64), where=mass > 0)
    MinvK = sp.diags(inv) @ K
    Q = K
    for _ in range(k - 1):
        Q = Q @ MinvK
    Q = ((Q + Q.T) * 0.5).tocsr()  # symmetric up to the products' round-off
    Q.sum_duplicates()
    return Q


class HarmonicDeformer(Deformer):
    """k-harmonic displacement (module docstring): one back-substitution per drag.

    Parameters
    ----------
    V, F, handles, fixed :
        See :class:`~meshlap_core.deform.base.Deformer`.
    k : int
        1 (harmonic), 2 (biharmonic) or 3 (triharmonic).
    progress : callable, optional
        ``progress(fraction, message)`` between the set-up's phases.
    cancel : threading.Event or callable, optional
        Checked between the phases (the factorization itself runs to its end).

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core import HarmonicDeformer
    >>> from meshlap_core.primitives import icosphere
    >>> V, F = icosphere(2)
    >>> bi = HarmonicDeformer(V, F, handles=[0], fixed=[100], k=2)
    >>> U = bi.update(V[[0]] + [0.0, 0.0, 0.2])
    >>> bool(np.array_equal(U[0], V[0] + [0.0, 0.0, 0.2])), bool(np.array_equal(U[100], V[100]))
    (True, True)

    A flat 5×5 grid held at x = 0 and its x = 1 column lifted by 1: the harmonic (k = 1)
    displacement is linear in x, so every vertex rises by its x:

    >>> import numpy as np
    >>> from meshlap_core import HarmonicDeformer, grid
    >>> V, F = grid(5, 5)
    >>> left, right = np.flatnonzero(V[:, 0] == 0), np.flatnonzero(V[:, 0] == 1)
    >>> solver = HarmonicDeformer(V, F, right, left, k=1)  # factorized once
    >>> U = solver.update(V[right] + [0, 0, 1])  # one back-substitution per drag
    >>> bool(np.allclose(U[:, 2], V[:, 0]))
    True
    """

    def __init__(
        self,
        V: FloatArray,
        F: Any,
        handles: Any,
        fixed: Any = None,
        k: int = 2,
        *,
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> None:
        if isinstance(k, bool) or k not in HARMONIC_ORDERS.values():
            raise MeshError(f"k must be 1, 2 or 3, got {k!r}", "k")
        super().__init__(V, F, handles, fixed)
        self.k = int(k)
        self.method = next(m for m, order in HARMONIC_ORDERS.items() if order == self.k)
        self.energy_name = ENERGY_NAMES[self.k]
        phase(progress, cancel, 0.0, "deformation: cotangent stiffness and mass")
        K = stiffness(self.V, self.F, self.solid, self.l2)
        mass = vertex_areas(self.V, self.F, MASS_AREA) if self.k > 1 else np.ones(self.n)
        self.Q = k_harmonic_operator(K, mass, self.k)
        c = self._constrain(K)
        phase(
            progress,
            cancel,
            0.2,
            f"deformation: factorizing Q_{self.k} ({c.n_unknowns:,} unknowns)",
        )
        self.system = PinnedSystem(self.Q, c.free, c.known)
        self._finish_setup(self.system.stats)
        phase(progress, cancel, 1.0, "deformation: ready")

    def update(self, targets: Any) -> FloatArray:
        """Move the handles to ``targets`` ``(h,3)``; the deformed positions ``(n,3)``."""
        self._set_targets(targets)
        d = self.system.solve(self._known(self._targets - self.V[self.handles]))
        self._U = self.V + d
        self._U[self.handles] = self._targets  # p + (u − p) is u only up to round-off
        return self.positions

    def energy(self) -> float:
        """``Σ dᵀ Q_k d`` over the coordinates of the current displacement (a positive
        semidefinite form: a value below 0 is round-off, shown as 0)."""
        d = self._U - self.V
        return max(float(np.einsum("ij,ij->", d, self.Q @ d)), 0.0)
