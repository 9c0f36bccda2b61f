"""Cutting a mesh along edges: the seams that open a surface into a disk.

Cutting is vertex splitting. Around a vertex its corners (one per face) are joined across
every interior edge that is not cut; each group of joined corners (a *wedge*) becomes a vertex
of its own. A cut edge thus gets two copies of its interior vertices, while a path's two ends
stay whole (a slit), and the faces keep their order and orientation: face ``f`` of the cut
mesh is face ``f`` of the input, with new vertex indices. :func:`split_along` returns the new
faces and, for every new vertex, the input vertex it is a copy of.

Where the cuts come from:

* :func:`genus_cut`: libigl's ``cut_to_disk`` (the triangle-deletion approach of Gu, Gortler &
  Hoppe, "Geometry images", 2002): enough edges to open every handle and join every boundary
  loop, nothing guaranteed about their length;
* :func:`slit`: a closed genus-0 surface (which ``cut_to_disk`` leaves alone) is slit along the
  shortest edge path between two far-apart vertices (a double sweep of Dijkstra's algorithm:
  the vertex farthest from vertex 0, then the one farthest from it);
* :func:`seam_edges`: a path of vertices the user chose (consecutive vertices joined by an
  edge), checked.
"""

from __future__ import annotations

from typing import Any

import igl
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, dijkstra

from ..errors import MeshError
from ..topology import EdgeTable
from ..types import BoolArray, FloatArray, IntArray, exact_indices

MAX_SEAM = 10_000_000
"""A seam longer than this many vertices is refused before it is read (bounded work)."""


