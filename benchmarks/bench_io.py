"""Loading speed: meshlap's own parsers + validator against ``igl.read_triangle_mesh``.

Run from the repository root::

    python benchmarks/bench_io.py            # armadillo_loop.obj and dragon.obj
    python benchmarks/bench_io.py bunny.obj  # any file in ../shared/meshes, or a path

For each mesh it prints the best of ``--repeat`` runs (seconds) of

* ``igl``:      ``igl.read_triangle_mesh`` (no validation at all),
* ``parse``:    our parser only,
* ``validate``: ``validate_mesh`` on the parsed arrays (repairs + topology report),
* ``load``:     ``load_mesh`` = parse + validate,
* ``pipeline``: ``load_mesh`` + cotangent stiffness + Voronoi mass + uniform Laplacian, against
  ``igl.read_triangle_mesh`` + ``igl.cotmatrix`` + ``igl.massmatrix`` + ``igl.adjacency_matrix``,

and the ratios ours / libigl. Timings are wall-clock in one process; no thresholds are checked.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path

import igl
import numpy as np

from meshlap_core import laplacian
from meshlap_core.io import load_mesh
from meshlap_core.io.load import _parse
from meshlap_core.validate import validate_mesh

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "meshes"


def best(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def bench(path: Path, repeat: int) -> None:
    src = str(path)
    data = path.read_bytes()
    ext = path.suffix.lower()
    parsed = _parse(ext, data, src)

    def ours_pipeline() -> None:
        m = load_mesh(path)
        laplacian.cotan_stiffness(m.V, m.F)
        laplacian.mass_matrix(m.V, m.F, "voronoi")
        laplacian.uniform_laplacian(m.F, m.n_vertices)

    def igl_pipeline() -> None:
        V, F = igl.read_triangle_mesh(src)
        igl.cotmatrix(V, F)
        igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
        igl.adjacency_matrix(F)

    t_igl = best(lambda: igl.read_triangle_mesh(src), repeat)
    t_parse = best(lambda: _parse(ext, data, src), repeat)
    t_val = best(lambda: validate_mesh(parsed.V, parsed.faces, src), repeat)
    t_load = best(lambda: load_mesh(path), repeat)
    t_pipe_ours = best(ours_pipeline, repeat)
    t_pipe_igl = best(igl_pipeline, repeat)
    m = load_mesh(path)
    V, F = igl.read_triangle_mesh(src)
    same = np.array_equal(m.V, V) and np.array_equal(m.F, F)
    print(
        f"{path.name}: {m.n_vertices:,} vertices, {m.n_faces:,} faces, "
        f"{len(data) / 1e6:.1f} MB; arrays identical to libigl: {same}"
    )
    if m.report.repairs:
        print(f"  repairs: {'; '.join(m.report.repairs)}")
    print(f"  igl.read_triangle_mesh {t_igl:8.3f} s")
    print(f"  parse                  {t_parse:8.3f} s   ratio {t_parse / t_igl:5.2f}")
    print(f"  validate               {t_val:8.3f} s")
    print(f"  load_mesh              {t_load:8.3f} s   ratio {t_load / t_igl:5.2f}")
    print(
        f"  pipeline ours / igl    {t_pipe_ours:8.3f} s / {t_pipe_igl:.3f} s   "
        f"ratio {t_pipe_ours / t_pipe_igl:5.2f}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("meshes", nargs="*", default=["armadillo_loop.obj", "dragon.obj"])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    for name in args.meshes:
        path = Path(name) if Path(name).exists() else SHARED / name
        if not path.is_file():
            print(f"{name}: not found (looked in {SHARED})")
            continue
        bench(path, args.repeat)


if __name__ == "__main__":
    main()
