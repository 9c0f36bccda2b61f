"""Geodesic distance by the heat method, and the exact polyhedral distance.

The heat method (Crane, Weischedel & Wardetzky, "Geodesics in heat", ACM TOG 2013), with
``K = −C`` (cotangent stiffness, positive semidefinite) and ``M`` the lumped Voronoi mass:

1. heat for a short time ``t = m·h²`` (``h`` the mean edge length, ``m`` default 1) by one
   backward Euler step ``(M + tK) u = δ_γ`` (``δ_γ`` one at each source);
2. the unit field ``X = −∇u / |∇u|`` per face (``∇`` the piecewise-linear gradient,
   ``igl.grad``, here per face: :func:`face_gradients`);
3. the Poisson problem ``Δφ = ∇·X``, in weak form ``K φ = Gᵀ A X`` (``G`` the gradient,
   ``A`` the face areas; ``K = Gᵀ A G``), one vertex pinned per connected component;
4. ``d = φ − mean(φ[γ])`` in each component holding a source.

The matrices are factorized once (:class:`HeatGeodesic`), all on the pattern of ``K`` (a pinned
row and column kept as explicit zeros), so CHOLMOD's symbolic analysis is done once for all of
them (:class:`~meshlap_core.linalg.factor.SharedAnalysis`); ``K`` itself is assembled from the
per-face gradients the method needs anyway (:func:`gradient_stiffness`). A new source costs two
or three pairs of triangular solves and a few vectorized products per face (median 1.3 s at
692k vertices against ``igl.heat_geodesics_solve``'s 1.25 s side by side at load 7, of which
the three solves ~0.85 s; ``benchmarks/bench_diffusion.py``). The heat decays like
``exp(−d/√t)``, so beyond about ``575 √t`` from the sources it underflows (below 1e-250 of its
peak: 1.3 % to 23 % of the 692k armadillo with ``t = h²``, by source): those faces take the
direction of the heat of a longer time, ``t·100ʲ`` (``j = 1 … 4``; the levels the mesh's size
calls for factorized with the others, any other when first needed). Measured on the 692k scan
(one ``igl.upsample`` of the 173k ``armadillo_loop``, whose vertices it keeps): our distance
there differs from ours on the 173k mesh by 0.4 % on average (1.0 % at most), potpourri3d's
from its own 173k answer by 7.4 % (36 % at most). On a mesh with boundary the heat step takes
the paper's boundary condition (``"neumann"``, ``"dirichlet"`` or their ``"average"``, sec.
3.2.4). Vertices in components without a source get ``inf`` (no path reaches them).

:func:`exact_distance` is the exact polyhedral distance of Mitchell, Mount & Papadimitriou
(``igl.exact_geodesic``), run per component (libigl answers 0 across components).
"""

from __future__ import annotations

from typing import Any

import igl
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..errors import MeshError, check_cancel
from ..laplacian import mean_edge_length, vertex_areas
from ..linalg.common import ProgressCallback, report_progress
from ..linalg.components import components
from ..linalg.factor import SharedAnalysis, pinned_data
from ..linalg.spd import solver_backend
from ..options import (
    AREA_KINDS,
    DEFAULT_HEAT_BOUNDARY,
    HEAT_BOUNDARIES,
    MASS_AREA,
    MAX_STIFFNESS_RATIO,
    AreaKind,
    HeatBoundary,
    check_choice,
)
from ..types import FloatArray, IntArray, as_count, as_faces, as_mesh, as_real
from .heat import check_time
from .sources import check_sources

_ROUNDOFF = 64 * np.finfo(float).eps
"""A heat gradient below this times (the face's largest heat / h) is round-off."""
_UNDERFLOW = 1e-250
"""A face whose largest heat is below this times the largest heat anywhere has underflowed."""
_FAR_LEVELS = 4
"""Longer heat times tried where the heat underflowed: t·100 … t·100⁴ (reach ×10 each)."""
SIMPLICIAL_MAX_N = 200_000
"""Below this many vertices CHOLMOD factorizes the heat method's matrices simplicially
(``LDLᵀ``, no BLAS), from it supernodally. Measured side by side in one process (2 cores,
load 8; precompute, then the median click): 43k armadillo_igl 0.54 s / 22 ms simplicial
against 0.67 s / 34 ms supernodal; 173k armadillo_loop 4.4 s / 99 ms against 4.3 s / 200 ms;
the 692k scan 90 s / 0.52 s against 25 s / 0.68 s."""
_REACH = float(-np.log(_UNDERFLOW))
"""The heat of time ``t`` falls below :data:`_UNDERFLOW` of its peak about this many ``√t``
from the sources (it decays like ``exp(−d/√t)``)."""


