"""Discrete curvature: vertex normals, mean curvature (uniform and cotangent), angle-deficit
Gaussian curvature, principal curvatures.

Conventions. Normals are unit **angle-weighted** vertex normals (Thürmer & Wüthrich 1998),
outward for counter-clockwise faces. Laplacians are negative semidefinite, ``Δx = −2 H n``,
so ``H = −½ (Δx · n)`` is positive on a sphere with outward normals.

Vertex areas decide convergence. With the **Voronoi (mixed)** area of Meyer et al. 2003 (the
default, :data:`~meshlap_core.options.CURVATURE_AREA`), the cotangent mean curvature and the
angle-deficit Gaussian curvature converge on refined icospheres (max error shrinks about 4× per
subdivision). With the **barycentric** area (⅓ of the incident faces, the course's choice,
``area="barycentric"``) they do not: on
icospheres the error stalls near 15 %, because the barycentric cell is not the region the
cotangent formula integrates over. The uniform Laplacian is not a discretisation of Δ at all:
``H_uniform`` carries units of length and depends on the triangulation.

References
----------
Meyer, Desbrun, Schröder & Barr, "Discrete differential-geometry operators for triangulated
2-manifolds", VisMath 2002/2003.
"""

from __future__ import annotations

from typing import NamedTuple

import igl
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, dijkstra

from ..errors import MeshError
from ..laplacian import cotangents_intrinsic, uniform_laplacian, vertex_areas
from ..options import (
    AREA_KINDS,
    BOUNDARY_RULES,
    CURVATURE_AREA,
    CURVATURE_FIELDS,
    DEFAULT_BOUNDARY,
    MAX_FIT_PAIRS,
    AreaKind,
    BoundaryRule,
    CurvatureField,
    check_choice,
)
from ..topology import EdgeTable, boundary_vertex_mask
from ..types import BoolArray, FloatArray, IntArray, as_mesh


def _check_boundary(boundary: str) -> None:
    check_choice(boundary, BOUNDARY_RULES, "boundary rule", "boundary")


class _FaceFrame(NamedTuple):
    """Per-face quantities of one pass over the faces (``m`` faces).

    ``E[k]`` is the edge vector opposite corner ``k`` (``x[c₍ₖ₊₂₎] − x[c₍ₖ₊₁₎]``), one ``(m,)``
    array per coordinate; ``fn`` the face normal times ``dbl = |e₁ × e₂| = 2A``; ``cosdbl[k]``
    is ``cot θₖ · 2A`` (the dot product of the two edges leaving corner ``k``).
    """

    E: list[list[FloatArray]]
    fn: FloatArray
    dbl: FloatArray
    cosdbl: FloatArray


def _face_frame(V: FloatArray, F: IntArray) -> _FaceFrame:
    """One pass over the faces: edge vectors, ``2A·n_f``, ``2A`` and the corners' dot products."""
    # one contiguous array per coordinate (strided (m,3) slices made this 3x slower at 1.4M
    # faces); e_i is the edge opposite corner i
    X = [np.ascontiguousarray(V[:, d]) for d in range(3)]
    c0, c1, c2 = (np.ascontiguousarray(F[:, i]) for i in range(3))
    e0 = [x[c2] - x[c1] for x in X]
    e1 = [x[c0] - x[c2] for x in X]
    e2 = [x[c1] - x[c0] for x in X]
    # fn = e2 × (−e1) = e1 × e2
    fn = np.empty((len(F), 3))
    fn[:, 0] = e1[1] * e2[2] - e1[2] * e2[1]
    fn[:, 1] = e1[2] * e2[0] - e1[0] * e2[2]
    fn[:, 2] = e1[0] * e2[1] - e1[1] * e2[0]
    dbl = np.sqrt(np.einsum("ij,ij->i", fn, fn))

    def dot(a: list[FloatArray], b: list[FloatArray]) -> FloatArray:
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    cosdbl = np.empty(F.shape)  # |e||e'| cos θ at each corner, from the two edges leaving it
    cosdbl[:, 0] = -dot(e2, e1)
    cosdbl[:, 1] = -dot(e0, e2)
    cosdbl[:, 2] = -dot(e1, e0)
    return _FaceFrame([e0, e1, e2], fn, dbl, cosdbl)


