"""Ordered one-rings of every vertex at once, split into fans at non-manifold vertices.

A *fan* of a vertex ``v`` is a maximal sequence of faces around ``v`` in which consecutive faces
share an edge at ``v`` that exactly two faces use, traversed in opposite directions (a manifold,
consistently oriented edge). A manifold vertex has one fan: closed (interior vertex) or open
(boundary vertex). Two spheres touching at a point, tetrahedra sharing a vertex or a torus with
two vertices glued have vertices with several fans; every corner of a vertex lies in exactly one
of its fans.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from ..errors import MeshError
from ..types import BoolArray, IntArray, as_faces
from .edges import EdgeTable


class Fan(NamedTuple):
    """One fan of faces around a vertex ``v``.

    Attributes
    ----------
    neighbors : (k,) int
        Ring vertices in order; ``(v, neighbors[j], neighbors[j+1])`` is the face ``faces[j]``
        (counter-clockwise rings; wrapping around when ``closed``).
    faces : (k,) or (k-1,) int
        The faces between consecutive neighbours (``k`` for a closed fan, ``k - 1`` for an open
        one).
    closed : bool
        ``True`` for a closed cycle (no boundary at ``v`` on this fan).
    """

    neighbors: IntArray
    faces: IntArray
    closed: bool


def _reverse_segments(ptr: IntArray, values: IntArray) -> IntArray:
    """``values`` with every CSR segment ``values[ptr[s]:ptr[s+1]]`` reversed."""
    counts = np.diff(ptr)
    seg = np.repeat(np.arange(len(counts)), counts)
    pos = np.arange(len(values)) - ptr[seg]
    out = np.empty_like(values)
    out[ptr[seg] + counts[seg] - 1 - pos] = values
    return out


@dataclass(frozen=True)
class OneRing:
    """Ordered one-rings of all vertices, stored like a CSR matrix, with every vertex's fans.

    ``ring[i]`` (``indices[offsets[i]:offsets[i+1]]``) lists the neighbours of vertex ``i`` in
    order. With ``ccw=True`` consecutive neighbours ``(a, b)`` satisfy: ``(i, a, b)`` is a face,
    i.e. the order is counter-clockwise seen from the side the face normals point to. An
    interior vertex's list is a closed cycle (the first neighbour follows the last); a boundary
    vertex's list is an open fan from one boundary neighbour to the other. Vertices whose
    neighbourhood is not a single disk or half-disk (non-manifold, inconsistently oriented) have
    ``regular[i] = False`` and their neighbours sorted by index instead; their fans, each in
    order, are :meth:`fans` ``(i)``.

    Attributes
    ----------
    offsets : (n+1,) int
    indices : (k,) int
    boundary : (n,) bool
        The vertex has an open fan.
    regular : (n,) bool
        One fan (or none), bounded only by boundary edges: a disk or half-disk.
    fan_offsets : (n+1,) int
        Fans of vertex ``i`` are ``fan_offsets[i]:fan_offsets[i+1]``.
    fan_ptr, fan_indices : (f+1,) int, (q,) int
        Ring vertices of fan ``s``: ``fan_indices[fan_ptr[s]:fan_ptr[s+1]]``.
    fan_face_ptr, fan_faces : (f+1,) int, (r,) int
        Faces of fan ``s``: ``fan_faces[fan_face_ptr[s]:fan_face_ptr[s+1]]``.
    fan_closed : (f,) bool
    ccw : bool

    Examples
    --------
    On a 3 × 3 grid the centre has a closed ring of six, a corner an open fan:

    >>> from meshlap_core import grid, one_ring
    >>> V, F = grid(3, 3)
    >>> ring = one_ring(F, len(V))
    >>> ring[4].tolist(), bool(ring.boundary[4])
    ([7, 8, 5, 1, 0, 3], False)
    >>> ring[0].tolist(), bool(ring.boundary[0]), len(ring.fans(0))
    ([3, 4, 1], True, 1)
    >>> ring.reversed()[4].tolist()  # clockwise
    [3, 0, 1, 5, 8, 7]
    """

    offsets: IntArray
    indices: IntArray
    boundary: BoolArray
    regular: BoolArray
    fan_offsets: IntArray
    fan_ptr: IntArray
    fan_indices: IntArray
    fan_face_ptr: IntArray
    fan_faces: IntArray
    fan_closed: BoolArray
    ccw: bool = True

    def __len__(self) -> int:
        return len(self.offsets) - 1

    def _vertex(self, i: int) -> int:
        n = len(self)
        if not -n <= i < n:
            raise MeshError(f"vertex {i} is out of range (the mesh has {n} vertices)", "vertex")
        return i % n

    def __getitem__(self, i: int) -> IntArray:
        i = self._vertex(i)
        return self.indices[self.offsets[i] : self.offsets[i + 1]]

    @property
    def valence(self) -> IntArray:
        """Number of distinct neighbours of each vertex, ``(n,) int``."""
        return np.diff(self.offsets)

    @property
    def manifold(self) -> BoolArray:
        """``(n,) bool``: the vertex's faces form one disk or half-disk (same as ``regular``)."""
        return self.regular

    @property
    def n_fans(self) -> IntArray:
        """Number of fans of each vertex, ``(n,) int`` (0 for a vertex in no face)."""
        return np.diff(self.fan_offsets)

    def fans(self, i: int) -> list[Fan]:
        """The fans of vertex ``i``, each in ring order (see :class:`Fan`)."""
        i = self._vertex(i)
        out = []
        for s in range(int(self.fan_offsets[i]), int(self.fan_offsets[i + 1])):
            out.append(
                Fan(
                    self.fan_indices[self.fan_ptr[s] : self.fan_ptr[s + 1]],
                    self.fan_faces[self.fan_face_ptr[s] : self.fan_face_ptr[s + 1]],
                    bool(self.fan_closed[s]),
                )
            )
        return out

    def reversed(self) -> OneRing:
        """The same rings and fans in the opposite (clockwise) order."""
        faces = _reverse_segments(self.fan_face_ptr, self.fan_faces)
        # a closed fan's face j lies between neighbours j and j+1 (wrapping): once the ring is
        # reversed, its reversed face list must move one step forward
        ptr = self.fan_face_ptr
        counts = np.diff(ptr)
        seg = np.repeat(np.arange(len(counts)), counts)
        pos = np.arange(len(faces)) - ptr[seg]
        nxt = ptr[seg] + (pos + 1) % np.maximum(counts[seg], 1)
        rolled = np.where(self.fan_closed[seg], faces[nxt], faces)
        return OneRing(
            self.offsets,
            _reverse_segments(self.offsets, self.indices),
            self.boundary,
            self.regular,
            self.fan_offsets,
            self.fan_ptr,
            _reverse_segments(self.fan_ptr, self.fan_indices),
            self.fan_face_ptr,
            rolled,
            self.fan_closed,
            not self.ccw,
        )