def edge_counts(F: IntArray, n: int) -> sp.csr_matrix:
    """How many faces hold each edge: an upper-triangular ``(n,n)`` CSR matrix with entry
    ``(i, j)``, ``i < j``, the number of faces with the edge ``ij`` (1 on a boundary)."""
    F = np.asarray(F, dtype=np.int64)
    a = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    b = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    count = sp.coo_matrix((np.ones(len(lo)), (lo, hi)), shape=(n, n)).tocsr()
    count.sum_duplicates()
    return count


def _table_edges(count: sp.csr_matrix) -> IntArray:
    """The edges ``(i, j)``, ``i < j``, of the table ``count`` (:func:`edge_counts`), ``(e,2)``,
    sorted as :func:`meshlap_core.topology.edges` sorts them."""
    i = np.repeat(np.arange(count.shape[0]), np.diff(count.indptr))
    return np.column_stack((i, count.indices))


def boundary_vertices(F: IntArray, n: int) -> IntArray:
    """Vertices on a boundary edge (an edge of one face), sorted ``(b,)`` int. ``n`` (the
    vertex count) must hold every index of ``F``; more vertices than ``3·len(F)`` can hold
    no boundary (none of them is in a face), so a larger ``n`` is refused rather than
    allocated."""
    F = as_faces(F)
    n = as_count(n, "n", int(F.max(initial=-1)) + 1, max(len(F) * 3, 1))
    if len(F) == 0:
        return np.zeros(0, dtype=np.int64)
    return _boundary(edge_counts(F, n))


def _boundary(count: sp.csr_matrix) -> IntArray:
    """The vertices of the edges held by one face in the table ``count`` (sorted)."""
    rows = np.repeat(np.arange(count.shape[0]), np.diff(count.indptr))
    once = count.data == 1
    return np.unique(np.concatenate([rows[once], count.indices[once]])).astype(np.int64)


def face_gradients(V: FloatArray, F: IntArray) -> tuple[FloatArray, FloatArray]:
    """The gradient of each corner's hat function on each face, and the face areas.

    On the face ``(p₀, p₁, p₂)`` with unit normal ``n`` and area ``A``,
    ``∇φ_i = n × (p_k − p_j) / (2A)`` for ``(i, j, k)`` cyclic: the rows of ``igl.grad``,
    stored per corner, so ``∇u = Σ_i u_i ∇φ_i`` is three products (no sparse matrix).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    hat : (3, 3, m) float
        ``hat[i, :, f]`` the gradient of corner ``i``'s hat on face ``f`` (0 on a face of
        zero area).
    area : (m,) float
    """
    P = [V[F[:, i]] for i in range(3)]
    N = np.cross(P[1] - P[0], P[2] - P[0])
    double = np.linalg.norm(N, axis=1)
    ok = double > 0
    inv = np.divide(1.0, double, out=np.zeros_like(double), where=ok)
    unit = N * inv[:, None]
    hat = np.empty((3, 3, len(F)))
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        hat[i] = (np.cross(unit, P[k] - P[j]) * inv[:, None]).T
    return hat, 0.5 * double


