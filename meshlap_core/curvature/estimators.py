"""Principal curvatures and directions per vertex: the estimators side by side.

(The result type :class:`~meshlap_core.curvature.principal.PrincipalCurvatures` is re-exported
here.)

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
- ``"jet"`` — :func:`meshlap_core.curvature.jet_fit.jet_curvatures`: the scale-aware estimator, a
  weighted osculating-jet fit over a ball of a radius in world units (Cazals & Pouget 2003),
  robust to noise.

Cotan, Rusinkiewicz and the normal cycle take a ``topology``
(:class:`~meshlap_core.curvature.topology.CurvatureTopology`, :data:`TOPOLOGY_ESTIMATORS`): the
faces' edges built once and reused while the vertices move (noise, a slider of the lab).
"""

from __future__ import annotations

from collections.abc import Callable
from inspect import signature
from typing import Any

import numpy as np

from ..errors import MeshError
from ..options import (
    CURVATURE_AREA,
    CURVATURE_ESTIMATORS,
    DEFAULT_BOUNDARY,
    AreaKind,
    CurvatureEstimator,
    check_choice,
)
from ..types import FloatArray, IntArray, as_index, as_mesh
from .fields import (
    _areas_from,
    _cotan_Cx,
    _cotan_H,
    _deficit_from,
    _face_frame,
    _face_geometry,
    _geometry_of,
    _mixed_corner_areas,
    _normals_from,
    check_ring_radius,
    principal_curvature_quadric,
)
from .jet_fit import jet_curvatures
from .principal import PrincipalCurvatures, eig_sym2, tangent_frames
from .topology import CurvatureTopology, topology_for


def _from_tensor(
    a: FloatArray, b: FloatArray, c: FloatArray, t1: FloatArray, t2: FloatArray
) -> tuple[FloatArray, ...]:
    l1, l2, co, si = eig_sym2(a, b, c)
    d1 = co[:, None] * t1 + si[:, None] * t2
    return l1, l2, d1, -si[:, None] * t1 + co[:, None] * t2


def _columns(X: FloatArray) -> list[FloatArray]:
    """The three coordinates of ``X`` (k,3) as contiguous ``(k,)`` arrays (gathers and
    products on strided columns are about 3x slower)."""
    return [np.ascontiguousarray(X[:, d]) for d in range(3)]


def _solve3(S: list[FloatArray], rhs: list[FloatArray]) -> FloatArray:
    """The symmetric 3×3 systems ``[[S0, S1, S2], [S1, S3, S4], [S2, S4, S5]] x = rhs`` per row,
    regularised by ``1e-12 · trace`` (a vertex or face whose rows do not span the plane gets
    a finite solution, not a singular matrix), ``(k,3)``.

    In closed form (the adjugate over the determinant of the matrix scaled to unit trace: ten
    times faster than ``np.linalg.solve`` on stacked 3×3 matrices); rows whose scaled
    determinant is below ``1e-10`` (nearly singular: a boundary vertex with two edges) go to
    ``np.linalg.solve``."""
    tr = S[0] + S[3] + S[5]
    inv = 1.0 / (tr + 1e-300)
    reg = 1e-12 * (tr + 1e-300) * inv
    a, b, c = S[0] * inv + reg, S[1] * inv, S[2] * inv
    d, e, f = S[3] * inv + reg, S[4] * inv, S[5] * inv + reg
    r0, r1, r2 = rhs[0] * inv, rhs[1] * inv, rhs[2] * inv
    c00, c01, c02 = d * f - e * e, c * e - b * f, b * e - c * d
    c11, c12, c22 = a * f - c * c, b * c - a * e, a * d - b * b
    det = a * c00 + b * c01 + c * c02
    good = det > 1e-10
    with np.errstate(divide="ignore", invalid="ignore"):
        idet = 1.0 / det
    x = np.stack(
        [
            (c00 * r0 + c01 * r1 + c02 * r2) * idet,
            (c01 * r0 + c11 * r1 + c12 * r2) * idet,
            (c02 * r0 + c12 * r1 + c22 * r2) * idet,
        ],
        axis=1,
    )
    bad = np.flatnonzero(~good)
    if len(bad):
        A = np.empty((len(bad), 3, 3))
        for (i, j), s in zip(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)), S, strict=True):
            A[:, i, j] = A[:, j, i] = s[bad]
        A += (1e-12 * (tr[bad] + 1e-300))[:, None, None] * np.eye(3)
        x[bad] = np.linalg.solve(A, np.stack([r[bad] for r in rhs], axis=1)[:, :, None])[:, :, 0]
    return x


