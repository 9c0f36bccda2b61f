"""As-rigid-as-possible flattening (Liu, Zhang, Xu, Gotsman & Gortler, "A local/global approach
to mesh parameterization", SGP 2008), one iteration at a time.

The ARAP energy of a map ``u`` asks every face's Jacobian ``J_t`` (:mod:`.jacobian`) to be a
rotation ``R_t``:

    ``E(u, R) = ½ Σ_t Σ_i cot θ_t^i ‖(u_t^j − u_t^k) − R_t (x_t^j − x_t^k)‖²``
    ``        = Σ_t A_t ‖J_t − R_t‖²_F``

(``θ_t^i`` the face's angle opposite the edge ``jk``, ``x_t`` its corners in its isometric frame;
the two sums agree because ``Σ_i cot θ_i e_i e_iᵀ = 2A·I`` on a triangle). Each iteration
alternates the paper's two steps:

* **local**: for fixed ``u``, the best ``R_t`` is the rotation closest to ``J_t``
  (:func:`~meshlap_core.flatten.jacobian.closest_rotations`: the angle
  ``atan2(c − b, a + d)``, never a reflection);
* **global**: for fixed ``R``, ``∂E/∂u = 0`` is the Poisson system ``K u = ½ Σ_t Σ_i
  cot θ_t^i R_t (x_t^j − x_t^k)`` (scattered to ``j`` and ``k`` with opposite signs), ``K = −C``
  the cotangent stiffness: the same matrix every iteration, factorized once, with one vertex
  pinned (a free boundary: the energy does not see translations) or the whole outer loop
  (a fixed boundary).

Both steps lower ``E``, so the energies :meth:`ARAP.step` returns never increase
(``E(u_{k+1}, R(u_{k+1})) ≤ E(u_{k+1}, R(u_k)) ≤ E(u_k, R(u_k))``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError, check_cancel
from ..laplacian import cotangents_intrinsic
from ..linalg.common import ProgressCallback, report_progress
from ..types import FloatArray, IntArray, as_mesh, exact_indices
from .distortion import check_uv
from .fixed_boundary import DirichletSolver, cotan_laplacian, squared_lengths
from .jacobian import FaceFrames, face_frames


class ARAP:
    """ARAP iterations from an initial map; build once, then :meth:`step` (one iteration).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
        A disk without zero-area faces (a :class:`~meshlap_core.flatten.disk.Disk`'s:
        :meth:`Flattener.arap <meshlap_core.flatten.flattener.Flattener.arap>` makes one).
    init : (n,2) float
        The starting map (Liu et al. start from LSCM; the Flattener does too on a free
        boundary, from Tutte's map on a fixed one).
    pinned : (p,) int, optional
        Vertices held fixed (a fixed boundary); default: the first vertex of the first face,
        held where ``init`` puts it (a free boundary).
    frames : FaceFrames, optional
        :func:`~meshlap_core.flatten.jacobian.face_frames` of ``(V, F)``.
    cot : (m,3) float, optional
        The corner cotangents (:func:`~meshlap_core.laplacian.cotangents_intrinsic`).
    K : (n,n) scipy.sparse.csr_matrix, optional
        Their stiffness ``−C`` (:func:`~meshlap_core.flatten.fixed_boundary.cotan_laplacian`).

    Attributes
    ----------
    uv : (n,2) float
        The current map.
    rotations : (m,2,2) float
        The rotations of the current map's local step (``angles``: their angles).
    energy : float
        ``E(uv, rotations)``.
    energies : list of float
        The energy of the initial map, then after each iteration.
    iterations : int

    Notes
    -----
    An iteration is two sparse products and two back substitutions: the Jacobians' entries
    of all faces from the map (a ``(2m, n)`` matrix built once), the nearest rotations from
    them in closed form, and the right-hand side from the rotations (a ``(n, 2m)`` matrix of
    per-corner constants built once); at 43k vertices a third of the time of gathering the
    corners and rotating the edges face by face.

    Examples
    --------
    >>> from meshlap_core.primitives import grid
    >>> V, F = grid(4, 4)
    >>> arap = ARAP(V, F, V[:, :2] * 2.0)  # twice too big: ARAP shrinks it back
    >>> arap.step() < 1e-12 < arap.energies[0]
    True
    """

    def __init__(
        self,
        V: FloatArray,
        F: IntArray,
        init: FloatArray,
        *,
        pinned: IntArray | None = None,
        frames: FaceFrames | None = None,
        cot: FloatArray | None = None,
        K: Any = None,
    ) -> None:
        V, F = as_mesh(V, F)
        self.V, self.F = V, F
        n = len(V)
        init = check_uv(init, n, "init")
        if pinned is not None:
            pinned = exact_indices(pinned, "pinned").ravel()
            if len(pinned) == 0 or pinned.min() < 0 or pinned.max() >= n:
                raise MeshError(f"must be vertex indices in [0, {n}), at least one", "pinned")
        self.frames = face_frames(V, F) if frames is None else frames
        if cot is None:  # corner i: the angle opposite the edge (i+1, i+2)
            cot = cotangents_intrinsic(squared_lengths(V, F))
        K = cotan_laplacian(V, F, cot) if K is None else K
        self.uv = np.array(init, dtype=np.float64)
        self.pinned = np.array([F[0, 0]] if pinned is None else pinned, dtype=np.int64)
        self._values = self.uv[self.pinned].copy()
        self._solver = DirichletSolver(K, self.pinned)
        self._lifted = self._solver.lift(self._values)
        self._jacobian = _jacobian_matrix(self.frames, F, n)
        self._rhs = _rhs_matrix(self.frames, F, cot, n)
        self._cos, self._sin, self.energy = self._local()
        self.energies = [self.energy]
        self.iterations = 0

    @property
    def angles(self) -> FloatArray:
        """The angles of the local step's rotations ``(m,)``."""
        return np.arctan2(self._sin, self._cos)

    @property
    def rotations(self) -> FloatArray:
        """The local step's rotations ``(m,2,2)``."""
        c, s = self._cos, self._sin
        return np.stack([np.stack([c, -s], axis=1), np.stack([s, c], axis=1)], axis=1)

    def _local(self) -> tuple[FloatArray, FloatArray, float]:
        """The local step on the current map: its rotations (cosines and sines) and energy.

        The rotation nearest ``J = [[a, b], [c, d]]`` has ``(cos, sin) = (a + d, c − b)/r``
        with ``r = |(a + d, c − b)|`` (the angle ``atan2(c − b, a + d)`` without the
        trigonometry), and ``‖J − R‖²_F = ‖J‖²_F + 2 − 2r``.
        """
        m = len(self.F)
        # (centred: the products then round off relative to the layout's size, not its place)
        J = self._jacobian @ (self.uv - self.uv.mean(axis=0))  # rows: [a | c] then [b | d]
        a, c, b, d = J[:m, 0], J[:m, 1], J[m:, 0], J[m:, 1]
        x, y = a + d, c - b
        norm = np.sqrt(x * x + y * y)  # (np.hypot is 8x slower)
        inv = 1.0 / np.where(norm > 0, norm, 1.0)
        cs = np.where(norm > 0, x * inv, 1.0)  # (a zero conformal part: any rotation)
        sn = y * inv
        misfit = a * a + b * b + c * c + d * d + 2.0 - 2.0 * norm
        return cs, sn, float(self.frames.area @ misfit)

    def _global(self) -> FloatArray:
        """The global step: the map minimizing ``E(·, rotations)``."""
        m = len(self.F)
        R = np.empty((2 * m, 2))  # R g = (cos gx − sin gy, sin gx + cos gy)
        R[:m, 0], R[m:, 0], R[:m, 1], R[m:, 1] = self._cos, -self._sin, self._sin, self._cos
        uv = self._solver.solve_lifted(self._lifted, self._rhs @ R)
        uv[self.pinned] = self._values
        return uv

    def step(self) -> float:
        """One local/global iteration; returns the new energy (never above the last)."""
        self.uv = self._global()
        self._cos, self._sin, self.energy = self._local()
        self.energies.append(self.energy)
        self.iterations += 1
        return self.energy

    def run(
        self, iters: int, *, progress: ProgressCallback | None = None, cancel: Any = None
    ) -> float:
        """``iters`` iterations, ``cancel`` checked before each (the iterations done are
        kept; :class:`~meshlap_core.errors.Cancelled` is raised); returns the energy."""
        for i in range(int(iters)):
            check_cancel(cancel, "ARAP")
            self.step()
            report_progress(
                progress, (i + 1) / iters, f"ARAP iteration {i + 1}/{iters}: E = {self.energy:.6g}"
            )
        return self.energy


def _jacobian_matrix(frames: FaceFrames, F: IntArray, n: int) -> sp.csr_matrix:
    """``(2m, n)``: applied to one coordinate of a map, the first and second columns of every
    face's ``J`` (``a = p(u₁ − u₀)``, ``b = q(u₁ − u₀) + r(u₂ − u₀)`` with
    ``[[p, q], [0, r]]`` the frame's inverse; :mod:`.jacobian`)."""
    m = len(F)
    inv = frames.inverse
    p, q, r = inv[:, 0, 0], inv[:, 0, 1], inv[:, 1, 1]
    rows = np.concatenate([np.arange(m)] * 2 + [m + np.arange(m)] * 3)
    cols = np.concatenate([F[:, 1], F[:, 0], F[:, 1], F[:, 2], F[:, 0]])
    vals = np.concatenate([p, -p, q, r, -(q + r)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(2 * m, n))


def _rhs_matrix(frames: FaceFrames, F: IntArray, cot: FloatArray, n: int) -> sp.csr_matrix:
    """``(n, 2m)``: the global step's right-hand side is this times the rotations.

    Face ``t`` adds ``½ cot θ_i R_t (x_j − x_k)`` to vertex ``j`` and subtracts it from ``k``
    for each edge ``jk`` (opposite corner ``i``): to each corner ``v``, ``R_t g_tv`` with the
    constant ``g_tv = Σ ±½ cot θ_i (x_j − x_k)``. So the right-hand side is
    ``[G_x G_y] [[cos], [−sin]]`` and ``[G_x G_y] [[sin], [cos]]``, ``G`` holding ``g``.
    """
    m = len(F)
    x = frames.x
    g = np.zeros((m, 3, 2))
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        half = (0.5 * cot[:, i])[:, None] * (x[:, j] - x[:, k])
        g[:, j] += half
        g[:, k] -= half
    rows = np.concatenate([F.ravel(), F.ravel()])
    faces = np.repeat(np.arange(m), 3)
    cols = np.concatenate([faces, m + faces])
    vals = np.concatenate([g[..., 0].ravel(), g[..., 1].ravel()])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, 2 * m))
