"""Surface invariants from the edge table: components, Euler characteristic, genus, boundary
loop lengths, and the manifoldness / orientation report the validator attaches to a mesh."""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components as _cc

from ..errors import MeshError
from ..mesh import MeshReport, count_phrase
from ..types import IntArray, as_faces
from .edges import EdgeTable, boundary_loops, edges, n_of


def connected_components(F: IntArray, n: int) -> tuple[int, IntArray]:
    """Connected components of the vertex graph (isolated vertices are their own component).

    Returns
    -------
    count : int
    labels : (n,) int
        Component of each vertex, numbered from 0 in order of first appearance.
    """
    F = as_faces(F, n)
    i = np.concatenate([F[:, 0], F[:, 1]])
    j = np.concatenate([F[:, 1], F[:, 2]])
    G = sp.coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)).tocsr()
    count, labels = _cc(G, directed=False)
    return int(count), labels.astype(np.int64)


def euler_characteristic(F: IntArray, n: int | None = None) -> int:
    """Euler characteristic ``χ = V − E + F`` counting only vertices used by a face.

    Parameters
    ----------
    F : (m,3) int
    n : int, optional
        Unused vertices are ignored either way; kept for a uniform signature.
    """
    F = as_faces(F, n)
    return int(len(np.unique(F)) - len(edges(F)) + len(F))


def genus(F: IntArray, n: int | None = None) -> int:
    """Genus of an orientable surface: ``g = (2c − χ − b) / 2`` with ``c`` components (that
    have faces) and ``b`` boundary loops.

    Raises
    ------
    MeshError
        When the formula gives a non-integer or negative value (the mesh is not a manifold).
    """
    F = as_faces(F, n)
    if len(F) == 0:
        return 0
    used, Fc = np.unique(F, return_inverse=True)
    c, _ = connected_components(Fc.reshape(-1, 3), len(used))
    b = len(boundary_loops(F))
    twice = 2 * c - euler_characteristic(F) - b
    if twice < 0 or twice % 2:
        raise MeshError(f"genus undefined: 2c - chi - b = {twice} (the mesh is not a manifold)")
    return twice // 2


def _loop_lengths(B: IntArray) -> list[int] | None:
    """Lengths of the boundary loops of the half-edges ``B`` ``(b,2)``, listed by smallest vertex,
    or ``None`` when a vertex has several outgoing boundary half-edges (ambiguous loops).

    The loops are the cycles of the map ``a → b``; their lengths come from the weak components
    of that map, without a walk in Python, so a triangle soup with millions of boundary edges
    costs no more than a closed mesh.
    """
    a, b = B[:, 0], B[:, 1]
    if len(a) == 0:
        return []
    if len(np.unique(a)) != len(a):
        return None
    verts, inv = np.unique(np.concatenate([a, b]), return_inverse=True)
    G = sp.coo_matrix(
        (np.ones(len(a), dtype=np.int8), (inv[: len(a)], inv[len(a) :])),
        shape=(len(verts), len(verts)),
    ).tocsr()
    n_loops, labels = _cc(G, directed=True, connection="weak")
    has_out = np.zeros(len(verts), dtype=bool)
    has_out[inv[: len(a)]] = True  # a loop's length counts the vertices it leaves
    lengths = np.bincount(labels[has_out], minlength=n_loops)
    firsts = np.full(n_loops, len(verts), dtype=np.int64)
    np.minimum.at(firsts, labels, np.arange(len(verts)))
    return lengths[np.argsort(firsts)].astype(np.int64).tolist()


def surface_summary(
    F: IntArray, n: int | None = None, table: EdgeTable | None = None
) -> dict[str, Any]:
    """Every count ``meshlap info`` shows, from one :class:`EdgeTable` (``O(m)`` memory).

    Parameters
    ----------
    F : (m,3) int
    n : int, optional
        Number of vertices (default ``F.max() + 1``); unreferenced vertices count as
        components of their own, as in :func:`connected_components`.
    table : EdgeTable, optional
        ``EdgeTable.from_faces(F, n)``, when the caller has it.

    Returns
    -------
    summary : dict
        ``n_edges``, ``n_boundary_edges``, ``n_nonmanifold_edges``, ``euler_characteristic``
        (used vertices − edges + faces), ``n_components``, ``n_boundary_loops`` and
        ``boundary_loop_lengths`` (``None`` with ``boundary_note`` when the boundary is
        ambiguous), ``genus`` (``None`` with ``genus_note`` when ``2c − χ − b`` is negative or
        odd). The same values as :func:`edges`, :func:`euler_characteristic`,
        :func:`boundary_loops` and :func:`genus`, without recomputing the edges for each.
    """
    F = as_faces(F, n)
    n = n_of(F) if n is None else int(n)
    t = EdgeTable.from_faces(F, n) if table is None else table
    m = len(F)
    out: dict[str, Any] = {
        "n_edges": t.n_edges,
        "n_boundary_edges": int(np.count_nonzero(t.counts == 1)),
        "n_nonmanifold_edges": int(np.count_nonzero(t.counts > 2)),
    }
    used = np.zeros(n, dtype=bool)
    used[F.ravel()] = True
    n_used = int(np.count_nonzero(used))
    chi = n_used - out["n_edges"] + m
    out["euler_characteristic"] = chi
    n_all, _ = t.vertex_components
    out["n_components"] = n_all
    c_faces = n_all - (n - n_used)  # components that have faces
    lengths = _loop_lengths(t.boundary_halfedges())
    out["n_boundary_loops"] = None if lengths is None else len(lengths)
    out["boundary_loop_lengths"] = lengths
    if lengths is None:
        out["boundary_note"] = "boundary loops are ambiguous: a vertex has several boundary fans"
        out["genus"] = None
        out["genus_note"] = "genus undefined: the boundary is not a set of loops"
        return out
    twice = 2 * c_faces - chi - len(lengths) if m else 0
    if twice < 0 or twice % 2:
        out["genus"] = None
        out["genus_note"] = f"genus undefined: 2c - chi - b = {twice} (the mesh is not a manifold)"
    else:
        out["genus"] = twice // 2
    return out


