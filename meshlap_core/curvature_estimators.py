"""Principal curvatures and directions per vertex: the estimators side by side.

(The result type :class:`~meshlap_core.principal.PrincipalCurvatures` is re-exported here.)

Every estimator returns a :class:`PrincipalCurvatures` in **one convention** (the project's, see
``docs/conventions.md``): the normal is the outward one given by the face orientation
(counter-clockwise faces), a curvature is positive where the surface bends away from it, so
``H = (κ₁ + κ₂)/2 > 0`` on a sphere, and ``κ₁ ≥ κ₂`` at every vertex with ``d1``, ``d2`` the
unit tangent directions of ``κ₁`` and ``κ₂``.

Estimators (:data:`~meshlap_core.options.CURVATURE_ESTIMATORS`):

- ``"cotan"`` — :func:`cotan_curvatures`: cotangent mean curvature and angle-deficit Gaussian
  curvature with the mixed Voronoi area, ``κ₁,₂ = H ± √(H² − K)``; directions from a
  least-squares fit of the tensor to the edges' normal curvatures (Meyer, Desbrun, Schröder &
  Barr 2003, §5).
- ``"quadric"`` — :func:`quadric_curvatures`: libigl's quadric fit over ``radius`` edge rings
  (Panozzo, Puppo & Rocca 2010).
- ``"rusinkiewicz"`` — :func:`rusinkiewicz_curvatures`: a tensor per face from the vertex normals'
  differences along its edges, rotated into every vertex's tangent plane and averaged with the
  mixed Voronoi weights (Rusinkiewicz 2004).
- ``"normal_cycle"`` — :func:`normal_cycle_curvatures`: the normal-cycle tensor, dihedral angles
  times edge lengths over the Voronoi cell (Cohen-Steiner & Morvan 2003).
- ``"jet"`` — :func:`meshlap_core.curvature_fit.jet_curvatures`: the scale-aware estimator, a
  weighted osculating-jet fit over a ball of a radius in world units (Cazals & Pouget 2003),
  robust to noise.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .curvature import (
    _areas_from,
    _cotan_Cx,
    _cotan_H,
    _deficit_from,
    _face_frame,
    _face_geometry,
    _geometry_of,
    _mixed_corner_areas,
    _normals_from,
    principal_curvature_quadric,
)
from .curvature_fit import jet_curvatures
from .errors import MeshError
from .options import (
    CURVATURE_AREA,
    CURVATURE_ESTIMATORS,
    DEFAULT_BOUNDARY,
    AreaKind,
    CurvatureEstimator,
    check_choice,
)
from .principal import PrincipalCurvatures, eig_sym2, tangent_frames
from .topology import EdgeTable
from .types import FloatArray, IntArray, as_mesh


def _from_tensor(
    a: FloatArray, b: FloatArray, c: FloatArray, t1: FloatArray, t2: FloatArray
) -> tuple[FloatArray, ...]:
    l1, l2, co, si = eig_sym2(a, b, c)
    d1 = co[:, None] * t1 + si[:, None] * t2
    return l1, l2, d1, -si[:, None] * t1 + co[:, None] * t2


def _edge_tensor_fit(
    V: FloatArray, E: IntArray, N: FloatArray, t1: FloatArray, t2: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Least-squares ``[[a, b], [b, c]]`` per vertex from the normal curvatures of the edges
    ``E`` (e,2), ``κ_ij = 2 (x_i − x_j) · n_i / |x_i − x_j|²`` (Meyer et al. 2003, §5.3,
    uniform weights)."""
    n = len(V)
    src = np.concatenate([E[:, 0], E[:, 1]])
    dst = np.concatenate([E[:, 1], E[:, 0]])
    e = V[dst] - V[src]
    en = np.einsum("ij,ij->i", e, N[src])
    L2 = np.einsum("ij,ij->i", e, e)
    kappa = np.divide(-2.0 * en, L2, out=np.zeros_like(en), where=L2 > 0)
    # the edge's direction in the tangent plane: t1, t2 are orthogonal to n, so the tangent
    # projection of e has the coordinates (e·t1, e·t2); its angle φ gives the row
    # (cos²φ, 2 cosφ sinφ, sin²φ) = (co², 2 co si, si²) / r²
    co, si = np.einsum("ij,ij->i", e, t1[src]), np.einsum("ij,ij->i", e, t2[src])
    r2 = co * co + si * si
    inv = np.divide(1.0, r2, out=np.zeros_like(r2), where=r2 > 0)
    a, b, c = co * co * inv, 2.0 * co * si * inv, si * si * inv
    # the normal equations' 6 distinct entries and right-hand side summed per vertex
    # (9 bincounts: faster than one sparse product with a stacked (2e, 9) matrix)
    sums = [
        np.bincount(src, weights=w, minlength=n)
        for w in (a * a, a * b, a * c, b * b, b * c, c * c, a * kappa, b * kappa, c * kappa)
    ]
    A = np.stack([sums[i] for i in (0, 1, 2, 1, 3, 4, 2, 4, 5)], axis=1).reshape(n, 3, 3)
    rhs = np.stack(sums[6:], axis=1)
    A += 1e-12 * np.eye(3) * (np.trace(A, axis1=1, axis2=2)[:, None, None] + 1e-300)
    x = np.linalg.solve(A, rhs[:, :, None])[:, :, 0]
    return x[:, 0], x[:, 1], x[:, 2]