def gradient_stiffness(F: IntArray, hat: FloatArray, area: FloatArray, n: int) -> sp.csr_matrix:
    """The stiffness ``K = Gᵀ A G`` (``G`` the piecewise-linear gradient, ``A`` the face
    areas) from the per-face hat gradients of :func:`face_gradients`.

    ``K_ij = Σ_f A_f ⟨∇φ_i, ∇φ_j⟩`` over the faces holding ``i`` and ``j``: for an edge
    ``ij`` it is ``−½ (cot α_ij + cot β_ij)`` (so ``K = −C``, libigl's ``−cotmatrix``, to
    round-off), and ``K_ii = −Σ_{j≠i} K_ij``. Being ``Gᵀ A G``, it is positive semidefinite and
    the exact adjoint of the divergence the heat method takes (a face of zero area adds
    nothing). Every mesh edge and the whole diagonal are stored, zero or not, so matrices
    built from its values keep its pattern.

    Parameters
    ----------
    F : (m,3) int
    hat : (3,3,m) float
    area : (m,) float
    n : int

    Returns
    -------
    K : (n,n) scipy.sparse.csr_matrix
        Symmetric, sorted indices, each entry once.
    """
    off = np.concatenate(
        [area * np.einsum("kf,kf->f", hat[(i + 1) % 3], hat[(i + 2) % 3]) for i in range(3)]
    )
    a = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])  # the edge opposite corner i
    b = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    # Σ_j ∇φ_j = 0 on a face, so A⟨∇φ_i, ∇φ_i⟩ = −Σ_{j≠i} A⟨∇φ_i, ∇φ_j⟩: the diagonal is
    # minus the row sums (K·1 = 0), n entries instead of 3m to sort
    diag = -(np.bincount(a, off, minlength=n) + np.bincount(b, off, minlength=n))
    ar = np.arange(n)
    rows, cols = np.concatenate([a, b, ar]), np.concatenate([b, a, ar])
    K = sp.coo_matrix((np.concatenate([off, off, diag]), (rows, cols)), shape=(n, n)).tocsr()
    K.sum_duplicates()  # sorts the indices; keeps explicit zeros
    return K


def far_levels(V: FloatArray, t: float) -> int:
    """How many longer heat times (``t·100ʲ``) the farthest faces of the mesh will need: the
    smallest ``j`` whose reach ``575·10ʲ·√t`` (:data:`_REACH`) covers twice the bounding box's
    diagonal (a surface path is longer than the chord), at most :data:`_FAR_LEVELS`."""
    if len(V) == 0 or t <= 0:
        return 0
    span = 2.0 * float(np.linalg.norm(np.ptp(V, axis=0)))
    reach = _REACH * np.sqrt(t)
    if span <= reach:
        return 0
    return int(min(np.ceil(np.log10(span / reach)), _FAR_LEVELS))


def _diagonal_positions(K: sp.csr_matrix) -> IntArray:
    """Where each diagonal entry ``K_ii`` sits in ``K.data`` ``(n,)`` (sorted CSR storing its
    whole diagonal, as :func:`gradient_stiffness` does)."""
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    pos = np.flatnonzero(rows == K.indices)
    if len(pos) != K.shape[0]:
        raise ValueError("the matrix does not store its whole diagonal")
    return pos


def check_time_factor(m: float, name: str = "m") -> float:
    """The heat method's ``m`` (``t = m·h²``) as a positive finite float (booleans, complex
    numbers and strings refused, not converted)."""
    return as_real(m, name, positive=True)