def edge_ids(table: EdgeTable, pairs: IntArray) -> IntArray:
    """The row of each vertex pair ``(k,2)`` (either order) in ``table.edges``, ``-1`` for a
    pair that is not an edge of the mesh; ``(k,)`` int."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    n = max(table.n, 1)
    keys = table.edges[:, 0] * n + table.edges[:, 1]  # sorted: the edges are lexicographic
    want = pairs.min(axis=1) * n + pairs.max(axis=1)
    if len(keys) == 0:
        return np.full(len(want), -1, dtype=np.int64)
    pos = np.minimum(np.searchsorted(keys, want), len(keys) - 1)
    return np.where(keys[pos] == want, pos, -1).astype(np.int64)


def split_along(table: EdgeTable, cut: BoolArray) -> tuple[IntArray, IntArray]:
    """Cut the mesh of ``table`` along the edges marked in ``cut``.

    Parameters
    ----------
    table : EdgeTable
        The mesh's edge table (edge-manifold, consistently oriented).
    cut : (e,) bool
        ``True`` for the rows of ``table.edges`` to cut (boundary edges are cut already).

    Returns
    -------
    F : (m,3) int
        The cut mesh's faces, in the input's order and orientation.
    source : (n',) int
        The input vertex each new vertex copies, ascending; a vertex that no cut touches
        keeps one copy, so with nothing cut (and every vertex in a face) ``source`` is
        ``arange(n)`` and ``F`` the input's faces.
    """
    src = table.F.ravel()
    n3 = len(src)
    edge, h1, h2 = table.face_pairs()
    keep = ~cut[edge]
    h1, h2 = h1[keep], h2[keep]
    nxt1 = h1 - h1 % 3 + (h1 + 1) % 3
    nxt2 = h2 - h2 % 3 + (h2 + 1) % 3
    # h1 runs a -> b and h2 (consistently oriented) b -> a: the corner h1 (at a) and the corner
    # after h2 (at a) are one wedge, as are the corner after h1 (at b) and h2 (at b)
    rows = np.concatenate([h1, nxt1])
    cols = np.concatenate([nxt2, h2])
    G = sp.csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(n3, n3))
    count, labels = connected_components(G, directed=True, connection="weak")
    wedge_source = np.empty(count, dtype=np.int64)
    wedge_source[labels] = src
    order = np.lexsort((np.arange(count), wedge_source))  # by input vertex, then wedge
    new_id = np.empty(count, dtype=np.int64)
    new_id[order] = np.arange(count)
    return new_id[labels].reshape(-1, 3), wedge_source[order]


def path_pairs(paths: list[Any]) -> IntArray:
    """The consecutive vertex pairs of each path (a list of vertex sequences), ``(k,2)``."""
    pairs = [np.stack([p[:-1], p[1:]], axis=1) for p in map(np.asarray, paths) if len(p) > 1]
    return np.concatenate(pairs).astype(np.int64) if pairs else np.zeros((0, 2), np.int64)


def genus_cut(table: EdgeTable) -> BoolArray:
    """The interior edges libigl's ``cut_to_disk`` cuts to open every handle (and join every
    boundary loop) of the mesh of ``table``; ``(e,)`` bool (none on a genus-0 closed mesh)."""
    cut = np.zeros(table.n_edges, dtype=bool)
    ids = edge_ids(table, path_pairs(igl.cut_to_disk(table.F)))
    cut[ids[ids >= 0]] = True
    cut[table.counts == 1] = False  # boundary edges: open already
    return cut


def _graph(V: FloatArray, table: EdgeTable) -> sp.csr_matrix:
    """The edge graph weighted by edge length (upper triangle: Dijkstra reads it undirected)."""
    i, j = table.edges[:, 0], table.edges[:, 1]
    length = np.linalg.norm(V[i] - V[j], axis=1)
    length = np.maximum(length, np.finfo(float).tiny)  # a zero weight would drop the edge
    return sp.csr_matrix((length, (i, j)), shape=(table.n, table.n))


def slit(V: FloatArray, table: EdgeTable) -> BoolArray:
    """The shortest edge path between two far-apart vertices, ``(e,)`` bool.

    A double sweep: ``a`` the vertex farthest (along edges) from the first vertex of a face,
    ``b`` the one farthest from ``a``, and the shortest path from ``a`` to ``b`` (one more
    edge from ``b`` when that path is a single edge, as on a tetrahedron: cutting a lone edge
    doubles no vertex). Cutting a closed genus-0 mesh along it gives a disk whose boundary
    runs along the path twice.
    """
    G = _graph(V, table)
    start = int(table.F[0, 0])
    d0 = dijkstra(G, directed=False, indices=start)
    a = int(np.argmax(np.where(np.isfinite(d0), d0, -1.0)))
    da, pred = dijkstra(G, directed=False, indices=a, return_predecessors=True)
    b = int(np.argmax(np.where(np.isfinite(da), da, -1.0)))
    path = [b]
    while path[-1] != a:
        path.append(int(pred[path[-1]]))
    if len(path) == 2:  # one edge opens nothing (both ends are tips): go one edge further
        ring = table.edges[(table.edges == b).any(axis=1)].ravel()
        path.insert(0, int(ring[(ring != a) & (ring != b)][0]))
    cut = np.zeros(table.n_edges, dtype=bool)
    cut[edge_ids(table, path_pairs([path]))] = True
    return cut


def seam_edges(seam: Any, table: EdgeTable, name: str = "seam") -> BoolArray:
    """The edges of a user's seam, a path of vertex indices, ``(e,)`` bool.

    Parameters
    ----------
    seam : (k,) int
        At least two vertices; each consecutive pair must be an edge of the mesh (a closed
        path repeats its first vertex at the end).
    table : EdgeTable
    name : str
        The argument named in errors.

    Raises
    ------
    MeshError
        Not a 1-D integer sequence, fewer than two vertices, an index out of range, or two
        consecutive vertices that share no edge (named).
    """
    size = np.size(seam) if isinstance(seam, np.ndarray) else None
    if size is not None and size > MAX_SEAM:
        raise MeshError(f"has {size} vertices; at most {MAX_SEAM} are read", name)
    path = exact_indices(seam, name)
    if path.ndim != 1:
        raise MeshError(f"should be a 1-D path of vertex indices; shape is {path.shape}", name)
    if len(path) < 2:
        raise MeshError("a seam needs at least two vertices (one edge)", name)
    bad = np.flatnonzero((path < 0) | (path >= table.n))
    if len(bad):
        raise MeshError(
            f"vertex {int(path[bad[0]])} (position {int(bad[0])}) is out of range; the mesh "
            f"has {table.n} vertices",
            name,
        )
    pairs = np.stack([path[:-1], path[1:]], axis=1)
    ids = edge_ids(table, pairs)
    missing = np.flatnonzero(ids < 0)
    if len(missing):
        a, b = pairs[missing[0]]
        raise MeshError(
            f"vertices {int(a)} and {int(b)} (positions {int(missing[0])}, "
            f"{int(missing[0]) + 1}) are not joined by an edge; a seam follows mesh edges",
            name,
        )
    cut = np.zeros(table.n_edges, dtype=bool)
    cut[ids] = True
    return cut
