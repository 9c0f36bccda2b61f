"""``meshlap onering MESH --vertex I [--reverse] [--json]``: the ordered one-ring of a vertex.

A non-manifold vertex (several fans of faces: two spheres touching at a point, tetrahedra
sharing a vertex, a closed fan plus an open one) is flagged and each of its fans is listed in
order.
"""

from __future__ import annotations

import argparse

import numpy as np

from ..errors import MeshError
from ..io import load_mesh
from ..topology import one_ring
from ._common import add_json_flag, emit_json, print_report


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("onering", help="ordered neighbours of a vertex (counter-clockwise)")
    p.add_argument("mesh", help="mesh file (OBJ, OFF, PLY, STL)")
    p.add_argument(
        "--vertex", type=int, required=True, help="vertex index (0-based, after repairs)"
    )
    p.add_argument("--reverse", action="store_true", help="clockwise instead of counter-clockwise")
    add_json_flag(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    mesh = load_mesh(args.mesh)
    n = mesh.n_vertices
    if not 0 <= args.vertex < n:
        raise MeshError(
            f"vertex {args.vertex} is out of range (the mesh has {n} vertices: 0..{n - 1})",
            "--vertex",
        )
    # a vertex's ring depends on its own faces only: on a 2 M-face mesh this is what keeps the
    # command at the cost of loading the file
    own = np.flatnonzero((mesh.F == args.vertex).any(axis=1))
    ring = one_ring(mesh.F[own], n)
    if args.reverse:
        ring = ring.reversed()
    i = args.vertex
    nbrs = [int(x) for x in ring[i]]
    result = {
        "vertex": i,
        "neighbors": nbrs,
        "boundary": bool(ring.boundary[i]),
        "valence": len(nbrs),
        "order": "clockwise" if args.reverse else "counter-clockwise",
        "ordered": bool(ring.regular[i]),
        "manifold": bool(ring.manifold[i]),
        "fans": [
            {
                "neighbors": [int(x) for x in fan.neighbors],
                "faces": [int(f) for f in own[fan.faces]],  # indices into the mesh's faces
                "closed": fan.closed,
            }
            for fan in ring.fans(i)
        ],
        "repairs": list(mesh.report.repairs),
        "warnings": list(mesh.report.warnings),
    }
    print_report(args.mesh, mesh.report)  # vertex indices are those after the repairs
    if args.json:
        emit_json(result)
    else:
        _print_text(result)
    return 0


def _print_text(result: dict) -> None:
    """The human-readable form: the ring, and each fan of a non-manifold vertex."""
    i, nbrs = result["vertex"], result["neighbors"]
    kind = "boundary (open fan)" if result["boundary"] else "interior (closed cycle)"
    print(f"vertex {i}: {kind}, valence {len(nbrs)}, {result['order']}")
    if not result["ordered"]:
        print(
            "  neighbourhood is not a disk (non-manifold or inconsistently oriented): "
            "neighbours listed by index, not in order"
        )
    for k, j in enumerate(nbrs):
        print(f"  {k:>3}  {j}")
    if not result["manifold"]:
        fans = result["fans"]
        print(f"  non-manifold vertex: {len(fans)} fans, each in {result['order']} order")
        for k, fan in enumerate(fans):
            kind = "closed" if fan["closed"] else "open"
            print(f"  fan {k} ({kind}): {' '.join(str(j) for j in fan['neighbors'])}")