class HeatGeodesic:
    """Precomputed heat method on one mesh: build once, then :meth:`distance` per source set.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    m : float
        The time factor: ``t = m·h²`` (default 1, the paper's choice).
    boundary : {"neumann", "dirichlet", "average"}
        Heat-step boundary condition on meshes with boundary (ignored on closed meshes).
    area : {"voronoi", "barycentric"}
        The lumped mass ``M``.

    Attributes
    ----------
    t : float
        The heat time used.
    h : float
        The mean edge length.
    n_components : int
    labels : (n,) int
        Component of each vertex.
    boundary : (b,) int
        The boundary vertices.

    Examples
    --------
    On the unit sphere the distance to the antipode is π (within the method's error):

    >>> import numpy as np
    >>> from meshlap_core import HeatGeodesic, icosphere
    >>> V, F = icosphere(3)
    >>> d = HeatGeodesic(V, F).distance([0])
    >>> antipode = int(np.argmin(V @ V[0]))
    >>> float(d[0]), round(float(d[antipode]), 1)
    (0.0, 3.1)
    """

    def __init__(
        self,
        V: FloatArray,
        F: IntArray,
        m: float = 1.0,
        boundary: HeatBoundary = DEFAULT_HEAT_BOUNDARY,
        area: AreaKind = MASS_AREA,
    ) -> None:
        self.V, self.F = as_mesh(V, F)
        self.rule = check_choice(boundary, HEAT_BOUNDARIES, "boundary condition", "boundary")
        self.m = check_time_factor(m)
        check_choice(area, AREA_KINDS, "area")
        n = len(self.V)
        if n == 0 or len(self.F) == 0:
            raise MeshError("the mesh has no faces; the heat method needs a surface", "F")
        # ∇ of each corner's hat function per face (3 corners, 3 coordinates, m), and the face
        # areas: ∇u, the divergence Gᵀ A X and K = Gᵀ A G from them (no igl.grad/cotmatrix)
        self._hat, self._area = face_gradients(self.V, self.F)
        self._corners = [np.ascontiguousarray(self.F[:, i]) for i in range(3)]
        K = self._K = gradient_stiffness(self.F, self._hat, self._area, n)
        self.mass = vertex_areas(self.V, self.F, area)
        bad = np.flatnonzero(~(self.mass > 0))
        if len(bad):
            raise MeshError(
                f"vertex {int(bad[0])} (and {len(bad) - 1} more) has zero area: it is "
                "unreferenced or only in degenerate faces; remove unreferenced vertices and "
                "degenerate faces first (meshlap's load_mesh does)",
                "V",
            )
        count = edge_counts(self.F, n)  # one edge table: h and the boundary
        self.h = mean_edge_length(self.V, self.F, _table_edges(count))
        self.t = self.m * self.h**2
        per_m = self.h**2 * float(np.max(K.diagonal() / self.mass))  # t·max K_ii/M_ii / m
        stiff = self.m * per_m
        if not stiff <= MAX_STIFFNESS_RATIO:
            most = MAX_STIFFNESS_RATIO / per_m
            raise MeshError(
                f"m = {self.m:g} makes the heat time t = m·h² so long that M + tK is singular "
                f"in double precision (t·max K_ii/M_ii = {stiff:.1e} > {MAX_STIFFNESS_RATIO:.0e}); "
                f"on this mesh m must be at most {most:.3g}",
                "m",
            )
        self.boundary = _boundary(count)
        self.n_components, self.labels = components(K)
        self._face_label = self.labels[self.F[:, 0]]
        # every matrix below has K's pattern (pinned rows and columns kept as explicit
        # zeros), so one symbolic analysis serves all their factorizations: M + tK, the
        # pinned K, the Dirichlet M + tK and the longer times' M + t'K
        self._diag = _diagonal_positions(K)
        mode = "simplicial" if n < SIMPLICIAL_MAX_N else "supernodal"
        self._shared = SharedAnalysis(K.indptr, K.indices, solver_backend(), mode)
        heat = self._heat_data(self.t)
        self._heat = self._shared.factor(heat)
        self._heat_dirichlet: Any = None  # M + tK with the boundary rows pinned to u = 0
        if len(self.boundary) and self.rule != "neumann" and len(self.boundary) < n:
            self._heat_dirichlet = self._shared.factor(
                pinned_data(K.indptr, K.indices, heat, self.boundary)
            )
        self._far: dict[int, Any] = {}
        first = np.full(self.n_components, n)
        np.minimum.at(first, self.labels, np.arange(n))
        self._pinned = first  # one pinned vertex per component: K without them is definite
        self._poisson = self._shared.factor(pinned_data(K.indptr, K.indices, K.data, first))
        # the longer times the sources' farthest faces will need, factorized now: a click then
        # only back-substitutes (the 692k scan needs t·100; an unforeseen one is built lazily)
        for level in range(1, far_levels(self.V, self.t) + 1):
            self._far_solver(level)

    def _heat_data(self, t: float) -> FloatArray:
        """The values of ``M + tK`` on ``K``'s pattern."""
        data = t * self._K.data
        data[self._diag] += self.mass
        return data

    def heat(self, sources: IntArray) -> FloatArray:
        """The heat step ``u`` (before normalization) for checked ``sources``."""
        n = len(self.V)
        delta = np.zeros(n)
        delta[sources] = 1.0
        u = self._heat.solve(delta)
        if self._heat_dirichlet is None:
            return u
        delta[self.boundary] = 0.0  # the boundary rows are pinned: u = 0 there
        if not np.any(delta):  # every source on the boundary: Dirichlet heat is zero
            return u
        ud = self._heat_dirichlet.solve(delta)
        ud[self.boundary] = 0.0  # (0 already: those rows are decoupled)
        return ud if self.rule == "dirichlet" else 0.5 * (u + ud)

    def _directions(
        self, u: FloatArray, faces: IntArray | None = None
    ) -> tuple[FloatArray, np.ndarray, np.ndarray]:
        """``X = −∇u/|∇u|`` per face ``(3,m)`` (0 where a gradient at the round-off of the
        face's own heat has no direction: a face at constant heat, e.g. opposite the source on
        a tetrahedron), where it is trusted ``(m,)``, and where the heat underflowed ``(m,)``
        (below :data:`_UNDERFLOW` of the largest: denormal or 0, its gradient meaningless).
        With ``faces``, on those faces only (``(3, len(faces))``, ...)."""
        corners = self._corners if faces is None else [c[faces] for c in self._corners]
        hat = self._hat if faces is None else self._hat[:, :, faces]
        uc = [u[c] for c in corners]  # the heat at each corner, (m,) each
        g = uc[0] * hat[0]  # ∇u = Σ_i u_i ∇φ_i
        g += uc[1] * hat[1]
        g += uc[2] * hat[2]
        top = np.abs(uc[0])  # the face's largest heat
        np.maximum(top, np.abs(uc[1]), out=top)
        np.maximum(top, np.abs(uc[2]), out=top)
        # ∇u relative to the face's own heat: no underflow when squared (a gradient of 1e-161
        # would), and the round-off test is one comparison
        g /= np.where(top > 0, top, 1.0)
        norm = np.sqrt(np.einsum("kf,kf->f", g, g))
        known = norm > _ROUNDOFF / self.h
        # a face whose heat underflowed (not one at constant heat by symmetry) waits for a
        # longer time's direction
        peak = max(float(u.max(initial=0.0)), -float(u.min(initial=0.0)))
        lost = top <= _UNDERFLOW * peak
        g *= np.where(known, -1.0 / np.where(known, norm, 1.0), 0.0)
        return g, known & ~lost, lost

    def _far_solver(self, level: int) -> Any:
        """The Neumann heat step's factorization at ``t·100^level`` (built once)."""
        solver = self._far.get(level)
        if solver is None:
            solver = self._far[level] = self._shared.factor(self._heat_data(self.t * 100.0**level))
        return solver

    def _far_heat(self, level: int, sources: IntArray) -> FloatArray:
        """The Neumann heat at ``t·100^level`` from the sources."""
        delta = np.zeros(len(self.V))
        delta[sources] = 1.0
        return self._far_solver(level).solve(delta)

    def _divergence(self, X: FloatArray) -> FloatArray:
        """``Gᵀ A X`` ``(n,)``: each face's area times ``⟨∇φ_i, X⟩`` summed at its corners
        ``i`` (the weak divergence of the unit field ``X (3,m)``)."""
        n = len(self.V)
        b = np.zeros(n)
        for corner, hat in zip(self._corners, self._hat, strict=True):
            b += np.bincount(corner, self._area * np.einsum("kf,kf->f", hat, X), minlength=n)
        return b

    def distance(self, sources: int | IntArray) -> FloatArray:
        """Approximate geodesic distance to the nearest source.

        Parameters
        ----------
        sources : int or (s,) int
            Source vertices.

        Returns
        -------
        d : (n,) float
            0 at the sources (the mean over a component's sources is 0), ``inf`` in
            components without a source.
        """
        n = len(self.V)
        src = check_sources(sources, n)
        X, known, lost = self._directions(self.heat(src))
        # far from the sources the heat of t = m·h² underflows to 0 (it decays like
        # exp(−d/√t): beyond about 575 √t): those faces take the direction of the heat of a
        # longer time, t·100, t·100², ... (factorized once, with the precomputation when the
        # mesh's size calls for them), on those faces only
        wanted = np.bincount(self.labels[src], minlength=self.n_components)[self._face_label] > 0
        redo = wanted & (lost | ~known) if np.any(wanted & lost) else np.zeros_like(lost)
        level = 0
        while np.any(redo) and level < _FAR_LEVELS:
            level += 1
            faces = np.flatnonzero(redo)
            X2, known2, _ = self._directions(self._far_heat(level, src), faces)
            X[:, faces[known2]] = X2[:, known2]
            redo[faces[known2]] = False
        b = self._divergence(X)
        b[self._pinned] = 0.0  # the pinned vertices' rows: φ = 0 there
        phi = self._poisson.solve(b)
        count = np.bincount(self.labels[src], minlength=self.n_components)
        total = np.bincount(self.labels[src], weights=phi[src], minlength=self.n_components)
        has = count > 0
        shift = np.divide(total, count, out=np.zeros_like(total), where=has)
        d = phi - shift[self.labels]
        d[~has[self.labels]] = np.inf
        return d


