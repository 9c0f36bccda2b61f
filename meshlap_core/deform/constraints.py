"""The vertices a deformation holds: handles (moved to targets), a fixed region (held at rest),
and the checks that make the linear systems solvable.

Every method minimizes a quadratic (or, for ARAP, alternately quadratic) energy whose matrix is
positive *semi*definite: the cotangent stiffness ``K = −C`` and its powers ``K (M⁻¹K)ᵏ⁻¹``
annihilate exactly the functions that are constant on each connected component (connected
through faces that are not degenerate, :func:`solid_faces`). Holding one vertex of a component
makes the rest of it determined; a component that holds none would leave the system singular.
Such a component cannot be moved by any handle, so it is *held at rest*
(:attr:`Constraints.still`) and reported, rather than refused: a scan with a loose eye keeps
its eye where it was.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import igl
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..errors import MeshError
from ..options import DEGENERATE_REL, MAX_COORDINATE
from ..types import BoolArray, FloatArray, IntArray, real_array

MAX_LISTED = 8
"""An error message lists at most this many offending indices."""


def check_vertices(values: Any, n: int, name: str, what: str = "vertex") -> IntArray:
    """Vertex indices given by a user as a sorted ``(k,)`` int64 array without repeats.

    Parameters
    ----------
    values : int or (k,) array_like of int
        Indices in ``0 … n−1``: integers, or floats with integral values.
    n : int
        The mesh's vertex count.
    name : str
        The argument an error names (``"handles"``, ``"--fixed"``).
    what : str
        What the vertices are, in messages (``"handle"``).

    Raises
    ------
    MeshError
        Empty, not one-dimensional, not integral (booleans, strings, NaN, 1.5), or out of range.
    """
    raw = real_array(values, name, f"{what} indices")
    arr = np.atleast_1d(raw)
    if arr.ndim != 1:
        raise MeshError(f"{what} indices must be a flat list; shape is {raw.shape}", name)
    if arr.size == 0:
        raise MeshError(f"give at least one {what} vertex", name)
    if arr.dtype.kind == "O":
        arr = arr.astype(np.float64)
    if arr.dtype.kind == "f":
        bad = ~np.isfinite(arr) | (arr != np.round(arr))
        if bad.any():
            raise MeshError(f"{what} indices must be integers, got {arr[bad][0]!r}", name)
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        wrong = arr[(arr < 0) | (arr >= n)]
        shown = ", ".join(str(int(v)) if abs(v) < 2**63 else f"{v:g}" for v in wrong[:MAX_LISTED])
        raise MeshError(
            f"{what} vertex {shown} out of range (the mesh has {n} vertices: 0..{n - 1})", name
        )
    return np.unique(arr.astype(np.int64))


def check_targets(targets: Any, count: int, name: str = "targets") -> FloatArray:
    """Target positions of the handle vertices as a new ``(count, 3)`` float64 array.

    Raises
    ------
    MeshError
        Not real numbers, the wrong shape, or a NaN or infinite coordinate.
    """
    raw = real_array(targets, name, "target positions")
    try:
        arr = np.array(raw, dtype=np.float64, copy=True, order="C")
    except (TypeError, ValueError, OverflowError) as exc:
        raise MeshError(f"target positions are not numbers ({exc})", name) from None
    if arr.shape != (count, 3):
        raise MeshError(
            f"should have shape ({count}, 3), one row per handle; got {arr.shape}", name
        )
    if arr.size and not np.abs(arr).max() <= MAX_COORDINATE:  # NaN fails the test too
        row = int(np.flatnonzero(~(np.abs(arr) <= MAX_COORDINATE).all(axis=1))[0])
        if not np.isfinite(arr[row]).all():
            raise MeshError(f"row {row} has a NaN or infinite coordinate", name)
        raise MeshError(
            f"row {row} has a coordinate beyond ±{MAX_COORDINATE:.0e} (as vertices may not)", name
        )
    return arr


def solid_faces(V: FloatArray, F: IntArray) -> BoolArray:
    """Which faces are not degenerate, by the rule the cotangent weights use
    (:data:`~meshlap_core.options.DEGENERATE_REL`: ``16 A² > (2·DEGENERATE_REL)² (Σ l²)²``,
    Heron's ``16 A²`` from libigl's ``squared_edge_lengths``); a degenerate face gets zero
    weights."""
    return solid_from_lengths(igl.squared_edge_lengths(V, F))


def solid_from_lengths(l2: FloatArray) -> BoolArray:
    """:func:`solid_faces` from the squared edge lengths ``(m,3)`` (a deformer computes them
    once, for this test and for the weights)."""
    a, b, c = l2[:, 0], l2[:, 1], l2[:, 2]
    area16 = 2.0 * (a * b + b * c + c * a) - (a * a + b * b + c * c)
    return area16 > (2.0 * DEGENERATE_REL) ** 2 * (a + b + c) ** 2


def surface_components(F: IntArray, n: int, solid: BoolArray) -> tuple[int, IntArray]:
    """Components of the mesh joined through its solid faces (:func:`solid_faces`): the null
    space of the cotangent stiffness is the functions constant on each (a vertex only in
    degenerate faces, or in none, is a component of its own).

    Parameters
    ----------
    F : (m,3) int
    n : int
    solid : (m,) bool

    Returns
    -------
    count : int
    labels : (n,) int
    """
    G = F[solid]
    i = np.concatenate([G[:, 0], G[:, 1]])  # two edges of each face join its three corners
    j = np.concatenate([G[:, 1], G[:, 2]])
    A = sp.csr_matrix((np.ones(len(i), dtype=np.int8), (i, j)), shape=(n, n))
    count, labels = connected_components(A, directed=False)
    return int(count), labels.astype(np.int64)


@dataclass(frozen=True)
class Constraints:
    """The partition of the vertices of one handle set.

    Attributes
    ----------
    n : int
        Number of vertices.
    handles : (h,) int
        Moved to targets (sorted).
    fixed : (f,) int
        Held at their rest positions (sorted, disjoint from ``handles``).
    still : (s,) int
        Vertices of components holding neither a handle nor a fixed vertex: held at rest.
    known : (k,) int
        ``handles ∪ fixed ∪ still``, sorted: the rows a solve does not compute.
    free : (n−k,) int
        The unknowns, sorted.
    n_components : int
        Connected components (through solid faces).
    """

    n: int
    handles: IntArray
    fixed: IntArray
    still: IntArray
    known: IntArray
    free: IntArray
    n_components: int

    @property
    def n_unknowns(self) -> int:
        """Rows of the system solved per drag (per coordinate)."""
        return len(self.free)


def check_sets(n: int, handles: Any, fixed: Any = None) -> tuple[IntArray, IntArray]:
    """The handle and fixed vertices checked: sorted ``(h,)`` and ``(f,)`` int, disjoint.

    Raises
    ------
    MeshError
        Bad indices (named ``handles`` or ``fixed``), or a vertex both a handle and fixed.
    """
    h = check_vertices(handles, n, "handles", "handle")
    f = (
        np.zeros(0, dtype=np.int64)
        if fixed is None or (np.ndim(fixed) == 1 and len(fixed) == 0)
        else check_vertices(fixed, n, "fixed", "fixed")
    )
    both = np.intersect1d(h, f)
    if len(both):
        shown = ", ".join(str(int(v)) for v in both[:MAX_LISTED])
        raise MeshError(
            f"vertex {shown} is both a handle and fixed ({len(both)} such vertices); a vertex "
            "is moved or held, not both",
            "fixed",
        )
    return h, f


def make_constraints(
    F: IntArray,
    n: int,
    solid: BoolArray,
    handles: Any,
    fixed: Any = None,
    graph: sp.spmatrix | None = None,
) -> Constraints:
    """Check a handle set and partition the vertices (see :class:`Constraints`).

    Parameters
    ----------
    F : (m,3) int
    n : int
    solid : (m,) bool
        The faces that are not degenerate (:func:`solid_faces`; they join the components).
    handles : (h,) int
        The handle vertices (all of them: a disc is grown before, by
        :func:`~meshlap_core.deform.regions.grow_handles`).
    fixed : (f,) int, optional
        Vertices held at rest; none by default.
    graph : (n,n) scipy.sparse matrix, optional
        A matrix whose pattern joins the corners of every face (the cotangent stiffness):
        when every face is solid its components are the mesh's, found without building a
        graph of the faces.

    Raises
    ------
    MeshError
        As :func:`check_sets`.
    """
    h, f = check_sets(n, handles, fixed)
    if graph is not None and solid.all():
        # the pattern is symmetric: its strong components are the components, found without
        # the transpose an undirected search builds
        count, labels = connected_components(graph, directed=True, connection="strong")
        labels = labels.astype(np.int64)
    else:
        count, labels = surface_components(F, n, solid)
    held = np.zeros(count, dtype=bool)
    held[labels[h]] = True
    held[labels[f]] = True
    at_rest = ~held[labels]
    still = np.flatnonzero(at_rest)
    is_known = at_rest
    is_known[h] = True
    is_known[f] = True
    known = np.flatnonzero(is_known)
    free = np.flatnonzero(~is_known)
    return Constraints(n, h, f, still, known, free, int(count))
