"""Max error of cotangent H and angle-deficit K on unit icospheres, per vertex-area choice.

Run: ``python benchmarks/convergence_icosphere.py``. Prints the README table: the
``meshlap surface sphere --convergence --mesher icosphere --res 1,2,3,4,5,6`` study
(:func:`meshlap_core.curvature.convergence.convergence_study`), its max errors per level.
"""

from __future__ import annotations

from _util import print_table

from meshlap_core.curvature.convergence import convergence_study

COLUMNS = {
    "cotan H, barycentric": "H cotan barycentric",
    "K, barycentric": "K deficit barycentric",
    "cotan H, Voronoi": "H cotan voronoi",
    "K, Voronoi": "K deficit voronoi",
}


def main() -> None:
    study = convergence_study("sphere", range(1, 7), mesher="icosphere")
    rows = [
        [s, n, *(f"{study.errors[name]['max'][k]:.2e}" for name in COLUMNS.values())]
        for k, (s, n) in enumerate(zip(study.resolutions, study.n_vertices, strict=True))
    ]
    print_table(["subdivisions", "vertices", *COLUMNS], rows)


if __name__ == "__main__":
    main()