def _geometry_of(fr: _FaceFrame) -> tuple[FloatArray, FloatArray]:
    """Unit face normals ``(m,3)`` and corner angles ``(m,3)`` of a :class:`_FaceFrame`.

    ``|e₁ × e₂|`` is twice the face area at every corner, so ``θ_i = atan2(2A, e₁ · e₂)``.
    """
    theta = np.arctan2(fr.dbl[:, None], fr.cosdbl)
    dbl = fr.dbl[:, None]
    fn = np.divide(fr.fn, dbl, out=np.zeros_like(fr.fn), where=dbl > 0)
    return fn, theta


def _face_geometry(V: FloatArray, F: IntArray) -> tuple[FloatArray, FloatArray]:
    """Unit face normals ``(m,3)`` and corner angles ``(m,3)`` from one cross product per face."""
    return _geometry_of(_face_frame(V, F))


def _cotan_Cx(fr: _FaceFrame, F: IntArray, n: int) -> FloatArray:
    """``C x`` (the cotangent stiffness times the coordinates) without assembling ``C``.

    ``(C x)_i = Σ_j ½(cot α_ij + cot β_ij)(x_j − x_i)``: every face adds, at each corner, the
    half-cotangent-weighted edge vectors of its two edges there (``cot θ_k = cosdbl_k / 2A``).
    Equal to ``cotan_stiffness(V, F) @ V`` (the tests check it): where a face has zero area
    (libigl's weights are not finite there) the guarded rule of
    :func:`~meshlap_core.laplacian.cotangents_intrinsic` applies, as in ``cotan_stiffness``.
    """
    if len(F) == 0:
        return np.zeros((n, 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        half_cot = 0.5 * fr.cosdbl / fr.dbl[:, None]
    if not np.isfinite(half_cot).all():
        l2 = np.stack([sum(c * c for c in e) for e in fr.E], axis=1)
        half_cot = 0.5 * cotangents_intrinsic(l2)
    e0, e1, e2 = fr.E
    w0, w1, w2 = half_cot[:, 0], half_cot[:, 1], half_cot[:, 2]
    idx = F.ravel()
    out = np.empty((n, 3))
    G = np.empty((len(F), 3))
    for d in range(3):  # the three coordinates; corner k gets its two edges' pull
        G[:, 0] = w2 * e2[d] - w1 * e1[d]
        G[:, 1] = w0 * e0[d] - w2 * e2[d]
        G[:, 2] = w1 * e1[d] - w0 * e0[d]
        out[:, d] = np.bincount(idx, weights=G.ravel(), minlength=n)
    return out


def _normals_from(F: IntArray, n: int, fn: FloatArray, theta: FloatArray) -> FloatArray:
    N = np.zeros((n, 3))
    for c in range(3):
        N[:, c] = np.bincount(F.ravel(), weights=(fn[:, c : c + 1] * theta).ravel(), minlength=n)
    norm = np.sqrt(np.einsum("ij,ij->i", N, N))[:, None]
    return np.divide(N, norm, out=np.zeros_like(N), where=norm > 1e-300)


def _deficit_from(
    F: IntArray, n: int, theta: FloatArray, boundary: str, on_b: BoolArray | None = None
) -> FloatArray:
    _check_boundary(boundary)
    total = np.bincount(F.ravel(), weights=theta.ravel(), minlength=n)
    d = 2.0 * np.pi - total
    if on_b is None:
        on_b = boundary_vertex_mask(F, n)
    if boundary == "pi":
        d[on_b] = np.pi - total[on_b]
    elif boundary == "zero":
        d[on_b] = 0.0
    used = np.zeros(n, dtype=bool)
    used[F.ravel()] = True
    d[~used] = 0.0
    return d


def corner_angles(V: FloatArray, F: IntArray) -> FloatArray:
    """Interior angle at each corner, ``θ = atan2(|e₁ × e₂|, e₁ · e₂)``.

    ``atan2`` is accurate for angles near 0 and π and gives 0 (not NaN) at a zero-length edge.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    theta : (m,3) float
        ``theta[f, i]`` is the angle at corner ``F[f, i]`` (libigl ``internal_angles`` order).
    """
    V, F = as_mesh(V, F)
    return _face_geometry(V, F)[1]


def vertex_normals(V: FloatArray, F: IntArray) -> FloatArray:
    """Unit angle-weighted vertex normals (outward for counter-clockwise faces).

    ``n_i ∝ Σ_f θ_i,f n_f`` over the faces around ``i`` (Thürmer & Wüthrich 1998). Vertices
    with no well-defined normal (unreferenced, or all incident faces degenerate) get the zero
    vector, never NaN.

    Returns
    -------
    N : (n,3) float

    Examples
    --------
    >>> import numpy as np
    >>> from meshlap_core import icosphere, vertex_normals
    >>> V, F = icosphere(3)
    >>> N = vertex_normals(V, F)
    >>> bool(np.allclose(np.linalg.norm(N, axis=1), 1)), bool(np.abs(N - V).max() < 0.01)
    (True, True)
    """
    V, F = as_mesh(V, F)
    if len(F) == 0:
        return np.zeros_like(V)
    return _normals_from(F, len(V), *_face_geometry(V, F))


def mean_curvature_uniform(V: FloatArray, F: IntArray) -> FloatArray:
    """Mean curvature from the uniform Laplacian, ``H = −½ (L_u x · n)`` (the course formula).

    ``L_u = D⁻¹A − I`` (negative semidefinite). Not scale-invariant: ``H_uniform`` has units of
    length and depends on the triangulation, so it is a shape indicator, not a consistent
    estimate of ``H`` (compare :func:`mean_curvature_cotan`).

    Returns
    -------
    H : (n,) float
    """
    V, F = as_mesh(V, F)
    Lx = uniform_laplacian(F, len(V)) @ V
    return -0.5 * np.sum(Lx * vertex_normals(V, F), axis=1)


def _cotan_H(Cx: FloatArray, area: FloatArray, N: FloatArray) -> FloatArray:
    Lx = np.divide(Cx, area[:, None], out=np.zeros_like(Cx), where=area[:, None] > 0)
    return -0.5 * np.sum(Lx * N, axis=1)


def _uniform_Lx(V: FloatArray, E: IntArray) -> FloatArray:
    """``L_u x = D⁻¹A x − x`` from the unique edges ``E`` ``(e,2)`` without assembling ``L_u``.

    ``(L_u x)_i = mean_{j∈N₁(i)} x_j − x_i`` (zero at isolated vertices), the rows of
    :func:`~meshlap_core.laplacian.uniform_laplacian`; an edge ``(i, i)`` counts once.
    """
    n = len(V)
    a, b = E[:, 0], E[:, 1]
    loop = a == b
    deg = np.bincount(a, minlength=n) + np.bincount(b[~loop], minlength=n)
    out = np.empty((n, 3))
    keep = ~loop
    for d in range(3):
        x = np.ascontiguousarray(V[:, d])
        out[:, d] = np.bincount(a, weights=x[b], minlength=n)
        out[:, d] += np.bincount(b[keep], weights=x[a[keep]], minlength=n)
    inv = np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)
    out *= inv[:, None]
    out -= np.where(deg > 0, 1.0, 0.0)[:, None] * V
    return out


def _cot_weights(fr: _FaceFrame) -> list[FloatArray]:
    """``|e_k|² cot θ_k`` for the three corners ``k`` of every face of a :class:`_FaceFrame`
    (``cot θ = cosdbl / 2A``; 0 where the face has no area), three ``(m,)`` arrays: each
    computed once, shared by the two corners whose Voronoi share uses it."""
    out = []
    for k in range(3):
        e = fr.E[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            w = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) * fr.cosdbl[:, k] / fr.dbl
        out.append(np.where(np.isfinite(w), w, 0.0))
    return out


def _mixed_corner_area(
    fr: _FaceFrame, i: int, any_obtuse: BoolArray, cw: list[FloatArray] | None = None
) -> FloatArray:
    """Corner ``i``'s share of the mixed Voronoi area (Meyer et al. 2003, Fig. 4) in every
    face of a :class:`_FaceFrame`, ``(m,)``: ``⅛ (|e_j|² cot θ_j + |e_k|² cot θ_k)`` in a
    non-obtuse triangle (``cot θ = cosdbl / 2A``, ``e_j`` opposite corner ``j``), else half
    the area at the obtuse corner (``cosdbl < 0``) and a quarter at the others. One column at
    a time: no ``(m,3)`` temporaries on a big scan (``cw``: :func:`_cot_weights`, when the
    three corners are wanted)."""
    if cw is None:
        cw = _cot_weights(fr)
    vor = cw[(i + 1) % 3] / 8.0 + cw[(i + 2) % 3] / 8.0
    quarter = fr.dbl / 8.0  # a quarter of the area A = dbl / 2
    mixed = np.where(fr.cosdbl[:, i] < 0, 2.0 * quarter, quarter)
    return np.where(any_obtuse, mixed, vor)


def _mixed_corner_areas(fr: _FaceFrame) -> FloatArray:
    """Every corner's share of the mixed Voronoi area, ``(m,3)`` (:func:`_mixed_corner_area`)."""
    any_obtuse = (fr.cosdbl < 0).any(axis=1)
    cw = _cot_weights(fr)
    return np.stack([_mixed_corner_area(fr, i, any_obtuse, cw) for i in range(3)], axis=1)


def _areas_from(V: FloatArray, F: IntArray, fr: _FaceFrame, area: str) -> FloatArray:
    """Vertex areas as :func:`~meshlap_core.laplacian.vertex_areas` from the frame: the
    barycentric ones from its ``2A`` (one third of each face's area at each corner), the mixed
    Voronoi ones from its cotangents (:func:`_mixed_corner_areas`; libigl's ``massmatrix``
    assembles a sparse matrix for the same diagonal, 10x slower)."""
    if len(F) == 0:
        return vertex_areas(V, F, area)
    if area == "barycentric":
        return np.bincount(F.ravel(), weights=np.repeat(fr.dbl / 6.0, 3), minlength=len(V))
    check_choice(area, AREA_KINDS, "area")
    any_obtuse = (fr.cosdbl < 0).any(axis=1)
    cw = _cot_weights(fr)
    out = np.zeros(len(V))
    for i in range(3):
        w = _mixed_corner_area(fr, i, any_obtuse, cw)
        out += np.bincount(F[:, i], weights=w, minlength=len(V))
    return out


def mean_curvature_cotan(V: FloatArray, F: IntArray, area: AreaKind = CURVATURE_AREA) -> FloatArray:
    """Mean curvature from the Laplace–Beltrami operator, ``H = −½ (M⁻¹C x · n)``.

    ``C`` is the cotangent stiffness (negative semidefinite), ``M`` the lumped ``area``
    (the mixed Voronoi area that converges by default; ``"barycentric"`` for the course's, see
    the module notes). Zero-area vertices get 0.

    Returns
    -------
    H : (n,) float
    """
    check_choice(area, AREA_KINDS, "area")
    V, F = as_mesh(V, F)
    n = len(V)
    fr = _face_frame(V, F)
    A, Cx = _areas_from(V, F, fr, area), _cotan_Cx(fr, F, n)
    N = _normals_from(F, n, *_geometry_of(fr))
    return _cotan_H(Cx, A, N)


def angle_deficit(
    V: FloatArray, F: IntArray, boundary: BoundaryRule = DEFAULT_BOUNDARY
) -> FloatArray:
    """Integrated Gaussian curvature: the angle deficit at every vertex.

    Interior vertices: ``2π − Σθ``. Boundary vertices: ``π − Σθ`` (``"pi"``, the default, the
    geodesic-curvature term that makes ``Σ deficit = 2πχ`` hold on surfaces with boundary),
    ``2π − Σθ`` (``"2pi"``) or ``0`` (``"zero"``). Unreferenced vertices get 0.

    Returns
    -------
    d : (n,) float
    """
    V, F = as_mesh(V, F)
    return _deficit_from(F, len(V), _face_geometry(V, F)[1], boundary)


def gaussian_curvature(
    V: FloatArray,
    F: IntArray,
    area: AreaKind = CURVATURE_AREA,
    boundary: BoundaryRule = DEFAULT_BOUNDARY,
) -> FloatArray:
    """Angle-deficit Gaussian curvature ``K = (2π − Σθ) / A_i`` (see :func:`angle_deficit`).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    area : {"barycentric", "voronoi"}
        Vertex area ``A_i`` (mixed Voronoi by default; barycentric as in the course).
    boundary : {"pi", "2pi", "zero"}
        Rule at boundary vertices.

    Returns
    -------
    K : (n,) float
        Zero where ``A_i = 0``.
    """
    check_choice(area, AREA_KINDS, "area")
    V, F = as_mesh(V, F)
    d = angle_deficit(V, F, boundary)
    A = vertex_areas(V, F, area)
    return np.divide(d, A, out=np.zeros_like(d), where=A > 0)


def principal_from_HK(H: FloatArray, K: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``κ₁,₂ = H ± √max(H² − K, 0)`` (κ₁ ≥ κ₂)."""
    r = np.sqrt(np.maximum(H * H - K, 0.0))
    return H + r, H - r


def principal_curvatures(
    V: FloatArray,
    F: IntArray,
    area: AreaKind = CURVATURE_AREA,
    boundary: BoundaryRule = DEFAULT_BOUNDARY,
) -> tuple[FloatArray, FloatArray]:
    """Principal curvatures from the cotangent ``H`` and the angle-deficit ``K`` (same area).

    Returns
    -------
    k1, k2 : (n,) float
        ``κ₁ = H + √max(H² − K, 0) ≥ κ₂ = H − √max(H² − K, 0)``.
    """
    f = all_curvature_fields(V, F, area=area, boundary=boundary)
    return f["k1"], f["k2"]


MIN_QUADRIC_RINGS = 2
"""libigl's quadric fit needs at least two rings (it raises 1 to 2 with a warning on stderr)."""


def check_ring_radius(radius: object, name: str = "radius") -> int:
    """A count of edge rings for libigl's quadric as an ``int >= 2``
    (:data:`MIN_QUADRIC_RINGS`; a bool, a fraction, NaN or an infinity refused, naming
    ``name``)."""
    want = f"a whole number of edge rings >= {MIN_QUADRIC_RINGS}"
    if isinstance(radius, bool | np.bool_ | str | bytes):
        raise MeshError(f"{want}, got {radius!r}", name)
    try:
        value = float(radius)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        raise MeshError(f"{want}, got {radius!r}", name) from None
    if not (np.isfinite(value) and value == int(value)):
        raise MeshError(f"{want}, got {radius!r}", name)
    if value < MIN_QUADRIC_RINGS:
        raise MeshError(
            f"{want} (libigl's quadric fit would take {MIN_QUADRIC_RINGS} instead), got {radius!r}",
            name,
        )
    return int(value)


def ring_reach(F: IntArray, n: int) -> int:
    """An upper bound of the number of edge rings around any vertex: twice the largest
    eccentricity (in edges) of one vertex per component (``ecc ≤ diameter ≤ 2·ecc``).
    Rings beyond it hold nothing new; libigl's quadric still loops over each."""
    if len(F) == 0:
        return 0
    a = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    b = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    graph = sp.coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)).tocsr()
    _, labels = connected_components(graph, directed=False)
    reps = np.unique(labels, return_index=True)[1]
    dist = dijkstra(graph, directed=False, indices=reps, unweighted=True, min_only=True)
    return int(2 * np.max(dist[np.isfinite(dist)], initial=0.0))