def cotan_curvatures(
    V: FloatArray, F: IntArray, area: AreaKind = CURVATURE_AREA, boundary: str = DEFAULT_BOUNDARY
) -> PrincipalCurvatures:
    """Cotangent ``H`` and angle-deficit ``K`` (Meyer, Desbrun, Schröder & Barr 2003).

    ``H = −½ (M⁻¹C x) · n``, ``K = (2π − Σθ)/A``, ``κ₁,₂ = H ± √max(H² − K, 0)``, with ``A`` the
    mixed Voronoi area by default (``area="barycentric"`` for the course's). The directions are
    the eigenvectors of the symmetric tensor fitted in the least-squares sense to the normal
    curvatures of the edges, ``κ_ij = 2 (x_i − x_j)·n_i / |x_i − x_j|²`` (the paper's §5.3;
    uniform weights), the larger eigenvalue's for ``d1``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    area : {"voronoi", "barycentric"}
    boundary : {"pi", "2pi", "zero"}
        Rule of the angle deficit at boundary vertices.

    Returns
    -------
    PrincipalCurvatures
        Order 2 in L2 for ``H`` and ``K`` on smooth regular meshes with the Voronoi area.
    """
    V, F = as_mesh(V, F)
    n = len(V)
    fr = _face_frame(V, F)  # one pass over the faces for the normals, angles and C x
    fn, theta = _geometry_of(fr)
    N = _normals_from(F, n, fn, theta)
    A = _areas_from(V, F, fr, area)
    H = _cotan_H(_cotan_Cx(fr, F, n), A, N)  # C x without assembling C
    table = EdgeTable.from_faces(F, n)  # one sort for the edges and the boundary
    d = _deficit_from(F, n, theta, boundary, table.boundary_vertex_mask())
    K = np.divide(d, A, out=np.zeros_like(d), where=A > 0)
    r = np.sqrt(np.maximum(H * H - K, 0.0))
    t1, t2 = tangent_frames(N)
    _, _, d1, d2 = _from_tensor(*_edge_tensor_fit(V, table.edges, N, t1, t2), t1, t2)
    return PrincipalCurvatures(H + r, H - r, d1, d2, N, "cotan")