def _edge_tensor_fit(
    V: FloatArray, topo: CurvatureTopology, N: FloatArray, t1: FloatArray, t2: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Least-squares ``[[a, b], [b, c]]`` per vertex from the normal curvatures of the edges
    (``topo.directed``, both directions), ``κ_ij = 2 (x_i − x_j) · n_i / |x_i − x_j|²``
    (Meyer et al. 2003, §5.3, uniform weights)."""
    n = len(V)
    src, dst = topo.directed
    deg = np.bincount(src, minlength=n)
    # the edges are sorted by source: the source's values are repeats, not gathers
    e = [x[dst] - np.repeat(x, deg) for x in _columns(V)]

    def along(B: FloatArray) -> FloatArray:
        b = _columns(B)
        return (
            np.repeat(b[0], deg) * e[0] + np.repeat(b[1], deg) * e[1] + np.repeat(b[2], deg) * e[2]
        )

    en, co, si = along(N), along(t1), along(t2)
    L2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    # the edge's direction in the tangent plane: t1, t2 are orthogonal to n, so the tangent
    # projection of e has the coordinates (co, si) = (e·t1, e·t2) at the angle φ; its row of
    # the fit is (cos²φ, 2 cosφ sinφ, sin²φ) = ((1 + C)/2, S, (1 − C)/2) with C = cos 2φ,
    # S = sin 2φ: the normal equations need only Σ1, ΣC, ΣS, ΣC², ΣCS (ΣS² = Σ1 − ΣC²) and
    # Σκ, ΣκC, ΣκS, 7 sums per vertex instead of 9 (an edge along n has no row: weight 0)
    r2 = co * co + si * si
    inv = np.divide(1.0, r2, out=np.zeros_like(r2), where=r2 > 0)
    kappa = np.divide(-2.0 * en, L2, out=np.zeros_like(en), where=(L2 > 0) & (r2 > 0))
    C = (co * co - si * si) * inv
    S = 2.0 * co * si * inv
    one = deg if (r2 > 0).all() else np.bincount(src, weights=r2 > 0, minlength=n)
    sC, sS, sCC, sCS, sk, skC, skS = (
        np.bincount(src, weights=w, minlength=n)
        for w in (C, S, C * C, C * S, kappa, kappa * C, kappa * S)
    )
    sSS = one - sCC
    sums = [
        0.25 * (one + 2.0 * sC + sCC),  # Σ a²
        0.5 * (sS + sCS),  # Σ a b
        0.25 * sSS,  # Σ a c
        sSS,  # Σ b²
        0.5 * (sS - sCS),  # Σ b c
        0.25 * (one - 2.0 * sC + sCC),  # Σ c²
        0.5 * (sk + skC),  # Σ a κ
        skS,  # Σ b κ
        0.5 * (sk - skC),  # Σ c κ
    ]
    x = _solve3(sums[:6], sums[6:])
    return x[:, 0], x[:, 1], x[:, 2]


def cotan_curvatures(
    V: FloatArray,
    F: IntArray,
    area: AreaKind = CURVATURE_AREA,
    boundary: str = DEFAULT_BOUNDARY,
    topology: CurvatureTopology | None = None,
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
    topology : CurvatureTopology, optional
        ``F``'s edges built once (:class:`~meshlap_core.curvature.topology.CurvatureTopology`):
        pass it again with every new ``V`` of the same faces.

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
    topo = topology_for(F, n, topology)  # the edges and the boundary: one sort, kept
    d = _deficit_from(F, n, theta, boundary, topo.on_boundary)
    K = np.divide(d, A, out=np.zeros_like(d), where=A > 0)
    r = np.sqrt(np.maximum(H * H - K, 0.0))
    t1, t2 = tangent_frames(N)
    _, _, d1, d2 = _from_tensor(*_edge_tensor_fit(V, topo, N, t1, t2), t1, t2)
    return PrincipalCurvatures(H + r, H - r, d1, d2, N, "cotan")


def quadric_curvatures(V: FloatArray, F: IntArray, radius: int = 5) -> PrincipalCurvatures:
    """libigl's ``principal_curvature`` (a quadric fitted over ``radius`` edge rings; Panozzo,
    Puppo & Rocca, "Efficient multi-scale curvature and crease estimation", 2010), on the mesh
    scaled to a unit box (see
    :func:`~meshlap_core.curvature.principal_curvature_quadric`: bounds of the radius, and a
    failed fit refused, never reported as 0).

    libigl returns ``PV1 ≥ PV2`` (``PV1`` is the **max**) against the normal of the face
    orientation: ``k1 = PV1``, ``k2 = PV2``, ``d1 = PD1``, ``d2 = PD2`` in this convention.

    Returns
    -------
    PrincipalCurvatures
    """
    V, F = as_mesh(V, F)
    k1, k2, d1, d2 = principal_curvature_quadric(V, F, radius)  # (checks the radius)
    fn, theta = _face_geometry(V, F)
    return PrincipalCurvatures(k1, k2, d1, d2, _normals_from(F, len(V), fn, theta), "quadric")


def _cross(a: list[FloatArray], b: list[FloatArray]) -> list[FloatArray]:
    """``a × b`` on coordinate columns."""
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a: list[FloatArray], b: list[FloatArray]) -> FloatArray:
    """``a · b`` on coordinate columns."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _face_tensors(
    P: list[list[FloatArray]], NN: list[list[FloatArray]], u: list[FloatArray], v: list[FloatArray]
) -> FloatArray:
    """Rusinkiewicz's per-face ``(a, b, c)`` ``(m,3)``: the least-squares solution of
    ``II (e·u, e·v)ᵀ = (Δn·u, Δn·v)ᵀ`` over the three edges (corner positions ``P[k]`` and
    vertex normals ``NN[k]`` as coordinate columns); the 6 × 3 system's normal equations."""
    zero = np.zeros_like(u[0])
    S = [zero, zero, zero, zero, zero, zero]  # S00, S01, S02 (= 0), S11, S12, S22
    rhs = [zero, zero, zero]
    for i, j in ((0, 1), (1, 2), (2, 0)):
        e = [P[j][d] - P[i][d] for d in range(3)]
        dn = [NN[j][d] - NN[i][d] for d in range(3)]
        eu, ev, nu, nv = _dot(e, u), _dot(e, v), _dot(dn, u), _dot(dn, v)
        uu, uv, vv = eu * eu, eu * ev, ev * ev
        # rows (eu, ev, 0) → nu and (0, eu, ev) → nv
        S = [S[0] + uu, S[1] + uv, S[2], S[3] + vv + uu, S[4] + uv, S[5] + vv]
        rhs = [rhs[0] + eu * nu, rhs[1] + ev * nu + eu * nv, rhs[2] + ev * nv]
    return _solve3(S, rhs)


