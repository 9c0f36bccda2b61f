"""Regenerate the README screenshots of every viewer panel (headless, EGL).

Run: ``python docs/make_screenshots.py [NAME ...]`` (names: the keys of :data:`SHOTS`,
``inspector``, ``diffusion_distance``, ``diffusion_heat``; all when none). Uses
../shared/meshes/armadillo.obj for the spectral panel and nefertiti.obj for the flatten panel
when present, the bundled assets otherwise. The inspector shot is taken on a perturbed grid
(:func:`perturbed_grid`, seeded) at a vertex whose ring has a negative cotangent weight.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from meshlap_core import primitives
from meshlap_core.io import save_mesh

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "img"
ARMADILLO = ROOT.parent / "shared" / "meshes" / "armadillo.obj"
SCAN = ROOT.parent / "shared" / "meshes" / "armadillo_igl.obj"
NEFERTITI = ROOT.parent / "shared" / "meshes" / "nefertiti.obj"

SHOTS = {
    "curvature": [str(ROOT / "assets" / "bumpy.obj"), "--panel", "curvature", "--field", "cotan"],
    "onering": [str(ROOT / "assets" / "bumpy.obj"), "--panel", "onering", "--vertex", "100"],
    "spectral": [
        str(ARMADILLO if ARMADILLO.is_file() else ROOT / "assets" / "bumpy.obj"),
        "--panel",
        "spectral",
        "--k",
        "50",
    ],
    "smoothing": [str(ROOT / "assets" / "bumpy.obj"), "--panel", "smoothing"],
    "surfaces": ["--panel", "surfaces"],
    "curvature_lab": ["--panel", "curvature_lab"],
    "flatten": [  # the checkerboard through LSCM, the layout and the copy by area distortion
        str(NEFERTITI if NEFERTITI.is_file() else ROOT / "assets" / "bumpy.obj"),
        "--panel",
        "flatten",
        "--map",
        "lscm",
        "--distortion",
        "area",
    ],
}


DIFFUSION_VERTEX = 2259
"""A vertex of ``assets/bumpy.obj`` up and left of the one facing the camera: the distance's
isolines and the heat's spread both in view."""


def heat_session(folder: Path) -> Path:
    """A session of the Diffusion view showing heat two ways on the bumpy sphere: 60 modes
    computed, a unit of heat at :data:`DIFFUSION_VERTEX`, t = 10 h², 10 backward Euler steps,
    the eigen-expansion and their difference on copies beside it, isolines of the heat on."""
    path = folder / "heat.json"
    session = {
        "format": "meshlap-session",
        "version": 1,
        "mesh": str(ROOT / "assets" / "bumpy.obj"),
        "panel": "diffusion",
        "spectral": {"computed": True, "k_request": 60, "k": 60},
        "diffusion": {
            "show": "heat",
            "sources": [DIFFUSION_VERTEX],
            "log_t": 1.0,
            "steps": 10,
            "isoline_fields": {"heat": {"on": True, "count": 10}},
        },
    }
    path.write_text(json.dumps(session))
    return path


INSPECT_VERTEX = 54
"""A vertex of :func:`perturbed_grid` near the centre with a negative weight (w = -0.50)."""


def perturbed_grid(seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """A 10 x 10 grid with its vertices jittered in the plane (±0.3 of a cell, seeded) and a
    gentle bump: some triangles become obtuse, so some cotangent weights are negative."""
    V, F = primitives.grid(10, 10)
    V = V.copy()
    h = 1.0 / 9.0
    V[:, :2] += np.random.default_rng(seed).uniform(-0.3, 0.3, (len(V), 2)) * h
    V[:, 2] += 0.15 * h * np.sin(3 * V[:, 0]) * np.cos(2 * V[:, 1])
    return V, F


def directions_session(folder: Path) -> Path | None:
    """A session opening the curvature lab on the armadillo_igl scan: the Rusinkiewicz
    estimator's H with its principal directions as crosses (black k1, green k2)."""
    if not SCAN.is_file():
        return None
    from meshlap_app.state.session import Session, write_session

    s = Session(mesh=SCAN, panel="curvature_lab", camera=closeup_camera(folder))
    s.settings["curvature_lab"].update(
        {"source": "mesh", "estimator": "rusinkiewicz", "quantity": "H", "show": "estimate"}
    )
    return write_session(folder / "directions.json", s)


CLOSEUP = """
import json, sys
import numpy as np
import polyscope as ps
from meshlap_app.state.camera import captured
from meshlap_app.viewer import init_polyscope
from meshlap_core.io import load_mesh
m = load_mesh(sys.argv[1])
init_polyscope("openGL3_egl")
ps.register_surface_mesh("m", m.V, m.F)
lo, hi = m.V.min(0), m.V.max(0)
c = 0.5 * (lo + hi)
top = (m.V[:, 1] > lo[1] + 0.7 * (hi[1] - lo[1])) & (abs(m.V[:, 0] - c[0]) < 0.12 * (hi[0] - lo[0]))
d = np.linalg.norm(hi - lo)
head = m.V[top].mean(0) + np.array([0.09, 0.0, 0.0]) * d  # the head left of the panel
ps.look_at(head + np.array([-0.1, 0.05, 0.42]) * d, head)
print(json.dumps(captured(json.loads(ps.get_view_as_json()))))
"""
"""Run in a child process (EGL): the camera looking at the scan's head (the middle of its top
third, between the raised hands) from the front."""


def closeup_camera(folder: Path) -> dict:
    """polyscope's view of :data:`SCAN`'s head (a session's camera, :data:`CLOSEUP`)."""
    import json

    out = subprocess.run(
        [sys.executable, "-c", CLOSEUP, str(SCAN)],
        check=True,
        cwd=folder,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:  # polyscope writes .ini files into the cwd
        grid = Path(tmp) / "perturbed_grid.obj"
        save_mesh(grid, *perturbed_grid())
        shots = dict(SHOTS)
        shots["inspector"] = [str(grid), "--panel", "onering", "--vertex", str(INSPECT_VERTEX)]
        bumpy = str(ROOT / "assets" / "bumpy.obj")
        shots["diffusion_distance"] = [
            bumpy, "--panel", "diffusion", "--vertex", str(DIFFUSION_VERTEX),
        ]  # fmt: skip
        shots["diffusion_heat"] = ["--session", str(heat_session(Path(tmp)))]
        session = directions_session(Path(tmp))
        if session is not None:  # principal directions on a scan
            shots["curvature_directions"] = ["--session", str(session)]
        only = sys.argv[1:]  # names of the shots to take (all when none)
        for name, args in shots.items():
            if only and name not in only:
                continue
            out = OUT / f"{name}.png"
            cmd = [
                sys.executable,
                "-m",
                "meshlap_core.cli",
                "view",
                *args,
                "--screenshot",
                str(out),
            ]
            subprocess.run(cmd, check=True, cwd=tmp, capture_output=True)
            print(f"wrote {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
