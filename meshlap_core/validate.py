"""The one mesh validator: fatal problems raise, repairable ones are repaired *and reported*.

:func:`validate_mesh` turns raw arrays (or polygon lists) into a :class:`Mesh` whose ``V`` is
``(n,3) float64`` and ``F`` is ``(m,3) int64``, with a :class:`MeshReport` saying what was
repaired and what was found. Every loader in :mod:`meshlap_core.io` goes through it.

Fatal (raise :class:`~meshlap_core.errors.MeshError`): no vertices, no faces, NaN/inf or huge
coordinates, indices out of range, faces with fewer than 3 corners, all faces degenerate.

Repaired (when ``repair=True``) and listed in ``report.repairs``: polygons triangulated (fan),
degenerate faces removed (a repeated corner or zero area), duplicate faces removed (same three
vertices in any order), unreferenced vertices removed. ``Mesh.vertex_map`` /
``Mesh.face_map`` relate the result to the input.

Detected, never repaired (``report.warnings`` and fields): non-manifold edges (more than two
faces), non-manifold vertices (the faces around the vertex form more than one fan),
inconsistent orientation. :func:`require_manifold` turns those into an error for operations that
need a manifold.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from .errors import MeshError
from .mesh import Mesh, MeshReport, Polygons
from .mesh import count_phrase as _count
from .options import DEGENERATE_REL, MAX_COORDINATE, MIN_EXTENT, SLIVER_ANGLE
from .topology import sort_with_order as _sort_with_order
from .topology import topology_report, topology_report_with_table
from .types import BoolArray, FloatArray, IntArray, exact_indices, real_array

__all__ = [
    "SLIVER_ANGLE",
    "Mesh",
    "MeshReport",
    "Polygons",
    "degenerate_faces",
    "duplicate_faces",
    "duplicate_positions",
    "require_manifold",
    "sliver_faces",
    "topology_report",
    "validate_mesh",
]


def require_manifold(mesh_or_F: Mesh | Any, operation: str, source: str | None = None) -> None:
    """Raise unless the mesh is edge-manifold and consistently oriented.

    Parameters
    ----------
    mesh_or_F : Mesh or (m,3) int
        A validated :class:`Mesh` (its report is reused) or a triangle list.
    operation : str
        What needs the manifold, e.g. ``"mean curvature flow"``; starts the message.
    source : str, optional
        File or argument named in the error (default: the mesh's source).

    Raises
    ------
    MeshError
        ``"<operation> needs an edge-manifold, consistently oriented mesh; this one has N
        non-manifold edges and K inconsistently oriented edges"``.
    """
    if isinstance(mesh_or_F, Mesh):
        rep = mesh_or_F.report
        source = source if source is not None else mesh_or_F.source
    else:
        rep = topology_report(mesh_or_F)
    problems = []
    if rep.n_nonmanifold_edges:
        problems.append(_count(rep.n_nonmanifold_edges, "non-manifold edge"))
    if not rep.consistently_oriented:
        problems.append(_count(rep.n_inconsistent_edges, "inconsistently oriented edge"))
    if problems:
        raise MeshError(
            f"{operation} needs an edge-manifold, consistently oriented mesh; this one has "
            + " and ".join(problems),
            source,
        )


# --------------------------------------------------------------------------------------------
# validation


def _coerce_vertices(V: Any, label: str, vertex_map: IntArray) -> FloatArray:
    raw = real_array(V, label, "vertex coordinates")  # no bool, complex or string cast
    try:
        arr = np.array(raw, dtype=np.float64, copy=True, order="C")
    except (TypeError, ValueError) as exc:
        raise MeshError(f"vertex coordinates are not numbers ({exc})", label) from None
    if arr.size == 0:
        raise MeshError("the mesh has no vertices", label)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise MeshError(f"vertices should have shape (n,3); shape is {arr.shape}", label)
    finite = np.isfinite(arr)
    if not finite.all():
        i = int(np.flatnonzero(~finite.all(axis=1))[0])
        raise MeshError(
            f"vertex {int(vertex_map[i])} has a NaN or infinite coordinate "
            f"({', '.join(repr(float(x)) for x in arr[i])})",
            label,
        )
    big = np.abs(arr).max(axis=1)
    if big.max() > MAX_COORDINATE:
        i = int(np.argmax(big))
        raise MeshError(
            f"vertex {int(vertex_map[i])} has coordinate {float(big[i]):.3g}; coordinates beyond "
            f"±{MAX_COORDINATE:.0e} overflow squared-length computations (rescale the mesh)",
            label,
        )
    diag = float(np.sqrt(np.sum((arr.max(axis=0) - arr.min(axis=0)) ** 2)))
    if 0.0 < diag < MIN_EXTENT:
        raise MeshError(
            f"the mesh is too small: its bounding-box diagonal is {diag:.3g}; below "
            f"{MIN_EXTENT:.0e} squared-length computations underflow (rescale the mesh)",
            label,
        )
    return arr


def _coerce_faces(F: Any, label: str) -> tuple[IntArray, IntArray | None]:
    """Return ``(flat_or_triangles, sizes)``; ``sizes is None`` means an ``(m,3)`` array."""
    if isinstance(F, Polygons):
        flat = np.asarray(F.indices, dtype=np.int64).ravel()
        sizes = np.asarray(F.sizes, dtype=np.int64).ravel()
        if int(sizes.sum()) != len(flat):
            raise MeshError("polygon sizes do not add up to the number of indices", label)
        return flat, sizes
    if isinstance(F, np.ndarray) or (isinstance(F, Sequence) and len(F) and not _is_ragged(F)):
        raw = np.asarray(F)
        if raw.size == 0:
            return np.zeros((0, 3), dtype=np.int64), None
        if raw.ndim != 2:
            raise MeshError(f"faces should have shape (m,k); shape is {raw.shape}", label)
        if raw.dtype.kind == "f":
            ok = np.isfinite(raw) & (np.mod(raw, 1) == 0)
            if not ok.all():
                f = int(np.flatnonzero(~ok.all(axis=1))[0])
                raise MeshError(f"face {f} has a non-integer index {raw[f].tolist()}", label)
        arr = exact_indices(raw, label)  # checked before the cast: no wrap, no truncation
        if arr.shape[1] == 3:
            return arr.copy(), None
        return arr.ravel().copy(), np.full(len(arr), arr.shape[1], dtype=np.int64)
    if not isinstance(F, Sequence):
        raise MeshError(f"faces must be an array or a list of index lists, got {type(F)}", label)
    if len(F) == 0:
        return np.zeros((0, 3), dtype=np.int64), None
    sizes = np.fromiter((len(f) for f in F), dtype=np.int64, count=len(F))
    try:
        flat = np.concatenate([np.asarray(f).ravel() for f in F]) if sizes.sum() else np.zeros(0)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"faces are not integer index lists ({exc})", label) from None
    if flat.dtype.kind == "f" and not np.all(np.mod(flat, 1) == 0):
        raise MeshError("face indices must be integers", label)
    return exact_indices(flat, label), sizes


def _is_ragged(F: Sequence) -> bool:
    try:
        first = len(F[0])
    except TypeError:
        return False
    return any(len(f) != first for f in F)


def _fan_triangulate(flat: IntArray, sizes: IntArray) -> tuple[IntArray, IntArray]:
    """Fan triangles ``(p0, p_j, p_{j+1})`` of each polygon, and the polygon of each triangle."""
    ntri = sizes - 2
    poly = np.repeat(np.arange(len(sizes)), ntri)
    offsets = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    tri_start = np.concatenate([[0], np.cumsum(ntri)[:-1]])
    j = np.arange(int(ntri.sum())) - np.repeat(tri_start, ntri) + 1
    o = offsets[poly]
    T = np.stack([flat[o], flat[o + j], flat[o + j + 1]], axis=1)
    return T, poly


def _face_measures(
    V: FloatArray, F: IntArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Twice the area and the three squared edge lengths of every face (column arrays)."""
    X, Y, Z = (np.ascontiguousarray(V[:, d]) for d in range(3))
    i, j, k = F[:, 0], F[:, 1], F[:, 2]
    ax, ay, az = X[i], Y[i], Z[i]
    ux, uy, uz = X[j] - ax, Y[j] - ay, Z[j] - az  # b - a
    vx, vy, vz = X[k] - ax, Y[k] - ay, Z[k] - az  # c - a
    cx, cy, cz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    dbl = np.sqrt(cx * cx + cy * cy + cz * cz)  # twice the area
    wx, wy, wz = vx - ux, vy - uy, vz - uz  # c - b
    a = wx * wx + wy * wy + wz * wz  # opposite corner 0
    b = vx * vx + vy * vy + vz * vz  # opposite corner 1
    c = ux * ux + uy * uy + uz * uz  # opposite corner 2
    return dbl, a, b, c


def _degenerate_from(
    F: IntArray, dbl: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray
) -> tuple[BoolArray, BoolArray]:
    repeated = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 0] == F[:, 2])
    zero = (dbl <= DEGENERATE_REL * (a + b + c)) & ~repeated
    return repeated, zero