def quadric_curvatures(V: FloatArray, F: IntArray, radius: int = 5) -> PrincipalCurvatures:
    """libigl's ``principal_curvature`` (a quadric fitted over ``radius`` edge rings; Panozzo,
    Puppo & Rocca, "Efficient multi-scale curvature and crease estimation", 2010).

    libigl returns ``PV1 ≥ PV2`` (``PV1`` is the **max**) against the normal of the face
    orientation: ``k1 = PV1``, ``k2 = PV2``, ``d1 = PD1``, ``d2 = PD2`` in this convention.

    Returns
    -------
    PrincipalCurvatures
    """
    V, F = as_mesh(V, F)
    if int(radius) < 1:
        raise MeshError(f"the ring radius must be at least 1, got {radius}", "radius")
    k1, k2, d1, d2 = principal_curvature_quadric(V, F, int(radius))
    fn, theta = _face_geometry(V, F)
    return PrincipalCurvatures(k1, k2, d1, d2, _normals_from(F, len(V), fn, theta), "quadric")


def _rotate_into(x: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """The rotation taking unit ``a`` to unit ``b`` about ``a × b`` applied to ``x`` (rows)."""
    k = np.cross(a, b)
    c = np.einsum("ij,ij->i", a, b)
    kx = np.einsum("ij,ij->i", k, x)
    kk = np.einsum("ij,ij->i", k, k)
    s = np.where(c > -1 + 1e-12, 1.0 / (1.0 + c), 0.0)
    return x + np.cross(k, x) + s[:, None] * (k * kx[:, None] - x * kk[:, None])


def rusinkiewicz_curvatures(V: FloatArray, F: IntArray) -> PrincipalCurvatures:
    """Per-face curvature tensors averaged to the vertices (Rusinkiewicz, "Estimating curvatures
    and their derivatives on triangle meshes", 3DPVT 2004).

    On every face, with an orthonormal frame ``(u, v)`` of its plane, the tensor
    ``II = [[a, b], [b, c]]`` solves in the least-squares sense ``II (e·u, e·v)ᵀ =
    ((n_j − n_i)·u, (n_j − n_i)·v)ᵀ`` over its three edges ``e = x_j − x_i`` (the vertex normals'
    change along the edges: ``II = dn/dx``, positive on a sphere with outward normals). Each
    vertex rotates its tangent frame into the face's plane (about ``n_i × n_f``), expresses the
    face tensor there, and averages with its corners' mixed Voronoi areas as weights.

    Returns
    -------
    PrincipalCurvatures
    """
    V, F = as_mesh(V, F)
    n = len(V)
    fr = _face_frame(V, F)
    fn, theta = _geometry_of(fr)
    N = _normals_from(F, n, fn, theta)
    P = [V[F[:, i]] for i in range(3)]
    u = P[1] - P[0]
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300)
    v = np.cross(fn, u)
    # normal equations of the 6 x 3 system, one per face
    A = np.zeros((len(F), 3, 3))
    rhs = np.zeros((len(F), 3))
    for i, j in ((0, 1), (1, 2), (2, 0)):
        e, dn = P[j] - P[i], N[F[:, j]] - N[F[:, i]]
        eu, ev = np.einsum("ij,ij->i", e, u), np.einsum("ij,ij->i", e, v)
        nu, nv = np.einsum("ij,ij->i", dn, u), np.einsum("ij,ij->i", dn, v)
        for row, y in (((eu, ev, 0 * eu), nu), ((0 * eu, eu, ev), nv)):
            r = np.stack(row, axis=1)
            A += r[:, :, None] * r[:, None, :]
            rhs += r * y[:, None]
    A += 1e-12 * np.eye(3) * (np.trace(A, axis1=1, axis2=2)[:, None, None] + 1e-300)
    abc = np.linalg.solve(A, rhs[:, :, None])[:, :, 0]
    w = _mixed_corner_areas(fr)  # each corner's mixed Voronoi area (Meyer et al. 2003)
    t1, t2 = tangent_frames(N)
    acc = np.zeros((n, 3))
    for k in range(3):
        vk = F[:, k]
        r1 = _rotate_into(t1[vk], N[vk], fn)
        r2 = _rotate_into(t2[vk], N[vk], fn)
        c1 = (np.einsum("ij,ij->i", r1, u), np.einsum("ij,ij->i", r1, v))
        c2 = (np.einsum("ij,ij->i", r2, u), np.einsum("ij,ij->i", r2, v))

        def form(x: tuple[FloatArray, FloatArray], y: tuple[FloatArray, FloatArray]) -> FloatArray:
            return (
                abc[:, 0] * x[0] * y[0]
                + abc[:, 1] * (x[0] * y[1] + x[1] * y[0])
                + abc[:, 2] * x[1] * y[1]
            )

        for col, val in enumerate((form(c1, c1), form(c1, c2), form(c2, c2))):
            acc[:, col] += np.bincount(vk, w[:, k] * val, minlength=n)
    W = np.bincount(F.ravel(), w.ravel(), minlength=n)
    acc = np.divide(acc, W[:, None], out=np.zeros_like(acc), where=W[:, None] > 0)
    k1, k2, d1, d2 = _from_tensor(acc[:, 0], acc[:, 1], acc[:, 2], t1, t2)
    return PrincipalCurvatures(k1, k2, d1, d2, N, "rusinkiewicz")


