"""Topology: edges, boundary, components, Euler characteristic, genus, ordered one-rings."""

import itertools

import numpy as np
import pytest

from meshlap_core import primitives, topology
from meshlap_core.errors import MeshError
from tests.support import hostile


def face_set(F):
    """Faces as a set of rotation-normalised tuples (orientation kept)."""
    out = set()
    for f in F.tolist():
        k = f.index(min(f))
        out.add(tuple(f[k:] + f[:k]))
    return out


def consecutive(r, closed):
    """Consecutive pairs of a list, wrapping around when ``closed``."""
    return list(itertools.pairwise(r + r[:1] if closed else r))


def rot(t):
    k = t.index(min(t))
    return tuple(t[k:] + t[:k])


@pytest.mark.parametrize(
    "make, chi, genus, loops",
    [
        (lambda: primitives.icosphere(2), 2, 0, 0),
        (primitives.torus_mesh, 0, 1, 0),
        (primitives.grid, 1, 0, 1),
        (primitives.cube, 2, 0, 0),
    ],
)
def test_euler_genus_boundary(make, chi, genus, loops):
    V, F = make()
    assert topology.euler_characteristic(F) == chi
    assert topology.genus(F) == genus
    assert len(topology.boundary_loops(F)) == loops
    assert topology.connected_components(F, len(V))[0] == 1
    E = topology.edges(F)
    assert len(V) - len(E) + len(F) == chi


def test_grid_boundary_loop_is_ccw_perimeter():
    V, F = primitives.grid(4, 5)
    (loop,) = topology.boundary_loops(F)
    assert len(loop) == 2 * (4 + 5) - 4
    # shoelace area of the loop in the xy plane is positive (counter-clockwise seen from +z)
    x, y = V[loop, 0], V[loop, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) == pytest.approx(1.0)
    assert topology.boundary_vertex_mask(F, len(V)).sum() == len(loop)


def test_two_components_and_isolated_vertex():
    V1, F1 = primitives.icosphere(1)
    V2, F2 = primitives.cube()
    F = np.vstack([F1, F2 + len(V1)])
    n = len(V1) + len(V2) + 1  # plus one unreferenced vertex
    count, labels = topology.connected_components(F, n)
    assert count == 3
    assert len(set(labels[: len(V1)])) == 1 and labels[0] != labels[len(V1)]
    assert topology.euler_characteristic(F) == 4
    assert topology.genus(F) == 0


@pytest.mark.parametrize(
    "make",
    [
        lambda: primitives.icosphere(2),
        primitives.torus_mesh,
        lambda: primitives.grid(6, 7),
        lambda: primitives.cube(1),
    ],
)
def test_one_ring_follows_face_orientation(make):
    V, F = make()
    n = len(V)
    ring = topology.one_ring(F, n)
    faces = face_set(F)
    bmask = topology.boundary_vertex_mask(F, n)
    np.testing.assert_array_equal(ring.boundary, bmask)
    assert ring.regular.all()
    # neighbours as sets agree with the edge list
    E = topology.edges(F)
    deg = np.bincount(E.ravel(), minlength=n)
    np.testing.assert_array_equal(ring.valence, deg)
    for i in range(n):
        r = ring[i].tolist()
        assert len(set(r)) == len(r)
        for a, b in consecutive(r, closed=not bmask[i]):
            assert rot([i, a, b]) in faces
        if bmask[i]:  # an open fan runs from one boundary neighbour to the other
            assert bmask[r[0]] and bmask[r[-1]]
        rr = ring.reversed()[i].tolist()
        assert rr == r[::-1]
        for a, b in consecutive(rr, closed=not bmask[i]):
            assert rot([i, b, a]) in faces


def test_cube_corner_ring_by_hand():
    _, F = primitives.cube()
    # vertex 0 = (0,0,0) sees 1=(1,0,0), 5, 4, 7, 3, 2 ... in some counter-clockwise order seen
    # from outside (-1,-1,-1): check it is a rotation of the cycle 2,1,5,4,7,3
    r = topology.one_ring(F, 8)[0].tolist()
    expected = [2, 1, 5, 4, 7, 3]
    k = r.index(2)
    assert r[k:] + r[:k] == expected


def test_irregular_vertices_flagged():
    # bowtie: two triangles sharing only vertex 0
    F = np.array([[0, 1, 2], [0, 3, 4]])
    ring = topology.one_ring(F, 5)
    assert not ring.regular[0]
    assert sorted(ring[0].tolist()) == [1, 2, 3, 4]
    assert ring.regular[1:].all()
    # three triangles on one edge
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    ring = topology.one_ring(F, 5)
    assert not ring.regular[0] and not ring.regular[1]
    with pytest.raises(MeshError):
        topology.genus(F)


def test_vertex_out_of_range_message():
    _, F = primitives.cube()
    with pytest.raises(MeshError, match="out of range"):
        topology.one_ring(F, 8)[8]


@pytest.mark.parametrize(
    "make, fans",
    [
        (hostile.touching_spheres, [True, True]),
        (lambda: hostile.tetrahedra_sharing_vertex(2), [True, True]),
        (lambda: hostile.tetrahedra_sharing_vertex(3), [True, True, True]),
        (hostile.glued_torus, [True, True]),
        (hostile.sphere_touching_disk, [True, False]),
    ],
)
def test_nonmanifold_vertex_fans_listed_in_order(make, fans):
    """Vertices with several fans (the one-ring walk used to loop forever on them): each fan is
    listed separately, in counter-clockwise order, and the vertex is flagged."""
    V, F = make()
    n = len(V)
    ring = topology.one_ring(F, n)
    v = int(F[0, 0])  # the glued vertex
    assert not ring.manifold[v] and ring.n_fans[v] == len(fans)
    got = ring.fans(v)
    assert [f.closed for f in got] == fans
    faces = face_set(F)
    seen = []
    for fan in got:
        r = fan.neighbors.tolist()
        for a, b in consecutive(r, closed=fan.closed):
            assert rot([v, a, b]) in faces
        seen += fan.faces.tolist()
    assert sorted(seen) == np.flatnonzero((F == v).any(axis=1)).tolist()
    assert sorted(ring[v].tolist()) == ring[v].tolist()  # not a disk: listed by index
    others = np.ones(n, dtype=bool)
    others[v] = False
    assert ring.manifold[others].all() and (ring.n_fans[others] == 1).all()
    assert ring.boundary[v] == (False in fans)


def test_one_ring_of_a_vertex_in_no_face():
    ring = topology.one_ring(np.array([[0, 1, 2]]), 4)
    assert ring.n_fans[3] == 0 and ring.fans(3) == [] and ring.manifold[3]
    assert ring[3].tolist() == []
