"""Max error of cotangent H and angle-deficit K on unit icospheres, per vertex-area choice.

Run: ``python benchmarks/convergence_icosphere.py``. Prints the README table.
"""

from __future__ import annotations

import numpy as np
from _util import print_table

from meshlap_core import primitives
from meshlap_core.curvature import gaussian_curvature, mean_curvature_cotan


def main() -> None:
    rows = []
    for s in range(1, 7):
        V, F = primitives.icosphere(s)
        row: list[object] = [s, len(V)]
        for area in ("barycentric", "voronoi"):
            row += [
                f"{np.abs(mean_curvature_cotan(V, F, area) - 1).max():.2e}",
                f"{np.abs(gaussian_curvature(V, F, area) - 1).max():.2e}",
            ]
        rows.append(row)
    print_table(
        [
            "subdivisions",
            "vertices",
            "cotan H, barycentric",
            "K, barycentric",
            "cotan H, Voronoi",
            "K, Voronoi",
        ],
        rows,
    )


if __name__ == "__main__":
    main()
