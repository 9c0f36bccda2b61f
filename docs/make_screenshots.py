"""Regenerate the README screenshots of every viewer panel (headless, EGL).

Run: ``python docs/make_screenshots.py``. Uses ../shared/meshes/armadillo.obj for the spectral
panel when present, the bundled assets otherwise.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "img"
ARMADILLO = ROOT.parent / "shared" / "meshes" / "armadillo.obj"

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
}


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:  # polyscope writes .ini files into the cwd
        for name, args in SHOTS.items():
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
