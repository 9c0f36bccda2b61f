"""The vertex inspector: every number that goes into the discrete operators at one vertex.

For a vertex ``i`` it lists, as a student would write them out, the quantities the global
operators sum: per neighbour ``j`` the opposite angles ``α_ij, β_ij`` and the cotangent weight
``w_ij = ½(cot α_ij + cot β_ij)``; per incident face the corner angle ``θ_f`` and the face's share
of the barycentric and mixed-Voronoi areas; and at the vertex the areas, the angle-weighted normal,
both Laplacians of the position and the curvatures they give:

- ``Δ_uniform x = (1/|N(i)|) Σ_j (x_j − x_i)`` and ``Δ_cotan x = (1/A_i) Σ_j w_ij (x_j − x_i)``
  (negative semidefinite: ``Δx = −2Hn``), so ``H = −½ Δx · n``;
- ``K = (θ₀ − Σθ)/A_i`` with ``θ₀ = 2π`` inside and the boundary rule's ``θ₀`` on the boundary;
- ``κ₁,₂ = H ± √max(H² − K, 0)``.

References: Pinkall & Polthier, *Computing discrete minimal surfaces and their conjugates*
(1993) for the weights; Meyer, Desbrun, Schröder & Barr, *Discrete differential-geometry
operators for triangulated 2-manifolds* (2003) for the mixed Voronoi area. The tests check every
listed quantity against the global operators (row ``i`` of ``C``, ``M_ii``, and the curvature
fields), so this is an independent, step-by-step re-computation, not a second implementation
that could drift.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import MeshError
from .options import (
    AREA_KINDS,
    BOUNDARY_RULES,
    CURVATURE_AREA,
    DEFAULT_BOUNDARY,
    AreaKind,
    BoundaryRule,
    check_choice,
)
from .topology import one_ring
from .topology.rings import Fan
from .types import BoolArray, FloatArray, IntArray, as_mesh


@dataclass(frozen=True)
class NeighbourTerm:
    """One neighbour ``j`` of the inspected vertex and its terms in the Laplacians."""

    index: int
    edge_length: float
    alpha: float  # radians, the angle opposite edge ij in the first face that holds it
    beta: float | None  # radians, in the second face; None on a boundary edge
    weight_cotan: float  # w_ij = ½(cot α + cot β)
    weight_uniform: float  # 1/|N(i)|
    contribution: FloatArray  # w_ij (x_j − x_i), (3,)
    negative: bool = False  # obtuse opposite angles made w_ij < 0 (beyond round-off)


@dataclass(frozen=True)
class FaceTerm:
    """One face around the inspected vertex."""

    face: int
    angle: float  # radians, the corner angle at the vertex
    area: float
    obtuse: bool  # some angle of the face exceeds 90°: the mixed-Voronoi rule changes
    obtuse_at_vertex: bool
    share_barycentric: float  # area / 3
    share_voronoi: float  # the mixed-Voronoi share of Meyer et al.


@dataclass(frozen=True)
class VertexInspection:
    """Everything :func:`inspect_vertex` computes for one vertex (see the module docstring)."""

    vertex: int
    position: FloatArray
    boundary: bool
    manifold: bool
    area_kind: str
    boundary_rule: str
    neighbors: list[NeighbourTerm]
    faces: list[FaceTerm]
    area_barycentric: float
    area_voronoi: float
    normal: FloatArray
    laplacian_uniform: FloatArray
    laplacian_cotan: FloatArray
    H_uniform: float
    H_cotan: float
    angle_sum: float
    angle_deficit: float
    K: float
    k1: float
    k2: float
    fans: list[Fan] = field(default_factory=list)

    @property
    def area(self) -> float:
        """``A_i`` of the selected area kind (the one ``Δ_cotan`` and ``K`` divide by)."""
        return self.area_voronoi if self.area_kind == "voronoi" else self.area_barycentric

    def to_json(self) -> dict[str, Any]:
        """The ``--json`` object of ``meshlap inspect`` (angles in degrees)."""

        def vec(x: FloatArray) -> list[float]:
            return [float(c) for c in x]

        return {
            "vertex": self.vertex,
            "boundary": self.boundary,
            "manifold": self.manifold,
            "area": self.area_kind,
            "boundary_rule": self.boundary_rule,
            "area_barycentric": self.area_barycentric,
            "area_voronoi": self.area_voronoi,
            "normal": vec(self.normal),
            "laplacian_uniform": vec(self.laplacian_uniform),
            "laplacian_cotan": vec(self.laplacian_cotan),
            "H_uniform": self.H_uniform,
            "H_cotan": self.H_cotan,
            "angle_sum": self.angle_sum,
            "angle_sum_deg": math.degrees(self.angle_sum),
            "angle_deficit": self.angle_deficit,
            "K": self.K,
            "k1": self.k1,
            "k2": self.k2,
            "fans": [
                {
                    "neighbors": [int(j) for j in f.neighbors],
                    "faces": [int(x) for x in f.faces],
                    "closed": f.closed,
                }
                for f in self.fans
            ],
            "neighbors": [
                {
                    "index": t.index,
                    "edge_length": t.edge_length,
                    "alpha_deg": math.degrees(t.alpha),
                    "beta_deg": None if t.beta is None else math.degrees(t.beta),
                    "weight_cotan": t.weight_cotan,
                    "weight_uniform": t.weight_uniform,
                    "contribution": vec(t.contribution),
                    "negative": t.negative,
                }
                for t in self.neighbors
            ],
            "faces": [
                {
                    "face": t.face,
                    "angle_deg": math.degrees(t.angle),
                    "area": t.area,
                    "obtuse": t.obtuse,
                    "share_barycentric": t.share_barycentric,
                    "share_voronoi": t.share_voronoi,
                }
                for t in self.faces
            ],
        }


def _cot(angle: FloatArray) -> FloatArray:
    """``cot θ``, 0 for a degenerate corner (θ = 0 or π), as the cotangent Laplacian does."""
    s = np.sin(angle)
    return np.divide(np.cos(angle), s, out=np.zeros_like(angle), where=np.abs(s) > 1e-300)


def _corner_geometry(V: FloatArray, tri: IntArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Angles ``(k,3)`` at the corners of ``tri`` (rows ``(i, a, b)``), areas ``(k,)``, and
    normals ``(k,3)`` (unit, zero for degenerate faces)."""
    P = V[tri]
    e_ia, e_ib, e_ab = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0], P[:, 2] - P[:, 1]
    cross = np.cross(e_ia, e_ib)
    dbl = np.linalg.norm(cross, axis=1)
    ang = np.stack(
        [
            np.arctan2(dbl, np.einsum("ij,ij->i", e_ia, e_ib)),
            np.arctan2(dbl, -np.einsum("ij,ij->i", e_ia, e_ab)),
            np.arctan2(dbl, np.einsum("ij,ij->i", e_ib, e_ab)),
        ],
        axis=1,
    )
    normal = np.divide(cross, dbl[:, None], out=np.zeros_like(cross), where=dbl[:, None] > 0)
    return ang, 0.5 * dbl, normal