def _interior_edges(F: IntArray, n: int) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """Edges with two consistently oriented faces: ``(a, b, f1, f2)``, ``a → b`` in ``f1`` and
    ``b → a`` in ``f2``."""
    m = len(F)
    A = F.ravel()
    B = np.roll(F, -1, axis=1).ravel()
    fid = np.repeat(np.arange(m), 3)
    key = A * n + B
    order = np.argsort(key, kind="stable")
    sk = key[order]
    rev = B * n + A
    pos = np.clip(np.searchsorted(sk, rev), 0, len(sk) - 1)
    found = (sk[pos] == rev) & (A < B)
    return A[found], B[found], fid[found], fid[order[pos[found]]]


def normal_cycle_curvatures(V: FloatArray, F: IntArray) -> PrincipalCurvatures:
    """The normal-cycle curvature tensor (Cohen-Steiner & Morvan, "Restricted Delaunay
    triangulations and normal cycle", SoCG 2003).

    Over the mixed Voronoi cell ``B_i`` of every vertex, ``T_i = (1/|B_i|) Σ_e β_e |e ∩ B_i|
    ê êᵀ`` over the edges ``e`` at ``i`` (``|e ∩ B_i| = |e|/2``), ``β_e`` the signed dihedral
    angle (positive at convex edges, outward normals). Bending across an edge is curvature
    *orthogonal* to it, so the tangent part of ``T`` has the eigenvalue ``κ₁`` along the
    direction of ``κ₂`` and vice versa: ``d1`` is the eigenvector of the smaller eigenvalue.

    Returns
    -------
    PrincipalCurvatures
        Converges on meshes whose triangulation is regular enough (the result of the paper);
        not pointwise on arbitrary ones.
    """
    V, F = as_mesh(V, F)
    n = len(V)
    fr = _face_frame(V, F)
    fn, theta = _geometry_of(fr)
    N = _normals_from(F, n, fn, theta)
    a, b, f1, f2 = _interior_edges(F, n)
    e = V[b] - V[a]
    L = np.linalg.norm(e, axis=1)
    eh = e / np.maximum(L, 1e-300)[:, None]
    n1, n2 = fn[f1], fn[f2]
    beta = np.arctan2(np.einsum("ij,ij->i", np.cross(n1, n2), eh), np.einsum("ij,ij->i", n1, n2))
    t1, t2 = tangent_frames(N)
    acc = np.zeros((n, 3))
    for v in (a, b):
        c1 = np.einsum("ij,ij->i", eh, t1[v])
        c2 = np.einsum("ij,ij->i", eh, t2[v])
        w = beta * 0.5 * L
        for col, val in enumerate((c1 * c1, c1 * c2, c2 * c2)):
            acc[:, col] += np.bincount(v, w * val, minlength=n)
    A = _areas_from(V, F, fr, "voronoi")
    acc = np.divide(acc, A[:, None], out=np.zeros_like(acc), where=A[:, None] > 0)
    l1, l2, co, si = eig_sym2(acc[:, 0], acc[:, 1], acc[:, 2])
    e1 = co[:, None] * t1 + si[:, None] * t2
    e2 = -si[:, None] * t1 + co[:, None] * t2
    # the larger eigenvalue is κ₁, measured across its eigenvector: d1 is the other one
    return PrincipalCurvatures(l1, l2, e2, e1, N, "normal_cycle")


