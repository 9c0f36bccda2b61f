"""Disk topology first: every map to the plane needs a topological disk.

:func:`make_disk` takes any connected, edge-manifold, consistently oriented triangle mesh and
returns a :class:`Disk`, saying in :attr:`Disk.messages` what it did:

* one boundary loop and genus 0 (a disk): flattened as it is;
* several boundary loops and genus 0: the longest loop (by length) is the outer boundary, the
  others are holes left free (a fixed-boundary map pins only the outer loop);
* a handle (genus ≥ 1), with or without boundary: cut to a disk along the edges of libigl's
  ``cut_to_disk`` (Gu, Gortler & Hoppe 2002), which also joins the boundary loops;
* closed and genus 0 (a sphere): slit along the shortest edge path between two far-apart
  vertices (:func:`~meshlap_core.flatten.cut.slit`);
* a ``seam`` (a path of vertex indices along edges) is cut first; whatever topology is left is
  then treated by the rules above.

Several connected components are refused (a clear error naming the count): one map per
component would also need the charts packed side by side, which is a different tool. Vertices
that are in no face are left out of the disk (they get no texture coordinate).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import MeshError
from ..mesh import count_phrase
from ..topology import EdgeTable, boundary_loops
from ..types import FloatArray, IntArray, as_mesh
from ..validate import degenerate_faces
from .cut import genus_cut, seam_edges, slit, split_along


@dataclass(frozen=True, eq=False)
class Disk:
    """A mesh opened into a topological disk (possibly with holes).

    Face ``f`` of the disk is face ``f`` of the input (same corners, same orientation), with
    the vertices along the cuts doubled: ``source[F]`` is the input's ``F``.

    Attributes
    ----------
    V : (n',3) float
        The disk's vertices (copies of input vertices).
    F : (m,3) int
        The disk's faces.
    source : (n',) int
        The input vertex each disk vertex copies (ascending).
    n_input : int
        The input's vertex count.
    outer : (b,) int
        The outer boundary loop (disk vertices, interior on the left: counter-clockwise seen
        from the side the normals point to).
    holes : tuple of (k,) int
        The other boundary loops, same orientation rule (clockwise around each hole).
    cut_edges : (c,2) int
        The input's edges that were cut (``i < j``, input vertex indices): draw them as a
        curve network on ``(V_input, cut_edges)``.
    how : str
        ``"disk"``, ``"holes"``, ``"genus-cut"``, ``"slit"`` (and ``"seam+..."`` after a seam).
    messages : tuple of str
        What was done, in words (for a panel or the command line).
    table : EdgeTable
        The disk's edge table (built anyway; the maps reuse it).
    """

    V: FloatArray
    F: IntArray
    source: IntArray
    n_input: int
    outer: IntArray
    holes: tuple[IntArray, ...]
    cut_edges: IntArray
    how: str
    messages: tuple[str, ...] = field(default=())
    table: EdgeTable | None = field(default=None, repr=False)

    @property
    def n_vertices(self) -> int:
        """Vertices of the disk."""
        return len(self.V)

    @property
    def boundary(self) -> IntArray:
        """Every boundary vertex of the disk (outer loop first, then the holes'), ``(b,)``."""
        return np.concatenate([self.outer, *self.holes]).astype(np.int64)

    def input_faces(self) -> IntArray:
        """The input's faces ``source[F]``, ``(m,3)``."""
        return self.source[self.F]


def _check_surface(V: FloatArray, F: IntArray, table: EdgeTable) -> None:
    """Refuse what no map to the plane can take: no faces, zero-area faces, a non-manifold
    or inconsistently oriented mesh, several components."""
    if len(F) == 0:
        raise MeshError("the mesh has no faces; flattening needs a surface", "F")
    repeated, zero = degenerate_faces(V, F)
    bad = np.flatnonzero(repeated | zero)
    if len(bad):
        raise MeshError(
            f"face {int(bad[0])} (and {len(bad) - 1} more) has zero area; its cotangent "
            "weights and its Jacobian are undefined (meshlap's load_mesh removes such faces)",
            "F",
        )
    problems = []
    if np.any(table.counts > 2):
        problems.append(count_phrase(int(np.count_nonzero(table.counts > 2)), "non-manifold edge"))
    flipped = np.count_nonzero(~table.consistent_pairs())
    if flipped:
        problems.append(count_phrase(int(flipped), "inconsistently oriented edge"))
    if problems:
        raise MeshError(
            "flattening needs an edge-manifold, consistently oriented mesh; this one has "
            + " and ".join(problems),
            "F",
        )
    _, labels = table.vertex_components
    face_label = labels[F[:, 0]]
    if np.any(face_label != face_label[0]):
        used = np.unique(face_label)
        sizes = np.bincount(np.searchsorted(used, face_label))
        raise MeshError(
            f"the mesh has {len(used)} connected components (the largest has "
            f"{int(sizes.max())} of the {len(F)} faces); flatten one component at a time",
            "F",
        )


def _loop_length(V: FloatArray, loop: IntArray) -> float:
    """Perimeter of a closed loop of vertices."""
    return float(np.linalg.norm(V[loop] - V[np.roll(loop, -1)], axis=1).sum())


def _genus(table: EdgeTable, n_loops: int) -> int:
    """``g = (2 − χ − b)/2`` of a connected mesh with ``b`` boundary loops."""
    used = np.count_nonzero(np.bincount(table.F.ravel(), minlength=table.n))
    chi = used - table.n_edges + len(table.F)
    return (2 - chi - n_loops) // 2


def _open(
    V: FloatArray,
    table: EdgeTable,
    source: IntArray,
    how: list[str],
    messages: list[str],
    cut_allowed: bool,
) -> tuple[EdgeTable, IntArray, IntArray]:
    """Cut the mesh of ``table`` (vertices ``V[source]``) into a disk if it is not one yet;
    returns ``(table, source, cut edges in input indices)``."""
    loops = boundary_loops(table.F, table)
    genus = _genus(table, len(loops))
    if not cut_allowed and (genus > 0 or not loops):
        raise MeshError(
            f"the mesh is not a disk (genus {genus}, {count_phrase(len(loops), 'boundary loop')}) "
            "and cutting is off: allow the automatic cut or give a seam that opens it",
            "F",
        )
    if genus > 0:
        cut = genus_cut(table)
        how.append("genus-cut")
        messages.append(
            f"genus {genus}: cut to a disk along {count_phrase(int(cut.sum()), 'edge')} "
            "(libigl cut_to_disk, Gu, Gortler & Hoppe 2002)"
        )
    elif not loops:
        cut = slit(V[source], table)
        how.append("slit")
        messages.append(
            "closed genus-0 surface: slit along the shortest path between two far-apart "
            f"vertices ({count_phrase(int(cut.sum()), 'edge')})"
        )
    else:
        return table, source, np.zeros((0, 2), dtype=np.int64)
    F2, src2 = split_along(table, cut)
    return EdgeTable.from_faces(F2, len(src2)), source[src2], source[table.edges[cut]]


def make_disk(V: Any, F: Any, seam: Any = None, *, cut: bool = True) -> Disk:
    """Open a connected triangle mesh into a topological disk (see the module's rules).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    seam : (k,) int, optional
        A path of vertex indices along edges to cut first (a closed path repeats its first
        vertex).
    cut : bool
        Cut handles and slit spheres automatically (default); ``False`` refuses a mesh that
        is not a disk (with holes) once the seam is cut.

    Returns
    -------
    Disk

    Raises
    ------
    MeshError
        No faces, a zero-area face, non-manifold edges, inconsistent orientation, several
        connected components, a bad seam, or a seam that cuts the mesh in pieces.

    Examples
    --------
    A flat grid is a disk already; a closed sphere is slit open, a torus cut along its
    generators:

    >>> from meshlap_core import grid, icosphere, make_disk, torus_mesh
    >>> make_disk(*grid(5, 5)).how
    'disk'
    >>> make_disk(*icosphere(1)).how
    'slit'
    >>> make_disk(*torus_mesh(8, 16)).how
    'genus-cut'
    """
    V, F = as_mesh(V, F)
    table = EdgeTable.from_faces(F, len(V))
    _check_surface(V, F, table)
    how: list[str] = []
    messages: list[str] = []
    cuts = [np.zeros((0, 2), dtype=np.int64)]
    seam_cut = np.zeros(table.n_edges, dtype=bool)
    if seam is not None:
        seam_cut = seam_edges(seam, table)
        how.append("seam")
        messages.append(f"seam: cut along {count_phrase(int(seam_cut.sum()), 'edge')}")
        cuts.append(table.edges[seam_cut])
    # one split: the seam's edges cut, every non-manifold vertex split into its fans (a
    # pinch point opens), vertices in no face dropped; when none of these is needed the
    # disk keeps the input's numbering (and its edge table)
    fans = table.wedge_counts()
    if seam_cut.any() or np.any(fans != 1):
        F1, source = split_along(table, seam_cut)
        table1 = EdgeTable.from_faces(F1, len(source))
    else:
        table1, source = table, np.arange(len(V), dtype=np.int64)
    extra = int(np.sum(fans[fans > 1] - 1))
    if extra:
        messages.append(
            f"{count_phrase(int(np.count_nonzero(fans > 1)), 'vertex', 'vertices')} where "
            f"several fans of faces meet: split into one vertex per fan ({extra} more)"
        )
    pieces, _ = table1.vertex_components
    if pieces > 1:
        what = "the seam cuts" if seam is not None else "its non-manifold vertices split"
        raise MeshError(
            f"{what} the mesh into {pieces} pieces; flatten one piece at a time",
            "seam" if seam is not None else "F",
        )
    table2, source, more = _open(V, table1, source, how, messages, bool(cut))
    cuts.append(more)
    loops = boundary_loops(table2.F, table2)
    if not loops or _genus(table2, len(loops)) != 0:  # (cut_to_disk's promise, checked)
        raise MeshError("could not open the mesh into a disk (is it a manifold?)", "F")
    Vd = V[source]
    lengths = [_loop_length(Vd, loop) for loop in loops]
    order = np.argsort(lengths, kind="stable")[::-1]
    outer, holes = loops[order[0]], tuple(loops[i] for i in order[1:])
    if holes:
        messages.append(
            f"{len(loops)} boundary loops: the longest ({len(outer)} vertices, length "
            f"{lengths[order[0]]:.4g}) is the outer boundary; the "
            f"{'other is a hole' if len(holes) == 1 else f'{len(holes)} others are holes'}, "
            "left free"
        )
        how.append("holes")
    cut_edges = np.concatenate(cuts)
    cut_edges = np.unique(np.sort(cut_edges, axis=1), axis=0) if len(cut_edges) else cut_edges
    return Disk(
        V=Vd,
        F=table2.F,
        source=source,
        n_input=len(V),
        outer=outer,
        holes=holes,
        cut_edges=cut_edges.reshape(-1, 2).astype(np.int64),
        how="+".join(how) or "disk",
        messages=tuple(messages),
        table=table2,
    )
