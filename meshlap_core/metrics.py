"""Geometric error metrics for smoothing and denoising: RMSE, enclosed volume, dihedral angles,
face normal deviation, per-vertex error maps.

Every comparison assumes the two meshes share connectivity (same ``F``, same vertex order), as
``fandisk.obj`` and ``fandisk_ns.obj`` do. Volumes are only defined for closed meshes (no
boundary edge); for open meshes the functions say so (``None`` plus a reason) instead of
returning a number that would look meaningful.

No Laplacian is used here (the sign convention of the project, Δ negative semidefinite, does
not enter).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import MeshError
from .topology import EdgeTable
from .types import FloatArray, IntArray, as_faces, as_mesh, as_vertices


def _same_shape(V: FloatArray, V_ref: FloatArray) -> None:
    if V.shape != V_ref.shape:
        raise MeshError(
            f"has {len(V)} vertices but the reference has {len(V_ref)}: "
            "metrics need the same connectivity and vertex order",
            "V",
        )


# --------------------------------------------------------------------------- positions


def vertex_errors(V: FloatArray, V_ref: FloatArray) -> FloatArray:
    """Per-vertex Euclidean distance to the reference, for error maps.

    Parameters
    ----------
    V, V_ref : (n,3) float
        Same vertex order.

    Returns
    -------
    e : (n,) float
        ``e_i = |V_i − V_ref_i|``.
    """
    V, V_ref = as_vertices(V), as_vertices(V_ref, "V_ref")
    _same_shape(V, V_ref)
    return np.sqrt(np.sum((V - V_ref) ** 2, axis=1))


def rmse(V: FloatArray, V_ref: FloatArray) -> float:
    """Root-mean-square vertex distance ``sqrt(mean_i |V_i − V_ref_i|²)``.

    Parameters
    ----------
    V, V_ref : (n,3) float

    Returns
    -------
    float
        0 for identical positions; in the mesh's length unit.

    Examples
    --------
    >>> from meshlap_core import rmse
    >>> rmse([[0, 0, 0], [1, 1, 1]], [[3, 4, 0], [4, 5, 1]])  # both points moved by 5
    5.0
    """
    e = vertex_errors(V, V_ref)
    return float(np.sqrt(np.mean(e**2))) if e.size else 0.0


def max_error(V: FloatArray, V_ref: FloatArray) -> float:
    """Largest per-vertex distance ``max_i |V_i − V_ref_i|`` (0 for an empty mesh)."""
    e = vertex_errors(V, V_ref)
    return float(e.max()) if e.size else 0.0


# --------------------------------------------------------------------------- volume


def n_boundary_edges(F: IntArray) -> int:
    """Number of undirected edges used by exactly one face."""
    return int(np.count_nonzero(EdgeTable.from_faces(F).counts == 1))


def is_closed(F: IntArray) -> bool:
    """``True`` when the mesh has faces and no boundary edge (every edge in ≥ 2 faces)."""
    F = as_faces(F)
    return len(F) > 0 and n_boundary_edges(F) == 0


def signed_volume(V: FloatArray, F: IntArray) -> float:
    """Signed enclosed volume by the divergence theorem.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
        Closed, consistently oriented; positive for outward normals.

    Returns
    -------
    float

    Notes
    -----
    ``vol = (1/6) Σ_f a_f · (b_f × c_f)`` (the divergence theorem applied to ``x/3``, summed over
    the tetrahedra the faces span with the origin). The value does not depend on the origin only
    when the mesh is closed; use :func:`enclosed_volume` for the checked version.
    """
    V, F = as_mesh(V, F)
    return signed_volume_unchecked(V, F)


VOLUME_CHUNK = 8192
"""Faces per block of :func:`signed_volume_unchecked`: the block's gathered coordinates and
products stay in the cache (at 692k vertices 45 instead of 75 ms of CPU per call, which runs
after every smoothing step)."""


def signed_volume_unchecked(V: FloatArray, F: IntArray, FT: IntArray | None = None) -> float:
    """Divergence-theorem volume without checks; ``FT`` is an optional ``(3,m)`` copy of ``F.T``.

    The divergence theorem on the field ``(0, 0, z)``: ``vol = Σ_f (z_a + z_b + z_c) ·
    ((b − a) × (c − a))_z / 6`` (the same value as ``Σ_f a · (b × c) / 6`` on a closed mesh,
    with six gathers and no cross product), over blocks of :data:`VOLUME_CHUNK` faces.
    """
    X, Y, Z = np.ascontiguousarray(V.T)
    i_all, j_all, k_all = np.ascontiguousarray(F.T) if FT is None else FT
    total = 0.0
    for s in range(0, len(i_all), VOLUME_CHUNK):
        i, j, k = (
            i_all[s : s + VOLUME_CHUNK],
            j_all[s : s + VOLUME_CHUNK],
            k_all[s : s + VOLUME_CHUNK],
        )
        xa, ya = X.take(i), Y.take(i)
        u = X.take(j)
        u -= xa
        v = Y.take(k)
        v -= ya
        u *= v  # (xb − xa)(yc − ya)
        w = Y.take(j)
        w -= ya
        v = X.take(k)
        v -= xa
        w *= v  # (yb − ya)(xc − xa)
        u -= w
        z = Z.take(i)
        z += Z.take(j)
        z += Z.take(k)
        total += float(np.dot(u, z))
    return total / 6.0


def enclosed_volume(V: FloatArray, F: IntArray) -> tuple[float | None, str | None]:
    """Enclosed volume of a closed mesh, or ``None`` and the reason it is undefined.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    volume : float or None
        Signed volume (divergence theorem, see :func:`signed_volume`), ``None`` for open meshes.
    reason : str or None
        Why the volume is undefined (``None`` when it is defined).
    """
    V, F = as_mesh(V, F)
    reason = volume_undefined_reason(F)
    if reason is not None:
        return None, reason
    return signed_volume_unchecked(V, F), None


def volume_undefined_reason(F: IntArray) -> str | None:
    """``None`` for a closed mesh, otherwise a sentence saying why it encloses no volume."""
    F = as_faces(F)
    if len(F) == 0:
        return "undefined: the mesh has no faces"
    nb = n_boundary_edges(F)
    if nb:
        return f"undefined: the mesh is open ({nb} boundary edges), so it encloses no volume"
    return None


def percent_volume_change(volume: float, volume_ref: float) -> float | None:
    """Change of the enclosed volume in percent, ``100 (|v| − |v_ref|) / |v_ref|``.

    The enclosed volume of a closed mesh is the absolute value of its signed (divergence
    theorem) volume, so an inward-oriented mesh that shrinks gives a negative change, as an
    outward one does.

    Parameters
    ----------
    volume, volume_ref : float
        Signed volumes (:func:`signed_volume`) of the mesh and of the reference.

    Returns
    -------
    float or None
        ``None`` when the reference volume is 0.
    """
    if volume_ref == 0.0:
        return None
    return 100.0 * (abs(volume) - abs(volume_ref)) / abs(volume_ref)


def volume_change_pct(
    V: FloatArray, V_ref: FloatArray, F: IntArray
) -> tuple[float | None, str | None]:
    """Percentage change of the enclosed volume, ``100 (|vol(V)| − |vol(V_ref)|) / |vol(V_ref)|``
    (see :func:`percent_volume_change`; the sign says whether the enclosed volume grew, whatever
    the orientation of the faces).

    Parameters
    ----------
    V, V_ref : (n,3) float
        Same connectivity ``F``.
    F : (m,3) int

    Returns
    -------
    pct : float or None
        ``None`` when the mesh is open (volume undefined) or the reference volume is 0.
    reason : str or None
    """
    V, F = as_mesh(V, F)
    V_ref = as_vertices(V_ref, "V_ref")
    _same_shape(V, V_ref)
    reason = volume_undefined_reason(F)
    if reason is not None:
        return None, reason
    pct = percent_volume_change(signed_volume_unchecked(V, F), signed_volume_unchecked(V_ref, F))
    if pct is None:
        return None, "undefined: the reference volume is 0"
    return pct, None


# --------------------------------------------------------------------------- normals, dihedrals


def face_normals(V: FloatArray, F: IntArray) -> FloatArray:
    """Unit face normals ``(b−a)×(c−a)/|·|``; rows of degenerate faces are NaN.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    N : (m,3) float
    """
    V, F = as_mesh(V, F)
    return _unit_face_normals(V, F)


def _unit_face_normals(V: FloatArray, F: IntArray) -> FloatArray:
    a = V[F[:, 0]]
    N = np.cross(V[F[:, 1]] - a, V[F[:, 2]] - a)
    length = np.linalg.norm(N, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(length > 0, N / np.where(length > 0, length, 1.0), np.nan)


def _angle_between(A: FloatArray, B: FloatArray) -> FloatArray:
    """Angle between row vectors (radians, in [0, π]); robust near 0 and π."""
    return np.arctan2(np.linalg.norm(np.cross(A, B), axis=1), np.einsum("ij,ij->i", A, B))


@dataclass(frozen=True)
class EdgeFaces:
    """The interior manifold edges of a mesh and the two faces on each.

    Attributes
    ----------
    edges : (k,2) int
        ``(a, b)`` as directed in ``faces[:, 0]`` (the first face has ``a → b`` in its winding).
    faces : (k,2) int
        The two faces sharing the edge.
    consistent : (k,) bool
        ``True`` when the second face runs ``b → a`` (orientations agree).

    Boundary edges (one face) and non-manifold edges (three or more) are left out.
    """

    edges: IntArray
    faces: IntArray
    consistent: np.ndarray


def edge_faces(F: IntArray) -> EdgeFaces:
    """Interior manifold edges with their two faces, in a fixed order (sorted by edge).

    The order depends on ``F`` only, so two meshes with the same faces get the same edge list.

    Parameters
    ----------
    F : (m,3) int

    Returns
    -------
    EdgeFaces
    """
    t = EdgeTable.from_faces(F)
    m = len(t.F)
    _, h1, h2 = t.face_pairs()
    # the first face is the one whose half-edge comes first in corner-column order (k m + f)
    swap = (h1 % 3) * m + h1 // 3 > (h2 % 3) * m + h2 // 3
    h1, h2 = np.where(swap, h2, h1), np.where(swap, h1, h2)
    src, dst = t.halfedge_vertices()
    edges = np.stack([src[h1], dst[h1]], axis=1)
    faces = np.stack([h1 // 3, h2 // 3], axis=1)
    return EdgeFaces(edges, faces, src[h2] == dst[h1])


def dihedral_angles(V: FloatArray, F: IntArray, adjacency: EdgeFaces | None = None) -> FloatArray:
    """Interior dihedral angle of every interior manifold edge, in radians, in ``(0, 2π)``.

    π on a flat edge, below π on a convex edge, above π on a concave (reflex) edge, for outward
    oriented faces. A cube has π/2 on its 12 edges and π on its face diagonals.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    adjacency : EdgeFaces, optional
        ``edge_faces(F)``, to reuse across many calls on meshes with the same faces.

    Returns
    -------
    theta : (k,) float
        In the edge order of ``adjacency``; NaN where a face is degenerate.

    Notes
    -----
    With unit normals ``n1, n2`` of the two faces and ``e`` the unit edge direction in the first
    face's winding, the signed bending angle is ``φ = atan2((n1 × n2)·e, n1·n2)`` (positive on a
    convex edge) and the dihedral angle is ``π − φ``. If the second face is oriented against the
    first, its normal is flipped first.
    """
    V, F = as_mesh(V, F)
    adj = edge_faces(F) if adjacency is None else adjacency
    return _dihedral_unchecked(V, F, adj)


def _dihedral_unchecked(V: FloatArray, F: IntArray, adj: EdgeFaces) -> FloatArray:
    if len(adj.edges) == 0:
        return np.zeros(0)
    N = _unit_face_normals(V, F)
    n1 = N[adj.faces[:, 0]]
    n2 = N[adj.faces[:, 1]] * np.where(adj.consistent, 1.0, -1.0)[:, None]
    e = V[adj.edges[:, 1]] - V[adj.edges[:, 0]]
    with np.errstate(invalid="ignore", divide="ignore"):
        e = e / np.linalg.norm(e, axis=1, keepdims=True)
    phi = np.arctan2(np.einsum("ij,ij->i", np.cross(n1, n2), e), np.einsum("ij,ij->i", n1, n2))
    return np.pi - phi


def dihedral_histogram(theta: FloatArray, bins: int = 36) -> tuple[np.ndarray, FloatArray]:
    """Histogram of dihedral angles in degrees over ``[0, 360]``.

    Parameters
    ----------
    theta : (k,) float
        Radians, as returned by :func:`dihedral_angles` (NaNs are ignored).
    bins : int
        Number of equal bins.

    Returns
    -------
    counts : (bins,) int
    edges_deg : (bins+1,) float
    """
    if bins < 1:
        raise MeshError("must be >= 1", "bins")
    t = np.degrees(np.asarray(theta, dtype=np.float64))
    t = t[np.isfinite(t)]
    counts, edges = np.histogram(t, bins=bins, range=(0.0, 360.0))
    return counts, edges


def _wrapped_abs_diff(a: FloatArray, b: FloatArray) -> FloatArray:
    d = np.mod(a - b + np.pi, 2 * np.pi) - np.pi
    return np.abs(d)


def dihedral_mae_deg(
    V: FloatArray, V_ref: FloatArray, F: IntArray, adjacency: EdgeFaces | None = None
) -> float:
    """Mean absolute difference of the dihedral angles to the reference, in degrees.

    Parameters
    ----------
    V, V_ref : (n,3) float
    F : (m,3) int
    adjacency : EdgeFaces, optional

    Returns
    -------
    float
        Over interior edges whose faces are non-degenerate in both meshes (NaN if none).
    """
    V, F = as_mesh(V, F)
    V_ref = as_vertices(V_ref, "V_ref")
    _same_shape(V, V_ref)
    adj = edge_faces(F) if adjacency is None else adjacency
    d = _wrapped_abs_diff(_dihedral_unchecked(V, F, adj), _dihedral_unchecked(V_ref, F, adj))
    d = d[np.isfinite(d)]
    return float(np.degrees(d.mean())) if d.size else float("nan")


def normal_deviation_deg(V: FloatArray, V_ref: FloatArray, F: IntArray) -> float:
    """Mean angle between corresponding unit face normals, in degrees.

    Parameters
    ----------
    V, V_ref : (n,3) float
    F : (m,3) int

    Returns
    -------
    float
        Over faces non-degenerate in both meshes (NaN if none).
    """
    V, F = as_mesh(V, F)
    V_ref = as_vertices(V_ref, "V_ref")
    _same_shape(V, V_ref)
    a = _angle_between(_unit_face_normals(V, F), _unit_face_normals(V_ref, F))
    a = a[np.isfinite(a)]
    return float(np.degrees(a.mean())) if a.size else float("nan")


# --------------------------------------------------------------------------- many comparisons


@dataclass
class Reference:
    """A clean reference mesh, precomputed for many comparisons (sweeps, live viewers).

    Parameters
    ----------
    V : (n,3) float
        Clean positions.
    F : (m,3) int
        Faces shared by every compared mesh.

    Examples
    --------
    >>> ref = Reference(V_clean, F)          # doctest: +SKIP
    >>> ref.compare(V_smoothed)["rmse"]      # doctest: +SKIP
    """

    V: FloatArray
    F: IntArray
    adjacency: EdgeFaces = field(init=False)
    volume: float | None = field(init=False)
    volume_reason: str | None = field(init=False)
    dihedral: FloatArray = field(init=False)
    normals: FloatArray = field(init=False)

    def __post_init__(self) -> None:
        self.V, self.F = as_mesh(self.V, self.F)
        self.adjacency = edge_faces(self.F)
        self.volume, self.volume_reason = enclosed_volume(self.V, self.F)
        self.dihedral = _dihedral_unchecked(self.V, self.F, self.adjacency)
        self.normals = _unit_face_normals(self.V, self.F)

    def compare(self, V: FloatArray) -> dict[str, Any]:
        """All metrics of ``V`` against the reference.

        Returns
        -------
        dict
            ``rmse``, ``max_error``, ``volume`` and ``volume_change_pct`` (``None`` for open
            meshes, with ``volume_note``), ``dihedral_mae_deg``, ``normal_dev_deg``.
        """
        V = as_vertices(V)
        _same_shape(V, self.V)
        e = np.sqrt(np.sum((V - self.V) ** 2, axis=1))
        out: dict[str, Any] = {
            "rmse": float(np.sqrt(np.mean(e**2))) if e.size else 0.0,
            "max_error": float(e.max()) if e.size else 0.0,
        }
        if self.volume is None or self.volume == 0.0:
            out["volume"] = None
            out["volume_change_pct"] = None
            out["volume_note"] = self.volume_reason or "undefined: the reference volume is 0"
        else:
            vol = signed_volume_unchecked(V, self.F)
            out["volume"] = vol
            out["volume_change_pct"] = percent_volume_change(vol, self.volume)
        d = _wrapped_abs_diff(_dihedral_unchecked(V, self.F, self.adjacency), self.dihedral)
        d = d[np.isfinite(d)]
        out["dihedral_mae_deg"] = float(np.degrees(d.mean())) if d.size else float("nan")
        a = _angle_between(_unit_face_normals(V, self.F), self.normals)
        a = a[np.isfinite(a)]
        out["normal_dev_deg"] = float(np.degrees(a.mean())) if a.size else float("nan")
        return out