def _sliver_from(
    dbl: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray, min_angle: float
) -> BoolArray:
    hi = np.maximum(np.maximum(a, b), c)
    lo = np.minimum(np.minimum(a, b), c)
    mid = a + b + c - hi - lo  # accurate: hi <= 4 mid by the triangle inequality
    return dbl < np.sin(min_angle) * np.sqrt(hi * mid)


def _face_flags(
    V: FloatArray, F: IntArray, chunk: int = 1 << 18
) -> tuple[BoolArray, BoolArray, BoolArray]:
    """Repeated-corner, zero-area and sliver masks, computed ``chunk`` faces at a time (the
    per-face temporaries of :func:`_face_measures` stay a few MB whatever the mesh size)."""
    m = len(F)
    repeated = np.empty(m, dtype=bool)
    zero = np.empty(m, dtype=bool)
    sliver = np.empty(m, dtype=bool)
    for s in range(0, m, chunk):
        Fc = F[s : s + chunk]
        measures = _face_measures(V, Fc)
        repeated[s : s + chunk], zero[s : s + chunk] = _degenerate_from(Fc, *measures)
        sliver[s : s + chunk] = _sliver_from(*measures, SLIVER_ANGLE)
    return repeated, zero, sliver


def degenerate_faces(V: FloatArray, F: IntArray) -> tuple[BoolArray, BoolArray]:
    """Faces with a repeated corner, and faces of zero area (collinear up to round-off).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int

    Returns
    -------
    repeated : (m,) bool
        Two corners share a vertex index.
    zero_area : (m,) bool
        Distinct corners but ``|(b-a)×(c-a)| ≤ 0.5e-12 (l₀² + l₁² + l₂²)`` (the threshold
        below which the cotangent Laplacian zeroes a face's weights).
    """
    return _degenerate_from(F, *_face_measures(V, F))