def _voronoi_shares(
    V: FloatArray, tri: IntArray, ang: FloatArray, area: FloatArray
) -> tuple[FloatArray, BoolArray, BoolArray]:
    """Mixed-Voronoi share of corner 0 of every ``(i, a, b)`` row (Meyer et al. 2003, Fig. 4).

    Non-obtuse face: ``⅛(|x_i − x_a|² cot θ_b + |x_i − x_b|² cot θ_a)``; obtuse at ``i``:
    ``A/2``; obtuse elsewhere: ``A/4``.
    """
    P = V[tri]
    l2_ia = np.sum((P[:, 1] - P[:, 0]) ** 2, axis=1)
    l2_ib = np.sum((P[:, 2] - P[:, 0]) ** 2, axis=1)
    voronoi = (l2_ia * _cot(ang[:, 2]) + l2_ib * _cot(ang[:, 1])) / 8.0
    obtuse = np.any(ang > np.pi / 2, axis=1)
    at_i = ang[:, 0] > np.pi / 2
    share = np.where(obtuse, np.where(at_i, area / 2, area / 4), voronoi)
    return share, obtuse, at_i


def inspect_vertex(
    V: FloatArray,
    F: IntArray,
    vertex: int,
    area: AreaKind = CURVATURE_AREA,
    boundary: BoundaryRule = DEFAULT_BOUNDARY,
) -> VertexInspection:
    """Recompute, step by step, every operator term at one vertex.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    vertex : int
        The vertex ``i`` (``0 <= i < n``).
    area : {"barycentric", "voronoi"}
        The ``A_i`` that ``Δ_cotan`` and ``K`` divide by (both areas are always listed).
    boundary : {"pi", "2pi", "zero"}
        The boundary rule of the angle deficit (see :mod:`meshlap_core.options`).

    Returns
    -------
    VertexInspection
        Neighbours in ring order (counter-clockwise seen from the side the normals point to;
        each fan of a non-manifold vertex in turn), incident faces, and the vertex quantities.

    Examples
    --------
    On the unit sphere the cotangent mean curvature at a vertex is 1; its cotangent weights
    and uniform weights are listed per neighbour:

    >>> from meshlap_core import icosphere, inspect_vertex
    >>> V, F = icosphere(2)
    >>> ins = inspect_vertex(V, F, 0)
    >>> len(ins.neighbors), round(ins.H_cotan, 6)
    (5, 1.0)
    >>> ins.neighbors[0].weight_uniform  # 1/|N| at a valence-5 vertex
    0.2
    >>> round(ins.angle_deficit / ins.area, 6) == round(ins.K, 6)  # K = (2π − Σθ) / A_i
    True
    """
    check_choice(area, AREA_KINDS, "area")
    check_choice(boundary, BOUNDARY_RULES, "boundary")
    V, F = as_mesh(V, F)
    n = len(V)
    if isinstance(vertex, bool) or not isinstance(vertex, (int, np.integer)):
        raise MeshError(f"must be an integer vertex index, not {vertex!r}", "vertex")
    if not 0 <= int(vertex) < n:
        raise MeshError(f"vertex {vertex} is out of range (the mesh has {n} vertices)", "vertex")
    i = int(vertex)
    rows, corner = np.nonzero(F == i)
    if len(rows) == 0:
        raise MeshError(f"vertex {i} belongs to no face", "vertex")
    # every incident face as (i, a, b), keeping its orientation
    tri = np.stack([F[rows, corner], F[rows, (corner + 1) % 3], F[rows, (corner + 2) % 3]], 1)
    ang, face_area, face_normal = _corner_geometry(V, tri)
    share_v, obtuse, at_i = _voronoi_shares(V, tri, ang, face_area)

    # opposite angles per neighbour: neighbour a sees the angle at b, neighbour b the one at a
    nbr = np.concatenate([tri[:, 1], tri[:, 2]])
    opp = np.concatenate([ang[:, 2], ang[:, 1]])
    ring, fans, manifold = _ring_and_fans(F, n, i, nbr)
    x_i = V[i]
    neighbours = []
    opposite = [opp[nbr == j] for j in ring]
    weights = [0.5 * float(np.sum(_cot(angles))) for angles in opposite]
    # a right angle's cotangent is round-off (~1e-17), not a negative weight
    tiny = 1e-12 * max((abs(w) for w in weights), default=0.0)
    for j, angles, w in zip(ring, opposite, weights, strict=True):
        neighbours.append(
            NeighbourTerm(
                index=int(j),
                edge_length=float(np.linalg.norm(V[j] - x_i)),
                alpha=float(angles[0]),
                beta=float(angles[1]) if len(angles) > 1 else None,
                weight_cotan=w,
                weight_uniform=1.0 / len(ring),
                contribution=w * (V[j] - x_i),
                negative=w < -tiny,
            )
        )
    faces = [
        FaceTerm(
            face=int(f),
            angle=float(ang[k, 0]),
            area=float(face_area[k]),
            obtuse=bool(obtuse[k]),
            obtuse_at_vertex=bool(at_i[k]),
            share_barycentric=float(face_area[k] / 3),
            share_voronoi=float(share_v[k]),
        )
        for k, f in enumerate(rows)
    ]
    return _vertex_terms(
        V, i, ring, neighbours, faces, ang, face_normal, area, boundary, fans, manifold
    )