def surface_components(F: IntArray, n: int) -> IntArray:
    """The connected component of each vertex through the faces ``(n,)`` int: ``0 … c−1``
    for the vertices of faces, ``−1`` for a vertex no face references (it has no surface
    around it, so no path leaves it)."""
    used = np.zeros(n, dtype=bool)
    used[F.ravel()] = True
    if len(F) == 0:
        return np.full(n, -1, dtype=np.int64)
    a = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    b = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    graph = sp.coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)).tocsr()
    _, raw = connected_components(graph, directed=False)
    labels = np.full(n, -1, dtype=np.int64)
    _, labels[used] = np.unique(raw[used], return_inverse=True)
    return labels


def _component_meshes(
    V: FloatArray, F: IntArray, src: IntArray
) -> tuple[FloatArray, list[tuple[IntArray, IntArray, IntArray]]]:
    """The components holding a source, each as ``(vertices, local faces, local sources)``,
    and the distance array to fill: ``inf`` everywhere but at the sources (0). A source on a
    vertex no face references is 0 at itself and reaches nothing."""
    n = len(V)
    labels = surface_components(F, n)
    d = np.full(n, np.inf)
    d[src] = 0.0
    wanted = np.unique(labels[src])
    parts = []
    for c in wanted[wanted >= 0]:
        verts = np.flatnonzero(labels == c)
        local = np.full(n, -1, dtype=np.int64)
        local[verts] = np.arange(len(verts))
        faces = local[F[labels[F[:, 0]] == c]]
        parts.append((verts, faces, local[src[labels[src] == c]]))
    return d, parts