def sliver_faces(V: FloatArray, F: IntArray, min_angle: float = SLIVER_ANGLE) -> BoolArray:
    """Nearly degenerate faces: smallest corner angle below ``min_angle`` (needles and caps).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    min_angle : float
        In radians (default :data:`SLIVER_ANGLE` = 1e-4).

    Returns
    -------
    sliver : (m,) bool
        Zero-area faces (see :func:`degenerate_faces`) are slivers too.

    Notes
    -----
    The smallest angle ``θ`` is opposite the shortest edge, and ``sin θ = 2A / (l_a l_b)`` with
    ``l_a, l_b`` the two longer edges, so the test is ``2A < sin(min_angle) · l_a l_b`` (no
    trigonometry per face). A needle (one short edge) has one such angle, a cap (one angle near
    π) two; the cotangent of the angle, about ``1/θ``, is the weight the cotangent Laplacian puts
    on the opposite edge.
    """
    if len(F) == 0:
        return np.zeros(0, dtype=bool)
    return _sliver_from(*_face_measures(V, F), min_angle)


def duplicate_positions(V: FloatArray) -> BoolArray:
    """Vertices at exactly the same position as an earlier vertex (cracks, unwelded seams).

    Parameters
    ----------
    V : (n,3) float

    Returns
    -------
    dup : (n,) bool
        True for every vertex but the first at each repeated position.

    Notes
    -----
    One 64-bit hash per vertex is sorted (``-0.0`` and ``0.0`` are the same position); only
    equal hashes are compared coordinate by coordinate, so the cost is one sort of ``n`` keys.
    """
    n = len(V)
    if n < 2:
        return np.zeros(n, dtype=bool)
    bits = np.ascontiguousarray(V + 0.0).view(np.uint64)
    with np.errstate(over="ignore"):
        h = (
            bits[:, 0] * np.uint64(0x9E3779B97F4A7C15)
            ^ bits[:, 1] * np.uint64(0xC2B2AE3D27D4EB4F)
            ^ bits[:, 2] * np.uint64(0x165667B19E3779F9)
        )
    order = np.argsort(h, kind="stable")
    hs = h[order]
    cand = np.flatnonzero(hs[1:] == hs[:-1])
    dup = np.zeros(n, dtype=bool)
    if len(cand) == 0:
        return dup
    # exact check of candidate groups (a hash collision of different positions is possible)
    idx = np.unique(np.concatenate([order[cand], order[cand + 1]]))
    _, first = np.unique(V[idx] + 0.0, axis=0, return_index=True)
    keep = np.zeros(len(idx), dtype=bool)
    keep[first] = True  # np.unique's first occurrence in idx order = lowest vertex index
    dup[idx[~keep]] = True
    return dup


