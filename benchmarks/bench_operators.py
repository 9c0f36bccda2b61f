"""Load + validate + all operators + all curvature fields, ours vs the bare libigl calls.

Run: ``python benchmarks/bench_operators.py [--repeat 3]``. Both pipelines run in this process,
interleaved, on the large meshes of ../shared/meshes; the table gives the best of ``repeat``
wall times per stage and the ratio ours / libigl. Target: the whole pipeline within 1.5× of
bare libigl, and under 2 s for armadillo_loop (173k vertices).

The libigl pipeline is what a user would write by hand: ``read_triangle_mesh``, ``cotmatrix``,
two ``massmatrix`` calls, ``adjacency_matrix``, angle-weighted normals, ``gaussian_curvature``,
and the mean / principal curvature arithmetic. It does no validation at all, which is why
``dragon`` (unreferenced vertices, duplicate faces) is run through it only after our repair:
libigl's ``principal_curvature`` crashes the process on unreferenced vertices.
"""

from __future__ import annotations

import argparse
from functools import partial

import igl
import numpy as np
from _util import best_of, print_table, shared_mesh

from meshlap_core.curvature import all_curvature_fields, principal_curvature_quadric
from meshlap_core.io import load_mesh
from meshlap_core.laplacian import cotan_stiffness, mass_matrix, uniform_laplacian
from meshlap_core.topology import boundary_vertex_mask

MESHES = ["armadillo_igl.obj", "nefertiti.obj", "dragon.obj", "armadillo_loop.obj"]


def igl_operators(V, F):
    C = igl.cotmatrix(V, F)
    Mv = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
    Mb = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC)
    A = igl.adjacency_matrix(F)
    return C, Mv, Mb, A


def igl_curvatures(V, F):
    C, _, Mb, A = igl_operators(V, F)
    N = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_ANGLE)
    a = Mb.diagonal()
    Hc = -0.5 * np.sum((C @ V) / a[:, None] * N, axis=1)
    deg = np.asarray(A.sum(axis=1)).ravel()
    Hu = -0.5 * np.sum(((A @ V) / deg[:, None] - V) * N, axis=1)
    K = igl.gaussian_curvature(V, F) / a
    r = np.sqrt(np.maximum(Hc * Hc - K, 0))
    return Hu, Hc, K, Hc + r, Hc - r


def ours_operators(V, F):
    return (
        cotan_stiffness(V, F),
        mass_matrix(V, F, "voronoi"),
        mass_matrix(V, F, "barycentric"),
        uniform_laplacian(F, len(V)),
    )


def rel_diff(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| / max |b|."""
    return float(np.abs(a - b).max() / (np.abs(b).max() + 1e-300))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quadric", action="store_true", help="also time libigl's quadric fit")
    args = ap.parse_args()
    rows = []
    for name in MESHES:
        path = shared_mesh(name)
        if path is None:
            continue
        t_load_o, mesh = best_of(lambda p=path: load_mesh(p), args.repeat)
        V, F = mesh.V, mesh.F
        if name == "dragon.obj":  # libigl cannot be trusted on the raw file: feed it our repair
            t_load_i = float("nan")
        else:
            t_load_i, _ = best_of(lambda p=path: igl.read_triangle_mesh(str(p)), args.repeat)
        t_ops_o, _ = best_of(partial(ours_operators, V, F), args.repeat)
        t_ops_i, _ = best_of(partial(igl_operators, V, F), args.repeat)
        t_cur_o, fo = best_of(partial(all_curvature_fields, V, F), args.repeat)
        t_cur_i, fi = best_of(partial(igl_curvatures, V, F), args.repeat)
        # boundary vertices differ on purpose (we use pi - sum, libigl 2pi - sum): compare inside
        inside = ~boundary_vertex_mask(F, len(V))
        agree = max(
            rel_diff(fo["cotan"][inside], fi[1][inside]),
            rel_diff(fo["gaussian"][inside], fi[2][inside]),
        )
        tot_o = t_load_o + t_ops_o + t_cur_o
        tot_i = (t_load_i if np.isfinite(t_load_i) else t_load_o) + t_ops_i + t_cur_i
        rows.append(
            [
                name.removesuffix(".obj"),
                len(V),
                t_load_o,
                t_load_i,
                t_ops_o,
                t_ops_i,
                t_cur_o,
                t_cur_i,
                tot_o,
                tot_i,
                f"{tot_o / tot_i:.2f}x",
                f"{agree:.1e}",
            ]
        )
        if args.quadric:
            t_q, _ = best_of(partial(principal_curvature_quadric, V, F), 1)
            print(f"{name}: libigl quadric fit {t_q:.2f} s")
    print_table(
        [
            "mesh",
            "vertices",
            "load ours",
            "load igl",
            "ops ours",
            "ops igl",
            "curv ours",
            "curv igl",
            "total ours",
            "total igl",
            "ratio",
            "max rel diff",
        ],
        rows,
    )
    note = "dragon: libigl gets our repaired mesh and our load time"
    print(f"(seconds, best of {args.repeat}; {note})")


if __name__ == "__main__":
    main()