def _ring_and_fans(F: IntArray, n: int, i: int, nbr: IntArray) -> tuple[list[int], list[Fan], bool]:
    """Neighbours of ``i`` in ring order (fan after fan), its fans, and whether it is manifold.

    The ring comes from the global one-ring code (:func:`meshlap_core.topology.one_ring`) run on
    the vertex's own faces, so it costs O(valence) on any mesh; fan face indices refer to ``F``.
    """
    rows = np.flatnonzero((F == i).any(axis=1))
    rings = one_ring(F[rows], n)
    fans = [Fan(f.neighbors, rows[f.faces], f.closed) for f in rings.fans(i)]
    order: list[int] = []
    for f in fans:
        order += [int(j) for j in f.neighbors if int(j) not in order]
    rest = sorted(int(j) for j in set(nbr.tolist()) - set(order))  # corners in no fan
    return order + rest, fans, bool(rings.manifold[i])


def _vertex_terms(
    V: FloatArray,
    i: int,
    ring: list[int],
    neighbours: list[NeighbourTerm],
    faces: list[FaceTerm],
    ang: FloatArray,
    face_normal: FloatArray,
    area: str,
    boundary: str,
    fans: list[Fan],
    manifold: bool,
) -> VertexInspection:
    """The vertex quantities from the per-neighbour and per-face terms."""
    x_i = V[i]
    a_bary = float(sum(f.share_barycentric for f in faces))
    a_vor = float(sum(f.share_voronoi for f in faces))
    A = a_vor if area == "voronoi" else a_bary
    nsum = np.sum(ang[:, :1] * face_normal, axis=0)
    norm = float(np.linalg.norm(nsum))
    normal = nsum / norm if norm > 1e-300 else np.zeros(3)
    lap_u = np.mean(V[ring] - x_i, axis=0)
    csum = np.sum([t.contribution for t in neighbours], axis=0)
    lap_c = csum / A if A > 0 else np.zeros(3)
    on_boundary = any(t.beta is None for t in neighbours)
    theta_sum = float(np.sum(ang[:, 0]))
    if on_boundary and boundary == "zero":
        deficit = 0.0
    else:
        theta0 = np.pi if (on_boundary and boundary == "pi") else 2 * np.pi
        deficit = float(theta0 - theta_sum)
    K = deficit / A if A > 0 else 0.0
    H_c = -0.5 * float(lap_c @ normal)
    r = math.sqrt(max(H_c * H_c - K, 0.0))
    return VertexInspection(
        vertex=i,
        position=x_i.copy(),
        boundary=on_boundary,
        manifold=manifold,
        area_kind=area,
        boundary_rule=boundary,
        neighbors=neighbours,
        faces=faces,
        area_barycentric=a_bary,
        area_voronoi=a_vor,
        normal=normal,
        laplacian_uniform=lap_u,
        laplacian_cotan=lap_c,
        H_uniform=-0.5 * float(lap_u @ normal),
        H_cotan=H_c,
        angle_sum=theta_sum,
        angle_deficit=deficit,
        K=K,
        k1=H_c + r,
        k2=H_c - r,
        fans=fans,
    )