def duplicate_faces(F: IntArray, n: int) -> BoolArray:
    """Faces with the same vertex set (any order) as an earlier face.

    Parameters
    ----------
    F : (m,3) int
    n : int
        Number of vertices.

    Returns
    -------
    dup : (m,) bool
        True for every occurrence but the first of each vertex set.
    """
    if len(F) == 0:
        return np.zeros(0, dtype=bool)
    S = np.sort(F, axis=1)
    if n < 2_000_000:  # n^3 < 2^63: one int64 key per face
        key = (S[:, 0] * np.int64(n) + S[:, 1]) * np.int64(n) + S[:, 2]
        order, ks = _sort_with_order(key)
        new = np.empty(len(ks), dtype=bool)
        new[0] = True
        np.not_equal(ks[1:], ks[:-1], out=new[1:])
        if new.all():
            return np.zeros(len(F), dtype=bool)
        # first occurrence in file order = smallest face index of each group
        first = np.minimum.reduceat(order, np.flatnonzero(new))
    else:  # n^3 overflows int64: sort by (S0·n + S1, S2) (np.unique(axis=0) took minutes)
        order = np.lexsort((S[:, 2], S[:, 0] * np.int64(n) + S[:, 1]))
        Ss = S[order]
        new = np.empty(len(Ss), dtype=bool)
        new[0] = True
        np.any(Ss[1:] != Ss[:-1], axis=1, out=new[1:])
        if new.all():
            return np.zeros(len(F), dtype=bool)
        first = np.minimum.reduceat(order, np.flatnonzero(new))
    dup = np.ones(len(F), dtype=bool)
    dup[first] = False
    return dup


def _check_faces(tri_or_flat: IntArray, sizes: IntArray | None, n: int, flabel: str) -> IntArray:
    """Refuse faces with fewer than 3 corners and indices outside ``[0, n)``; the flat indices."""
    if sizes is not None:
        small = np.flatnonzero(sizes < 3)
        if len(small):
            f = int(small[0])
            raise MeshError(
                f"face {f} has {int(sizes[f])} {'corner' if sizes[f] == 1 else 'corners'}; "
                f"a face needs at least 3"
                + (f" ({_count(len(small), 'face')} like this)" if len(small) > 1 else ""),
                flabel,
            )
    flat = tri_or_flat.ravel()
    lo, hi = int(flat.min()), int(flat.max())
    if lo < 0 or hi >= n:
        bad_idx = lo if lo < 0 else hi
        pos = int(np.flatnonzero(flat == bad_idx)[0])
        if sizes is None:
            f = pos // 3
        else:
            f = int(np.searchsorted(np.cumsum(sizes), pos, side="right"))
        raise MeshError(
            f"face {f} has index {bad_idx} but the mesh has {_count(n, 'vertex', 'vertices')} "
            f"(valid indices 0..{n - 1})",
            flabel,
        )

    return flat