def _in_face_plane(
    n: list[FloatArray],
    fn: list[FloatArray],
    t1: list[FloatArray],
    t2: list[FloatArray],
    u: list[FloatArray],
    v: list[FloatArray],
) -> tuple[tuple[FloatArray, FloatArray], tuple[FloatArray, FloatArray]]:
    """The vertex's tangent frame ``(t1, t2)`` rotated into the face's plane (the rotation
    ``R`` taking the vertex normal ``n`` to the face normal ``fn`` about ``n × fn``), in the
    face's basis ``(u, v)``: ``((t1·u, t1·v), (t2·u, t2·v))`` after the rotation.

    For a tangent ``t ⊥ n`` Rodrigues' formula reduces to ``R t = t − (t·fn)/(1 + n·fn)
    (n + fn)``, and ``u, v ⊥ fn``: ``R t · u = t·u − (t·fn)(n·u)/(1 + n·fn)``. The rotation
    keeps ``t2 = n × t1``, so the image of ``t2`` is ``fn × R t1``: its coordinates are
    ``(−y, x)`` for ``R t1 = (x, y)``. Where ``n`` is opposite ``fn`` no rotation is defined:
    ``t1``, ``t2`` are projected as they are."""
    c = _dot(n, fn)
    s = np.where(c > -1 + 1e-12, 1.0 / (1.0 + np.maximum(c, -1 + 1e-12)), 0.0)
    st = s * _dot(t1, fn)
    c1 = (_dot(t1, u) - st * _dot(n, u), _dot(t1, v) - st * _dot(n, v))
    c2 = (-c1[1], c1[0].copy())
    flip = np.flatnonzero(s == 0.0)
    if len(flip):
        c2[0][flip] = _dot(t2, u)[flip]
        c2[1][flip] = _dot(t2, v)[flip]
    return c1, c2