def topology_report(F: Any, n_vertices: int | None = None) -> MeshReport:
    """Edge / vertex manifoldness, orientation, boundary and components of a triangle list
    (see :func:`topology_report_with_table`, which also returns the edge table it built)."""
    return topology_report_with_table(F, n_vertices)[0]


def topology_report_with_table(
    F: Any, n_vertices: int | None = None
) -> tuple[MeshReport, EdgeTable | None]:
    """Edge / vertex manifoldness, orientation, boundary and components of a triangle list.

    Parameters
    ----------
    F : (m,3) int
        Triangles, 0-based.
    n_vertices : int, optional
        Number of vertices (default ``F.max() + 1``).

    Returns
    -------
    report : MeshReport
        With the topology fields and warnings filled in and no repairs.
    table : EdgeTable or None
        The table the report was computed from (``None`` without faces), to be shared by the
        callers (:attr:`Mesh.edge_table`) instead of rebuilt; its
        :attr:`~EdgeTable.vertex_components` are already computed.

    Notes
    -----
    From one :class:`EdgeTable`: an edge with more than two faces is non-manifold; a two-face
    edge traversed in the same direction by both faces is inconsistently oriented. A vertex
    with more than one wedge (:meth:`EdgeTable.wedge_counts`, the counts of
    :meth:`EdgeTable.wedges`) is non-manifold (libigl ``is_vertex_manifold``). All steps are
    vectorised.
    """
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    m = len(F)
    n = int(F.max()) + 1 if n_vertices is None and m else int(n_vertices or 0)
    rep = MeshReport(n_input_vertices=n, n_input_faces=m)
    if m == 0:
        return rep, None
    t = EdgeTable.from_faces(F, n)
    rep.n_edges = t.n_edges
    rep.n_boundary_edges = int(np.count_nonzero(t.counts == 1))
    bad = t.counts > 2
    rep.n_nonmanifold_edges = int(np.count_nonzero(bad))
    if rep.n_nonmanifold_edges:
        rep.nonmanifold_edges = t.edges[bad]
    rep.n_inconsistent_edges = int(np.count_nonzero(~t.consistent_pairs()))
    rep.consistently_oriented = rep.n_inconsistent_edges == 0

    wedges_per_vertex = t.wedge_counts()
    nm_v = np.flatnonzero(wedges_per_vertex > 1)
    rep.n_nonmanifold_vertices = len(nm_v)
    rep.nonmanifold_vertices = nm_v.astype(np.int64)
    # components of faces (through shared vertices), ignoring unreferenced vertices
    n_all, _ = t.vertex_components
    rep.n_components = n_all - int(np.count_nonzero(wedges_per_vertex == 0))
    rep.warnings.extend(_topology_warnings(rep))
    return rep, t


def _topology_warnings(rep: MeshReport) -> list[str]:
    out = []
    if rep.n_nonmanifold_edges:
        out.append(
            f"{count_phrase(rep.n_nonmanifold_edges, 'non-manifold edge')} "
            "(shared by more than two faces; not repaired)"
        )
    if rep.n_nonmanifold_vertices:
        nv = count_phrase(
            rep.n_nonmanifold_vertices, "non-manifold vertex", "non-manifold vertices"
        )
        out.append(f"{nv} (their faces form more than one fan; not repaired)")
    if not rep.consistently_oriented:
        out.append(
            "faces are not consistently oriented: "
            f"{count_phrase(rep.n_inconsistent_edges, 'edge is', 'edges are')} traversed in the "
            "same direction by both of their faces (not repaired)"
        )
    return out