def _num(x: float) -> str:
    """Four significant digits; round-off below 1e-12 of 1 shown as 0."""
    return "0" if abs(x) < 1e-12 else f"{x:.4g}"


def _vec(x: FloatArray) -> str:
    return "(" + ", ".join(_num(float(c)) for c in x) + ")"


def format_inspection(r: VertexInspection) -> str:
    """The inspection as text: one line per quantity, its formula with the numbers substituted.

    Angles are in degrees; negative cotangent weights are marked ``NEGATIVE (obtuse)``.
    """
    deg = math.degrees
    lines = [
        f"vertex {r.vertex} at {_vec(r.position)}"
        + (", boundary" if r.boundary else "")
        + ("" if r.manifold else f", NON-MANIFOLD: {len(r.fans)} fans"),
        *(
            f"  fan {k + 1} ({'closed' if f.closed else 'open'}): {[int(j) for j in f.neighbors]}"
            for k, f in enumerate(r.fans)
            if not r.manifold
        ),
        f"neighbours in ring order (|N(i)| = {len(r.neighbors)}):",
        "   j   |x_j - x_i|   alpha     beta    w_ij = 1/2(cot a + cot b)    1/|N|"
        "   w_ij (x_j - x_i)",
    ]
    for t in r.neighbors:
        beta = "   -   " if t.beta is None else f"{deg(t.beta):7.2f}"
        cot_b = "" if t.beta is None else f" + cot {deg(t.beta):.2f}°"
        flag = "  NEGATIVE (obtuse)" if t.negative else ""
        lines.append(
            f"{t.index:5d}  {t.edge_length:10.4g}  {deg(t.alpha):7.2f}  {beta}  "
            f"1/2(cot {deg(t.alpha):.2f}°{cot_b}) = {_num(t.weight_cotan):>9}  "
            f"{t.weight_uniform:6.4f}   {_vec(t.contribution)}{flag}"
        )
    lines.append("incident faces:")
    lines.append("   face   theta_f     area     obtuse   A/3       Voronoi share")
    for f in r.faces:
        rule = (
            "A/2 (obtuse at i)" if f.obtuse_at_vertex else ("A/4" if f.obtuse else "1/8 Σ l² cot")
        )
        lines.append(
            f"{f.face:7d}  {deg(f.angle):7.2f}°  {f.area:9.4g}  {'yes' if f.obtuse else 'no ':>5}  "
            f"{f.share_barycentric:9.4g}  {f.share_voronoi:9.4g} ({rule})"
        )
    A = r.area
    theta0 = {"pi": "π", "2pi": "2π", "zero": "—"}[r.boundary_rule] if r.boundary else "2π"
    n_dot = float(r.laplacian_cotan @ r.normal)
    lines += [
        f"A_i barycentric = Σ A_f/3 = {_num(r.area_barycentric)};  "
        f"A_i Voronoi = Σ shares = {_num(r.area_voronoi)}  (using {r.area_kind})",
        f"n = Σ θ_f n_f / |Σ θ_f n_f| = {_vec(r.normal)}",
        f"Δ_uniform x = 1/{len(r.neighbors)} Σ (x_j − x_i) = {_vec(r.laplacian_uniform)}",
        f"Δ_cotan x = (1/A_i) Σ w_ij (x_j − x_i) = (1/{_num(A)}) · "
        f"{_vec(r.laplacian_cotan * A)} = {_vec(r.laplacian_cotan)}",
        f"H_uniform = −½ Δ_uniform x · n = −½ · {_num(float(r.laplacian_uniform @ r.normal))}"
        f" = {_num(r.H_uniform)}",
        f"H_cotan = −½ Δ_cotan x · n = −½ · {_num(n_dot)} = {_num(r.H_cotan)}",
        f"Σθ = {math.degrees(r.angle_sum):.4f}°;  deficit = {theta0} − Σθ = "
        f"{_num(r.angle_deficit)} rad"
        + (f" (boundary rule {r.boundary_rule})" if r.boundary else ""),
        f"K = deficit / A_i = {_num(r.angle_deficit)} / {_num(A)} = {_num(r.K)}",
        f"κ₁,₂ = H ± √max(H² − K, 0) = {_num(r.H_cotan)} ± "
        f"√max({_num(r.H_cotan**2)} − {_num(r.K)}, 0) = {_num(r.k1)}, {_num(r.k2)}",
    ]
    return "\n".join(lines)
