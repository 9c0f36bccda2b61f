"""Curvature of a mesh: mean curvature two ways, Gaussian curvature, and Gauss–Bonnet.

Run: ``python examples/curvature_of_a_mesh.py [MESH]`` (default: the bundled bumpy sphere).
Uses only the public API of ``meshlap_core``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from meshlap_core import curvature_field, load_mesh, vertex_areas

DEFAULT = Path(__file__).resolve().parents[1] / "assets" / "bumpy.obj"


def main(path: str | Path = DEFAULT) -> dict[str, float]:
    mesh = load_mesh(path)
    H_uniform = curvature_field(mesh.V, mesh.F, "uniform")
    H_cotan = curvature_field(mesh.V, mesh.F, "cotan", area="voronoi")
    K = curvature_field(mesh.V, mesh.F, "gaussian", area="voronoi")
    total_K = float(np.sum(K * vertex_areas(mesh.V, mesh.F, "voronoi")))
    chi = len(mesh.V) - mesh.report.n_edges + len(mesh.F)
    print(f"{Path(path).name}: {len(mesh.V)} vertices, {len(mesh.F)} faces, χ = {chi}")
    print(f"mean curvature, cotangent: median {np.median(H_cotan):+.4f}")
    print(f"mean curvature, uniform:   median {np.median(H_uniform):+.4f} (not a curvature)")
    print(f"∫K dA = {total_K:.6f}, 2πχ = {2 * np.pi * chi:.6f}  (Gauss–Bonnet)")
    return {"total_K": total_K, "chi": chi, "median_H": float(np.median(H_cotan))}


if __name__ == "__main__":
    main(*sys.argv[1:2])