def principal_curvature_quadric(
    V: FloatArray, F: IntArray, radius: int = 5
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """libigl's quadric-fit principal curvatures (Panozzo et al. 2010), in our sign convention.

    ``radius`` is libigl's: the fit uses the vertices within ``radius`` rings (an integer count
    of edge rings, not a world distance). libigl measures curvature against the normal of the
    face orientation, positive on a sphere with counter-clockwise faces, and returns ``PV1`` as
    the maximum: ``k1 = PV1, k2 = PV2`` (reversing the faces negates and swaps both).

    libigl's fit uses absolute tolerances: it runs on the mesh scaled to a unit bounding box
    and the curvatures are scaled back (``κ(sV) = κ(V)/s``), so a mesh at 1e-55 or 1e74 gets
    its curvature (1e110, 1e-148), not a failed fit. Where the fit still fails (libigl answers
    NaN: too few or degenerate neighbours) the estimator says so instead of reporting 0.

    Call only on a validated mesh (libigl crashes on unreferenced vertices): this function
    refuses a mesh with unreferenced vertices.

    Returns
    -------
    k1, k2 : (n,) float
        ``κ₁ ≥ κ₂``, positive on a sphere with outward normals.
    d1, d2 : (n,3) float
        Unit principal directions of ``κ₁`` and ``κ₂``.

    Raises
    ------
    MeshError
        A bad radius, one reaching past every ring of the mesh or asking more fitting work than
        :data:`~meshlap_core.options.MAX_FIT_PAIRS` (both checked before libigl runs), no
        faces or unreferenced vertices, or a fit that fails at some vertices.

    Examples
    --------
    On a sphere of radius 2 both principal curvatures are ½:

    >>> from meshlap_core import icosphere, principal_curvature_quadric
    >>> V, F = icosphere(3)
    >>> k1, k2, d1, d2 = principal_curvature_quadric(2 * V, F, radius=2)
    >>> round(float(k1.mean()), 2), round(float(k2.mean()), 2), bool((k1 >= k2).all())
    (0.51, 0.51, True)
    """
    V, F = as_mesh(V, F)
    radius = check_ring_radius(radius)
    used = np.zeros(len(V), dtype=bool)
    used[F.ravel()] = True
    if len(F) == 0 or not used.all():
        raise MeshError("the quadric fit needs a mesh with faces and no unreferenced vertices")
    reach = ring_reach(F, len(V))
    if radius > max(reach, 1):
        raise MeshError(
            f"{radius} edge rings reach past the whole mesh (no vertex has more than {reach} "
            f"rings around it); use at most {max(reach, 1)}",
            "radius",
        )
    ball = min(len(V), 1 + 3 * radius * (radius + 1))  # a ring k holds ~6k vertices
    if len(V) * ball > MAX_FIT_PAIRS:
        most = max(1, int((np.sqrt(1 + 4 * (MAX_FIT_PAIRS / len(V) - 1) / 3) - 1) / 2))
        raise MeshError(
            f"{radius} edge rings around each of the {len(V)} vertices is ~{len(V) * ball:.1e} "
            f"vertex-neighbour pairs to fit, more than {MAX_FIT_PAIRS:.0e} (minutes of work); "
            f"use at most {most} rings on this mesh",
            "radius",
        )
    lo, hi = V.min(axis=0), V.max(axis=0)
    scale = float(np.linalg.norm((hi - lo) / 2.0) * 2.0)
    scale = scale if np.isfinite(scale) and scale > 0 else 1.0
    PD1, PD2, PV1, PV2, bad = igl.principal_curvature((V - lo) / scale, F, radius)
    # libigl fits against the angle-weighted normal of the face orientation and returns
    # PV1 = max ≥ PV2 = min, already this module's sign (positive on a sphere with CCW faces):
    # the sign is never taken from the data (a minimal surface has Σ H ≈ 0, any sign)
    swap = PV2 > PV1
    k1 = np.where(swap, PV2, PV1) / scale
    k2 = np.where(swap, PV1, PV2) / scale
    d1 = np.where(swap[:, None], PD2, PD1)
    d2 = np.where(swap[:, None], PD1, PD2)
    # libigl lists the vertices whose fit failed (and gives them 0, not NaN); a NaN is a
    # failure too
    failed = np.union1d(
        np.asarray(bad, dtype=np.int64).ravel(),
        np.flatnonzero(
            ~(np.isfinite(k1) & np.isfinite(k2) & np.isfinite(d1).all(1) & np.isfinite(d2).all(1))
        ),
    )
    if len(failed):
        raise MeshError(
            f"libigl's quadric fit failed at {len(failed)} vertices (first: vertex "
            f"{int(failed[0])}): too few or degenerate neighbours within {radius} rings; use "
            "a larger radius or another estimator",
            "radius",
        )
    return k1, k2, d1, d2


def all_curvature_fields(
    V: FloatArray,
    F: IntArray,
    area: AreaKind = CURVATURE_AREA,
    boundary: BoundaryRule = DEFAULT_BOUNDARY,
    table: EdgeTable | None = None,
) -> dict[str, FloatArray]:
    """Every per-vertex curvature field at once, sharing normals, areas and edges.

    ``table``, the :class:`~meshlap_core.topology.EdgeTable` of ``F`` (``Mesh.edge_table``
    of a loaded mesh), is reused instead of rebuilt; the uniform and cotangent Laplacians are
    applied to the coordinates edge by edge and face by face, never assembled (the same
    numbers as ``uniform_laplacian(F, n) @ V`` and ``cotan_stiffness(V, F) @ V``).

    Returns
    -------
    fields : dict of (n,) float
        ``uniform`` (H from the uniform Laplacian), ``cotan`` (H from M⁻¹C), ``gaussian``
        (angle deficit / area), ``k1``, ``k2`` (from cotan H and K) and ``difference``
        (uniform − cotan).

    Examples
    --------
    Gauss–Bonnet: the angle deficits ``K·A`` of a closed surface sum to ``2πχ``, exactly:

    >>> import numpy as np
    >>> from meshlap_core import all_curvature_fields, torus_mesh, vertex_areas
    >>> V, F = torus_mesh()
    >>> fields = all_curvature_fields(V, F, area="voronoi")
    >>> sorted(fields)
    ['cotan', 'difference', 'gaussian', 'k1', 'k2', 'uniform']
    >>> total = np.sum(fields["gaussian"] * vertex_areas(V, F, "voronoi"))
    >>> abs(float(total)) < 1e-9  # χ = 0 on a torus
    True
    """
    check_choice(area, AREA_KINDS, "area")
    _check_boundary(boundary)
    V, F = as_mesh(V, F)
    n = len(V)
    if table is None or table.n != n or not np.array_equal(table.F, F):
        table = EdgeTable.from_faces(F, n)
    fr = _face_frame(V, F)
    fn, theta = _geometry_of(fr)
    A = _areas_from(V, F, fr, area)
    Cx = _cotan_Cx(fr, F, n)
    del fr  # the per-face edge vectors: 9 arrays of m floats (400 MB at 2.77M vertices)
    N = _normals_from(F, n, fn, theta)
    del fn
    H_u = -0.5 * np.sum(_uniform_Lx(V, table.edges) * N, axis=1)
    H_c = _cotan_H(Cx, A, N)
    d = _deficit_from(F, n, theta, boundary, table.boundary_vertex_mask())
    K = np.divide(d, A, out=np.zeros_like(d), where=A > 0)
    k1, k2 = principal_from_HK(H_c, K)
    return {
        "uniform": H_u,
        "cotan": H_c,
        "gaussian": K,
        "k1": k1,
        "k2": k2,
        "difference": H_u - H_c,
    }


def curvature_field(
    V: FloatArray,
    F: IntArray,
    method: CurvatureField,
    area: AreaKind = CURVATURE_AREA,
    boundary: BoundaryRule = DEFAULT_BOUNDARY,
) -> FloatArray:
    """One named field of :func:`all_curvature_fields` (``method`` in uniform, cotan, gaussian, k1,
    k2, difference).

    Examples
    --------
    On the unit sphere (outward normals) ``H ≈ 1`` and ``K ≈ 1``; on a sphere of radius 2, a
    quarter of that for ``K``:

    >>> from meshlap_core import curvature_field, icosphere
    >>> V, F = icosphere(2)
    >>> round(float(curvature_field(V, F, "cotan").mean()), 3)
    1.0
    >>> round(float(curvature_field(2 * V, F, "gaussian").mean()), 2)
    0.25
    """
    check_choice(method, CURVATURE_FIELDS, "method")
    if method == "uniform":
        return mean_curvature_uniform(V, F)
    if method == "cotan":
        return mean_curvature_cotan(V, F, area)
    if method == "gaussian":
        return gaussian_curvature(V, F, area, boundary)
    return all_curvature_fields(V, F, area, boundary)[method]