def _repeated_corner(F: IntArray) -> int | None:
    """The first face with a repeated vertex (not a triangle), or ``None``."""
    bad = np.flatnonzero((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 0] == F[:, 2]))
    return int(bad[0]) if len(bad) else None


def _normalized(V: FloatArray) -> tuple[FloatArray, float]:
    """``V`` moved to its centroid and divided by its bounding box's diagonal (at most 1e300:
    finite), and that diagonal: the distances of the scaled mesh times it are the mesh's.
    libigl's geodesics use absolute tolerances; at 1e-55 MMP's windows never merge (4 GB in
    27 s), at 1e160 squared lengths overflow."""
    c = V.mean(axis=0)
    lo, hi = V.min(axis=0), V.max(axis=0)
    s = float(np.linalg.norm((hi - lo) / 2.0) * 2.0) if len(V) else 0.0
    if not (np.isfinite(s) and s > 0):
        return V - c, 1.0
    return (V - c) / s, s


def igl_heat_distance(
    V: FloatArray, F: IntArray, sources: Any, t: float | None = None
) -> FloatArray:
    """libigl's heat method (``igl.heat_geodesics_precompute`` / ``_solve``), the reference
    the tests and the benchmark compare :class:`HeatGeodesic` with; ``t`` defaults to
    libigl's (``h²``).

    Run per connected component holding a source (libigl's one Poisson solve puts another
    component at a finite distance), on that component's vertices only (a vertex no face
    references made libigl's precomputation fail, or crash when it was a source); the other
    components get ``inf``. A component that is one triangle (libigl's precomputation fails
    on it: all its vertices are boundary) is flat: its distance is the straight one. The mesh
    is scaled to a unit bounding box for libigl and the distances scaled back (``t`` with
    it).

    Raises
    ------
    MeshError
        Bad sources, a bad ``t`` (NaN, ≤ 0), a face with a repeated vertex or of zero area
        (libigl's cotangents are infinite there: it answers NaN), or a result that is not
        finite where a path exists.
    """
    V, F = as_mesh(V, F)
    src = check_sources(sources, len(V))
    tt = None if t is None else check_time(t)
    bad = _repeated_corner(F)
    if bad is None and len(F):
        double = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
        zero = np.flatnonzero(~(double > 0))
        bad = int(zero[0]) if len(zero) else None
    if bad is not None:
        raise MeshError(
            f"face {bad} {F[bad].tolist()} has zero area; libigl's heat method cannot take it "
            "(its cotangents are infinite there): remove degenerate faces first (load_mesh "
            "does)",
            "F",
        )
    d, parts = _component_meshes(V, F, src)
    for verts, faces, local_src in parts:
        Vc, scale = _normalized(V[verts])
        if len(faces) == 1:  # a flat triangle: the straight distance
            dist = np.min(np.linalg.norm(Vc[:, None, :] - Vc[None, local_src, :], axis=2), axis=1)
        else:
            data = igl.HeatGeodesicsData()
            if tt is None:
                igl.heat_geodesics_precompute(Vc, faces, data)
            else:
                igl.heat_geodesics_precompute(Vc, faces, tt / scale**2, data)
            dist = np.asarray(igl.heat_geodesics_solve(data, local_src))
        if not np.all(np.isfinite(dist)):
            raise MeshError(
                "libigl's heat method gave a distance that is not finite (t too small for "
                "this mesh?)",
                "t" if tt is not None else "F",
            )
        d[verts] = dist * scale
    return d