def _drop_degenerate(
    V: FloatArray,
    F: IntArray,
    face_map: IntArray,
    repair: bool,
    rep_list: list[str],
    warn_list: list[str],
    flabel: str,
) -> tuple[IntArray, IntArray, BoolArray]:
    """Remove (or, without ``repair``, report) degenerate faces; refuse a mesh of only those.

    Returns the kept faces, their input face indices and their sliver mask.
    """
    repeated, zero, sliver = _face_flags(V, F)
    n_rep, n_zero = int(repeated.sum()), int(zero.sum())
    if n_rep + n_zero == len(F):
        raise MeshError(
            f"all {_count(len(F), 'face')} are degenerate "
            f"({n_rep:,} with a repeated vertex, {n_zero:,} with zero area)",
            flabel,
        )
    if n_rep + n_zero:
        parts = []
        if n_rep:
            parts.append(f"{n_rep:,} with a repeated vertex")
        if n_zero:
            parts.append(f"{n_zero:,} with zero area")
        what = f"{_count(n_rep + n_zero, 'degenerate face')} ({', '.join(parts)})"
        if repair:
            keep = ~(repeated | zero)
            F, face_map, sliver = F[keep], face_map[keep], sliver[keep]
            rep_list.append(f"removed {what}")
        else:
            sliver &= ~(repeated | zero)  # reported as degenerate already
            warn_list.append(f"{what} (not removed: repair=False)")

    return F, face_map, sliver


def _drop_duplicates_and_unused(
    V: FloatArray,
    F: IntArray,
    face_map: IntArray,
    sliver: BoolArray,
    vmap0: IntArray,
    flat: IntArray,
    repair: bool,
    rep_list: list[str],
    warn_list: list[str],
) -> tuple[IntArray, IntArray, BoolArray, FloatArray, IntArray]:
    """Remove (or report) duplicate faces, then unreferenced vertices (``flat`` are the input
    face indices, to tell vertices orphaned by removed faces)."""
    n = len(V)
    dup = duplicate_faces(F, n)
    n_dup = int(dup.sum())
    if n_dup:
        what = (
            f"{_count(n_dup, 'duplicate face')} "
            "(same three vertices as an earlier face, in any order)"
        )
        if repair:
            F, face_map, sliver = F[~dup], face_map[~dup], sliver[~dup]
            rep_list.append(f"removed {what}")
        else:
            warn_list.append(f"{what} (not removed: repair=False)")

    used = np.zeros(n, dtype=bool)
    used[F.ravel()] = True
    n_unused = n - int(used.sum())
    if n_unused:
        if repair:
            used_in_input = np.zeros(n, dtype=bool)
            used_in_input[flat] = True
            orphaned = int(np.count_nonzero(used_in_input & ~used))
            new_index = np.cumsum(used) - 1
            F = new_index[F]
            V = V[used]
            vmap0 = vmap0[used]
            msg = f"removed {_count(n_unused, 'unreferenced vertex', 'unreferenced vertices')}"
            if orphaned:
                msg += f" ({orphaned:,} of them used only by removed faces)"
            rep_list.append(msg)
        else:
            warn_list.append(
                f"{_count(n_unused, 'unreferenced vertex', 'unreferenced vertices')} "
                "(not removed: repair=False)"
            )

    return F, face_map, sliver, V, vmap0