def rusinkiewicz_curvatures(
    V: FloatArray, F: IntArray, topology: CurvatureTopology | None = None
) -> PrincipalCurvatures:
    """Per-face curvature tensors averaged to the vertices (Rusinkiewicz, "Estimating curvatures
    and their derivatives on triangle meshes", 3DPVT 2004).

    On every face, with an orthonormal frame ``(u, v)`` of its plane, the tensor
    ``II = [[a, b], [b, c]]`` solves in the least-squares sense ``II (e·u, e·v)ᵀ =
    ((n_j − n_i)·u, (n_j − n_i)·v)ᵀ`` over its three edges ``e = x_j − x_i`` (the vertex normals'
    change along the edges: ``II = dn/dx``, positive on a sphere with outward normals). Each
    vertex rotates its tangent frame into the face's plane (about ``n_i × n_f``), expresses the
    face tensor there, and averages with its corners' mixed Voronoi areas as weights.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    topology : CurvatureTopology, optional
        Accepted for a common signature with the other tensor estimators (checked against
        ``F``; this one needs no edges).

    Returns
    -------
    PrincipalCurvatures
    """
    V, F = as_mesh(V, F)
    n = len(V)
    if topology is not None:
        topology_for(F, n, topology)
    fr = _face_frame(V, F)
    fn, theta = _geometry_of(fr)
    N = _normals_from(F, n, fn, theta)
    corners = [np.ascontiguousarray(F[:, k]) for k in range(3)]
    X, NC = _columns(V), _columns(N)
    P = [[x[c] for x in X] for c in corners]
    NN = [[x[c] for x in NC] for c in corners]
    fnc = _columns(fn)
    u = [P[1][d] - P[0][d] for d in range(3)]
    inv = 1.0 / np.maximum(np.sqrt(_dot(u, u)), 1e-300)
    u = [x * inv for x in u]
    v = _cross(fnc, u)
    abc = _face_tensors(P, NN, u, v)
    a, b, c = abc[:, 0], abc[:, 1], abc[:, 2]
    w = _mixed_corner_areas(fr)  # each corner's mixed Voronoi area (Meyer et al. 2003)
    t1, t2 = tangent_frames(N)
    T1, T2 = _columns(t1), _columns(t2)
    vals = np.empty((3, len(F), 3))  # (tensor entry, face, corner): the weighted forms
    for k in range(3):
        ck = corners[k]
        (x1, y1), (x2, y2) = _in_face_plane(
            NN[k], fnc, [x[ck] for x in T1], [x[ck] for x in T2], u, v
        )
        vals[0, :, k] = a * x1 * x1 + 2.0 * b * x1 * y1 + c * y1 * y1
        vals[1, :, k] = a * x1 * x2 + b * (x1 * y2 + y1 * x2) + c * y1 * y2
        vals[2, :, k] = a * x2 * x2 + 2.0 * b * x2 * y2 + c * y2 * y2
    vals *= w[None]
    flat = F.ravel()
    acc = np.zeros((n, 3))  # float even with no faces (an empty bincount is int)
    for j in range(3):
        acc[:, j] = np.bincount(flat, vals[j].ravel(), minlength=n)
    W = np.bincount(flat, w.ravel(), minlength=n)
    acc = np.divide(acc, W[:, None], out=np.zeros_like(acc), where=W[:, None] > 0)
    k1, k2, d1, d2 = _from_tensor(acc[:, 0], acc[:, 1], acc[:, 2], t1, t2)
    return PrincipalCurvatures(k1, k2, d1, d2, N, "rusinkiewicz")


