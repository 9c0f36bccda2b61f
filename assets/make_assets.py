"""Regenerate the bundled meshes in this folder from ``meshlap_core.primitives``.

Run from anywhere: ``python assets/make_assets.py``. The files are small (under 200 kB each)
and deterministic, so they are committed together with this script.
"""

from __future__ import annotations

from pathlib import Path

from meshlap_core import primitives
from meshlap_core.io import save_mesh

HERE = Path(__file__).resolve().parent

ASSETS = {
    "bumpy.obj": lambda: primitives.bumpy_sphere(4),  # the viewer's default mesh
    "icosphere.obj": lambda: primitives.icosphere(3),
    "torus.obj": lambda: primitives.torus_mesh(48, 24),
    "grid.obj": lambda: primitives.grid(20, 20),
    "cube.obj": lambda: primitives.cube(0),
}


def main() -> None:
    for name, make in ASSETS.items():
        V, F = make()
        save_mesh(HERE / name, V, F)
        print(f"wrote {name}: {len(V)} vertices, {len(F)} faces")


if __name__ == "__main__":
    main()