def _corner_successors(t: EdgeTable) -> tuple[IntArray, IntArray]:
    """Successor and predecessor of every corner around its vertex (``-1``: none).

    Corner ``c = 3f + k`` of face ``(v, a, b)`` (rotated so ``v`` is corner ``k``) is followed
    by the corner at ``v`` of the face across the edge ``v–b``, when that edge has exactly two
    faces that traverse it in opposite directions (``b → v`` here, ``v → b`` there). The map is
    injective, so the corners of a vertex form disjoint paths and cycles.
    """
    nc = 3 * len(t.F)
    src = t.F.ravel()
    corner = np.arange(nc, dtype=np.int64)
    h_in = corner - corner % 3 + (corner + 2) % 3  # half-edge b → v of the corner's face
    e = t.halfedge_edge[h_in]
    two = t.counts[e] == 2
    first = t.edge_halfedges[t.edge_ptr[e[two]]]
    second = t.edge_halfedges[t.edge_ptr[e[two]] + 1]
    other = np.full(nc, -1, dtype=np.int64)
    other[two] = first + second - h_in[two]
    ok = two.copy()
    ok[two] = src[other[two]] == src[two]  # the other half-edge leaves v: consistent
    succ = np.where(ok, other, -1)
    pred = np.full(nc, -1, dtype=np.int64)
    pred[succ[ok]] = corner[ok]
    return succ, pred