def exact_distance(
    V: FloatArray,
    F: IntArray,
    sources: Any,
    *,
    progress: ProgressCallback | None = None,
    cancel: Any = None,
) -> FloatArray:
    """The exact polyhedral geodesic distance (MMP, ``igl.exact_geodesic``).

    Each component holding a source is solved on its own faces and vertices (libigl reports
    0, not ``inf``, across components, and crashed on a source no face references); the
    others get ``inf``, a source no face references 0 at itself. Each component is scaled to
    a unit bounding box for libigl and its distances scaled back (libigl's tolerances are
    absolute). ``cancel`` is checked between components; one component's propagation cannot
    be interrupted (at 43k vertices it takes 18–39 s: the viewer runs it as a job).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    sources : int or (s,) int
    progress : callable, optional
        ``progress(fraction, message)`` per component.
    cancel : threading.Event or callable, optional

    Returns
    -------
    d : (n,) float

    Raises
    ------
    MeshError
        Bad sources, no faces, a face with a repeated vertex, or an edge of more than two
        faces in a component holding a source (libigl's MMP crashes the process on both:
        they are refused before it runs).

    Examples
    --------
    On a flat grid the polyhedral geodesic distance is the Euclidean one:

    >>> import numpy as np
    >>> from meshlap_core import exact_distance, grid
    >>> V, F = grid(5, 5)
    >>> d = exact_distance(V, F, 0)
    >>> bool(np.allclose(d, np.linalg.norm(V - V[0], axis=1)))
    True
    """
    V, F = as_mesh(V, F)
    n = len(V)
    src = check_sources(sources, n)
    if len(F) == 0:
        raise MeshError("the mesh has no faces", "F")
    d, parts = _component_meshes(V, F, src)
    for verts, faces, _ in parts:
        _check_exact_component(faces, verts)
    for i, (verts, faces, local_src) in enumerate(parts):
        check_cancel(cancel, "exact geodesic distance")
        report_progress(progress, i / len(parts), f"exact distance, component {i + 1}")
        Vc, scale = _normalized(V[verts])
        dist = igl.exact_geodesic(Vc, faces, VS=local_src, VT=np.arange(len(verts)))
        d[verts] = np.asarray(dist) * scale
    report_progress(progress, 1.0, "exact distance done")
    return d


def _check_exact_component(faces: IntArray, verts: IntArray) -> None:
    """Refuse what crashes libigl's MMP: a face with a repeated vertex, an edge held by more
    than two faces (a non-manifold edge, also made by a face listed twice). The message
    names them in the mesh's own numbering."""
    bad = _repeated_corner(faces)
    if bad is not None:
        raise MeshError(
            f"a face {verts[faces[bad]].tolist()} repeats a vertex; the exact distance (libigl's "
            "MMP) needs triangles (remove degenerate faces, as load_mesh does)",
            "F",
        )
    count = edge_counts(faces, len(verts))
    over = np.flatnonzero(count.data > 2)
    if len(over):
        rows = np.repeat(np.arange(count.shape[0]), np.diff(count.indptr))
        a, b = int(verts[rows[over[0]]]), int(verts[count.indices[over[0]]])
        raise MeshError(
            f"edge ({a}, {b}) is shared by {int(count.data[over[0]])} faces ({len(over)} such "
            "edge(s)); the exact distance (libigl's MMP) needs every edge in at most two "
            "faces. The heat method (HeatGeodesic, --method heat) takes non-manifold meshes",
            "F",
        )