def normal_cycle_curvatures(
    V: FloatArray, F: IntArray, topology: CurvatureTopology | None = None
) -> PrincipalCurvatures:
    """The normal-cycle curvature tensor (Cohen-Steiner & Morvan, "Restricted Delaunay
    triangulations and normal cycle", SoCG 2003).

    Over the mixed Voronoi cell ``B_i`` of every vertex, ``T_i = (1/|B_i|) Σ_e β_e |e ∩ B_i|
    ê êᵀ`` over the edges ``e`` at ``i`` (``|e ∩ B_i| = |e|/2``), ``β_e`` the signed dihedral
    angle (positive at convex edges, outward normals). Bending across an edge is curvature
    *orthogonal* to it, so the tangent part of ``T`` has the eigenvalue ``κ₁`` along the
    direction of ``κ₂`` and vice versa: ``d1`` is the eigenvector of the smaller eigenvalue.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    topology : CurvatureTopology, optional
        ``F``'s interior edges built once (pass it again with every new ``V``).

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
    a, b, f1, f2 = topology_for(F, n, topology).interior
    X, FN = _columns(V), _columns(fn)  # coordinate columns: gathers 3x faster than rows
    e = [x[b] - x[a] for x in X]
    L = np.sqrt(_dot(e, e))
    inv = 1.0 / np.maximum(L, 1e-300)
    eh = [x * inv for x in e]
    n1, n2 = [x[f1] for x in FN], [x[f2] for x in FN]
    beta = np.arctan2(_dot(_cross(n1, n2), eh), _dot(n1, n2))
    w = beta * 0.5 * L
    t1, t2 = tangent_frames(N)
    T1, T2 = _columns(t1), _columns(t2)
    ends = np.concatenate([a, b])  # both ends of every edge, in one sum per entry
    c1 = np.concatenate([_dot(eh, [x[v] for x in T1]) for v in (a, b)])
    c2 = np.concatenate([_dot(eh, [x[v] for x in T2]) for v in (a, b)])
    ww = np.concatenate([w, w])
    acc = np.zeros((n, 3))  # float even with no edges (an empty bincount is int)
    for j, val in enumerate((c1 * c1, c1 * c2, c2 * c2)):
        acc[:, j] = np.bincount(ends, ww * val, minlength=n)
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

TOPOLOGY_ESTIMATORS: tuple[str, ...] = tuple(
    name for name, f in ESTIMATOR_FUNCTIONS.items() if "topology" in signature(f).parameters
)
"""The estimators taking a ``topology`` (:class:`~meshlap_core.curvature.topology.
CurvatureTopology`): its faces' edges built once, reused for every new ``V`` (cotan,
Rusinkiewicz, normal cycle)."""


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

    Examples
    --------
    On a sphere of radius 2 every estimator finds ``k1 ≈ k2 ≈ ½``:

    >>> from meshlap_core import estimate_curvature, icosphere
    >>> V, F = icosphere(2)
    >>> pc = estimate_curvature(2 * V, F, "rusinkiewicz")
    >>> pc.estimator, round(float(pc.k1.mean()), 2), round(float(pc.k2.mean()), 2)
    ('rusinkiewicz', 0.5, 0.5)
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
    V: FloatArray,
    F: IntArray,
    vertex: int,
    estimator: CurvatureEstimator = "cotan",
    topology: CurvatureTopology | None = None,
    **options: Any,
) -> tuple[PrincipalCurvatures, int]:
    """The estimator at one vertex from a patch of rings around it (what an inspector needs
    on a big scan, in milliseconds): the same values as :func:`estimate_curvature` on the
    whole mesh at that vertex (tested), for the estimators of :data:`PATCH_RINGS` (the jet's
    automatic radius depends on the whole mesh: it is refused here).

    The patch grows ring by ring through the vertex–face adjacency
    (:attr:`~meshlap_core.curvature.topology.CurvatureTopology.vertex_faces`, CSR): only the
    faces near the vertex are read once it is built. Pass ``topology`` (of ``F``) to build it
    once for many vertices; ``options`` go to the estimator on the patch.

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
    vertex = as_index(vertex, len(V), "vertex")
    rings = PATCH_RINGS[estimator] or check_ring_radius(options.get("radius", 5)) + 2
    topo = topology_for(F, len(V), topology)
    keep = np.array([vertex], dtype=np.int64)  # sorted: the patch keeps the mesh's order
    faces = np.zeros(0, dtype=np.int64)
    for _ in range(rings):  # the faces touching the ring so far, then their vertices
        faces = topo.faces_around(keep)
        keep = np.union1d(keep, F[faces].ravel())
    local = np.searchsorted(keep, F[faces])
    p = estimate_curvature(V[keep], local, estimator, **options)
    return p, int(np.searchsorted(keep, vertex))


def disagreement(results: list[PrincipalCurvatures], field: str = "H") -> FloatArray:
    """Max pairwise difference of ``field`` among estimators at every vertex, ``(n,)``: where it
    is large, no estimator can be trusted (noise, sharp features, bad triangles)."""
    if isinstance(results, PrincipalCurvatures) or not results:
        raise MeshError("needs a list of at least one estimator's result", "results")
    if not all(isinstance(r, PrincipalCurvatures) for r in results):
        raise MeshError("every result must be a PrincipalCurvatures", "results")
    if len({len(r.k1) for r in results}) != 1:
        raise MeshError("the results are of meshes with different vertex counts", "results")
    X = np.stack([r.field(field) for r in results])
    return X.max(axis=0) - X.min(axis=0)