def _rank_paths(pred: IntArray) -> IntArray:
    """Distance of every node to the head of its path (pointer jumping, ``O(log L)`` rounds).

    ``pred`` must describe disjoint simple paths (no cycle); the round count is capped at
    ``bit_length(len(pred)) + 1``, which suffices for any path, so the loop always ends.
    """
    rank = (pred >= 0).astype(np.int64)
    p = pred.copy()
    for _ in range(len(pred).bit_length() + 1):
        live = np.flatnonzero(p >= 0)
        if len(live) == 0:
            return rank
        pl = p[live]
        rank_new = rank.copy()
        rank_new[live] += rank[pl]
        p[live] = p[pl]
        rank = rank_new
    raise RuntimeError("one_ring: a corner chain did not end (cycle left uncut)")


def one_ring(F: IntArray, n: int) -> OneRing:
    """Ordered one-ring and fans of every vertex at once, in ``O(m log m)`` vectorized work.

    Each face corner ``(v, a, b)`` says "after ``a`` comes ``b`` around ``v``". Corners around
    ``v`` are linked across the manifold, consistently oriented edges of the
    :class:`EdgeTable` (:func:`_corner_successors`); the components of that link graph are the
    fans. A fan whose corners form a cycle is closed and cut at its first corner (in the order
    of ``F``'s columns, then rows); an open fan starts at the corner with no predecessor. The
    position of every corner in its fan comes from pointer jumping (list ranking) with a
    bounded number of rounds, so the function terminates on any triangle list.

    Parameters
    ----------
    F : (m,3) int
    n : int
        Number of vertices.

    Returns
    -------
    OneRing
        Counter-clockwise rings and fans (see :class:`OneRing`); ``.reversed()`` gives
        clockwise ones.

    Examples
    --------
    The icosahedron's vertex 0 has five neighbours; consecutive ones make a face with it:

    >>> from meshlap_core import icosphere, one_ring
    >>> V, F = icosphere(0)
    >>> ring = one_ring(F, len(V))
    >>> ring[0].tolist()
    [1, 2, 3, 4, 5]
    >>> corners = {(f[s], f[(s + 1) % 3], f[(s + 2) % 3]) for f in F.tolist() for s in range(3)}
    >>> all((0, a, b) in corners for a, b in [(1, 2), (2, 3), (3, 4), (4, 5), (5, 1)])
    True
    """
    F = as_faces(F, n)
    m = len(F)
    t = EdgeTable.from_faces(F, n)
    nc = 3 * m
    v = F.ravel()
    a = np.roll(F, -1, axis=1).ravel()
    b = np.roll(F, -2, axis=1).ravel()
    succ, pred = _corner_successors(t)
    order_key = (np.arange(nc) % 3) * m + np.arange(nc) // 3  # column-major corner order

    # fans = components of the successor graph; a component without a head is a cycle
    if nc:
        G = csr_matrix(
            (
                np.ones(int(np.count_nonzero(succ >= 0)), np.int8),
                (np.flatnonzero(succ >= 0), succ[succ >= 0]),
            ),
            shape=(nc, nc),
        )
        n_fans, label = connected_components(G, directed=True, connection="weak")
    else:
        n_fans, label = 0, np.zeros(0, dtype=np.int64)
    open_fan = np.zeros(n_fans, dtype=bool)
    open_fan[label[pred < 0]] = True
    fan_key = np.full(n_fans, nc, dtype=np.int64)
    np.minimum.at(fan_key, label, order_key)
    cut = ~open_fan[label] & (order_key == fan_key[label])  # first corner of each cycle
    pred = pred.copy()
    pred[cut] = -1
    rank = _rank_paths(pred)

    # corners sorted by vertex, fan (by its first corner), position in the fan
    srt = np.lexsort((rank, fan_key[label], v))
    ls = label[srt]
    start = np.flatnonzero(np.concatenate([[True], ls[1:] != ls[:-1]])) if nc else ls
    fan_seq, fan_vertex = ls[start], v[srt][start]  # each fan's corners are contiguous in srt
    corners_per_fan = np.bincount(label, minlength=n_fans)[fan_seq]
    closed = ~open_fan[fan_seq]
    face_ptr = np.concatenate([[0], np.cumsum(corners_per_fan)]).astype(np.int64)
    ring_len = corners_per_fan + (~closed)
    ptr = np.concatenate([[0], np.cumsum(ring_len)]).astype(np.int64)
    fan_index = np.arange(len(srt)) - np.repeat(face_ptr[:-1], corners_per_fan)
    fan_of_sorted = np.repeat(np.arange(n_fans), corners_per_fan)
    fan_idx = np.empty(int(ptr[-1]), dtype=np.int64)
    fan_idx[ptr[fan_of_sorted] + fan_index] = a[srt]
    last = face_ptr[1:][~closed] - 1  # an open fan ends with its last corner's b
    fan_idx[ptr[1:][~closed] - 1] = b[srt][last]
    fan_offsets = np.concatenate([[0], np.cumsum(np.bincount(fan_vertex, minlength=n))])

    regular, boundary = _regular_boundary(t, srt, face_ptr, closed, fan_vertex, n)
    offsets, indices = _rings(regular, fan_vertex, ptr, fan_idx, v, a, b, n)
    return OneRing(
        offsets,
        indices,
        boundary,
        regular,
        fan_offsets.astype(np.int64),
        ptr,
        fan_idx,
        face_ptr,
        (srt // 3).astype(np.int64),
        closed,
        True,
    )


def _regular_boundary(
    t: EdgeTable,
    srt: IntArray,
    face_ptr: IntArray,
    closed: BoolArray,
    fan_vertex: IntArray,
    n: int,
) -> tuple[BoolArray, BoolArray]:
    """A vertex is regular when it has at most one fan and an open fan ends on boundary edges
    (one face) at both sides; it is a boundary vertex when it has an open fan."""
    n_fans = np.bincount(fan_vertex, minlength=n)
    boundary = np.zeros(n, dtype=bool)
    boundary[fan_vertex[~closed]] = True
    regular = n_fans <= 1
    open_ids = np.flatnonzero(~closed)
    if len(open_ids):
        head = srt[face_ptr[open_ids]]  # its outgoing half-edge v → a has no partner
        tail = srt[face_ptr[open_ids + 1] - 1]  # its incoming half-edge b → v has none
        tail_in = tail - tail % 3 + (tail + 2) % 3
        ends_ok = (t.counts[t.halfedge_edge[head]] == 1) & (t.counts[t.halfedge_edge[tail_in]] == 1)
        regular[fan_vertex[open_ids[~ends_ok]]] = False
    return regular, boundary


def _rings(
    regular: BoolArray,
    fan_vertex: IntArray,
    ptr: IntArray,
    fan_idx: IntArray,
    v: IntArray,
    a: IntArray,
    b: IntArray,
    n: int,
) -> tuple[IntArray, IntArray]:
    """Per-vertex rings: the single fan of a regular vertex, the sorted neighbours otherwise."""
    keep = regular[fan_vertex]
    lens = np.diff(ptr)[keep]
    rv = np.repeat(fan_vertex[keep], lens)
    starts = ptr[:-1][keep]
    rpos = np.arange(int(lens.sum())) - np.repeat(np.cumsum(lens) - lens, lens)
    rval = fan_idx[np.repeat(starts, lens) + rpos]
    irr = ~regular[v]
    if irr.any():
        keys = np.unique(np.concatenate([v[irr] * n + a[irr], v[irr] * n + b[irr]]))
        iv, ij = keys // n, keys % n
        rv, rpos, rval = (
            np.concatenate([rv, iv]),
            np.concatenate([rpos, ij]),
            np.concatenate([rval, ij]),
        )
    order = np.lexsort((rpos, rv))
    offsets = np.concatenate([[0], np.cumsum(np.bincount(rv, minlength=n))]).astype(np.int64)
    return offsets, rval[order].astype(np.int64)