def validate_mesh(
    V: Any,
    F_or_polygons: Any,
    source: str | os.PathLike | None = None,
    *,
    repair: bool = True,
    vertex_map: Any = None,
    repairs: Sequence[str] = (),
    warnings: Sequence[str] = (),
) -> Mesh:
    """Check a mesh, repair what can be repaired, report everything.

    Parameters
    ----------
    V : (n,3) array_like of float
    F_or_polygons : (m,3) or (m,k) array_like of int, list of index lists, or Polygons
        0-based corner indices; polygons with more than 3 corners are fan-triangulated.
    source : str or PathLike, optional
        File name (or label) used in messages; ``"V"`` / ``"F"`` when omitted.
    repair : bool
        When False, degenerate / duplicate faces and unreferenced vertices are kept and only
        reported in ``report.warnings`` (polygons are still triangulated).
    vertex_map : (n,) int, optional
        Input index of each given vertex (loaders pass it; default ``arange(n)``).
    repairs, warnings : sequence of str
        Entries the caller already made (a loader's repairs/warnings), kept first.

    Returns
    -------
    mesh : Mesh

    Raises
    ------
    MeshError
        No vertices / faces; NaN, inf or ``|x| > 1e75`` coordinates (names the vertex); a
        face with fewer than 3 corners or an index out of range (names the face and index);
        all faces degenerate.

    Notes
    -----
    Order: triangulate, drop degenerate faces, drop duplicate faces, drop unreferenced vertices
    (including those referenced only by dropped faces), then :func:`topology_report`.

    Examples
    --------
    A quad is fan-triangulated; an index past the last vertex is refused, naming the face:

    >>> from meshlap_core import MeshError, validate_mesh
    >>> square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    >>> validate_mesh(square, [[0, 1, 2, 3]]).F.tolist()
    [[0, 1, 2], [0, 2, 3]]
    >>> try:
    ...     validate_mesh(square, [[0, 1, 4]], source="square.obj")
    ... except MeshError as error:
    ...     print(error)
    square.obj: face 0 has index 4 but the mesh has 4 vertices (valid indices 0..3)
    """
    src = None if source is None else os.fspath(source)
    vlabel = src or "V"
    flabel = src or "F"
    rep_list = list(repairs)
    warn_list = list(warnings)

    vmap0 = None if vertex_map is None else np.asarray(vertex_map, dtype=np.int64).ravel()
    n_raw = np.shape(V)[0] if np.ndim(V) >= 1 else 0
    V = _coerce_vertices(V, vlabel, vmap0 if vmap0 is not None else np.arange(n_raw))
    n = len(V)
    if vmap0 is None:
        vmap0 = np.arange(n, dtype=np.int64)
    elif len(vmap0) != n:
        raise MeshError(f"vertex_map has {len(vmap0)} entries for {n} vertices", vlabel)

    tri_or_flat, sizes = _coerce_faces(F_or_polygons, flabel)
    n_faces_in = len(tri_or_flat) if sizes is None else len(sizes)
    if n_faces_in == 0:
        raise MeshError("the mesh has no faces", flabel)

    flat = _check_faces(tri_or_flat, sizes, n, flabel)

    if sizes is None:
        F = tri_or_flat
        face_map = np.arange(len(F), dtype=np.int64)
    else:
        F, face_map = _fan_triangulate(tri_or_flat, sizes)
        n_poly = int(np.count_nonzero(sizes > 3))
        if n_poly:
            rep_list.append(
                f"triangulated {_count(n_poly, 'polygon')} with more than 3 corners into "
                f"{_count(int((sizes[sizes > 3] - 2).sum()), 'triangle')} (fan triangulation)"
            )

    F, face_map, sliver = _drop_degenerate(V, F, face_map, repair, rep_list, warn_list, flabel)

    F, face_map, sliver, V, vmap0 = _drop_duplicates_and_unused(
        V, F, face_map, sliver, vmap0, flat, repair, rep_list, warn_list
    )

    n_sliver = int(np.count_nonzero(sliver))
    if n_sliver:
        warn_list.append(
            f"{_count(n_sliver, 'nearly degenerate face')} (a corner angle below "
            f"{SLIVER_ANGLE:g} rad, {np.degrees(SLIVER_ANGLE):.2g}°: needle or cap triangles); "
            "cotangent weights and curvature near them are unreliable"
        )
    n_same = int(np.count_nonzero(duplicate_positions(V)))
    if n_same:
        warn_list.append(
            f"{_count(n_same, 'vertex has', 'vertices have')} the same position as another "
            "vertex (not welded: the surface has a crack or seam there)"
        )

    F = np.ascontiguousarray(F, dtype=np.int64)
    report, table = topology_report_with_table(F, len(V))
    report.n_input_vertices = n
    report.n_input_faces = n_faces_in
    report.repairs = rep_list
    report.warnings = warn_list + report.warnings
    return Mesh(
        V=np.ascontiguousarray(V, dtype=np.float64),
        F=F,
        source=src,
        report=report,
        vertex_map=vmap0,
        face_map=face_map.astype(np.int64),
        edge_table=table,
    )