ESTIMATOR_FUNCTIONS: dict[str, Callable[..., PrincipalCurvatures]] = {
    "cotan": cotan_curvatures,
    "quadric": quadric_curvatures,
    "rusinkiewicz": rusinkiewicz_curvatures,
    "jet": jet_curvatures,
    "normal_cycle": normal_cycle_curvatures,
}
"""Estimator name → function ``(V, F, **options) -> PrincipalCurvatures``."""


def estimate_curvature(
    V: FloatArray, F: IntArray, estimator: CurvatureEstimator = "cotan", **options: Any
) -> PrincipalCurvatures:
    """Principal curvatures and directions by the named estimator (see the module notes).

    ``options`` go to the estimator: ``area``/``boundary`` (cotan), ``radius`` (quadric: edge
    rings; jet: world units, ``None`` for the automatic default).

    Raises
    ------
    MeshError
        An unknown estimator or option, or a mesh the estimator cannot use.
    """
    check_choice(estimator, CURVATURE_ESTIMATORS, "estimator")
    try:
        return ESTIMATOR_FUNCTIONS[estimator](V, F, **options)
    except TypeError as exc:
        if "argument" not in str(exc):
            raise
        raise MeshError(
            f"the {estimator} estimator does not take {sorted(options)}", "options"
        ) from None


PATCH_RINGS = {"cotan": 3, "rusinkiewicz": 3, "normal_cycle": 3, "quadric": None}
"""Edge rings of the patch :func:`curvature_at_vertex` estimates on: the vertex's value
depends on its 2-ring (normals of its neighbours, dihedral angles at its edges), libigl's
quadric on ``radius + 2`` rings (``None``: from its ``radius``)."""


def curvature_at_vertex(
    V: FloatArray, F: IntArray, vertex: int, estimator: CurvatureEstimator = "cotan", **options: Any
) -> tuple[PrincipalCurvatures, int]:
    """The estimator at one vertex from a patch of rings around it (what an inspector needs
    on a big scan, in milliseconds): the same values as :func:`estimate_curvature` on the
    whole mesh at that vertex (tested), for the estimators of :data:`PATCH_RINGS` (the jet's
    automatic radius depends on the whole mesh: it is refused here).

    Returns
    -------
    PrincipalCurvatures
        On the patch.
    int
        The vertex's index in the patch.

    Raises
    ------
    MeshError
        An unknown estimator or one without a patch rule, or a vertex out of range.
    """
    V, F = as_mesh(V, F)
    check_choice(estimator, CURVATURE_ESTIMATORS, "estimator")
    if estimator not in PATCH_RINGS:
        raise MeshError(f"the {estimator} estimator needs the whole mesh", "estimator")
    if not 0 <= int(vertex) < len(V):
        raise MeshError(f"vertex {vertex} is out of range (the mesh has {len(V)})", "vertex")
    rings = PATCH_RINGS[estimator] or int(options.get("radius", 5)) + 2
    mark = np.zeros(len(V), dtype=bool)
    mark[int(vertex)] = True
    faces = np.zeros(len(F), dtype=bool)
    for _ in range(rings):
        faces = mark[F].any(axis=1)
        mark[F[faces]] = True
    keep = np.flatnonzero(mark)
    local = np.full(len(V), -1, dtype=np.int64)
    local[keep] = np.arange(len(keep))
    p = estimate_curvature(V[keep], local[F[faces]], estimator, **options)
    return p, int(local[int(vertex)])


def disagreement(results: list[PrincipalCurvatures], field: str = "H") -> FloatArray:
    """Max pairwise difference of ``field`` among estimators at every vertex, ``(n,)``: where it
    is large, no estimator can be trusted (noise, sharp features, bad triangles)."""
    if not results:
        raise MeshError("needs at least one estimator's result", "results")
    X = np.stack([r.field(field) for r in results])
    return X.max(axis=0) - X.min(axis=0)
