"""Time ``meshlap animate``: a 60-frame smoothing GIF of armadillo_igl (target < 30 s).

Run: ``python benchmarks/bench_animate.py [--mesh armadillo_igl.obj] [--size 960x540]``.

End to end, as a user runs it (a subprocess: start-up, mesh load, EGL start, 60 frames rendered
with polyscope, captions, GIF quantization and the atomic write), ``--iters 59`` (frames 0..59).
Uses ../shared/meshes (falls back to the bundled bumpy sphere when absent, and says so).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _util import print_table, shared_mesh

ASSET = Path(__file__).resolve().parents[1] / "assets" / "bumpy.obj"


def time_animation(mesh: Path, size: str, frames: int, out: Path) -> tuple[float, int]:
    """Wall seconds of one ``meshlap animate`` run and the size of the GIF (bytes)."""
    cmd = [
        sys.executable,
        "-m",
        "meshlap_core.cli",
        "animate",
        str(mesh),
        "--panel",
        "smoothing",
        "--method",
        "implicit",
        "--lam",
        "1",
        "--noise",
        "0.005",
        "--iters",
        str(frames - 1),
        "--size",
        size,
        "--out",
        str(out),
    ]
    t = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, cwd=out.parent)
    wall = time.perf_counter() - t
    if res.returncode != 0:
        raise SystemExit(f"meshlap animate failed: {res.stderr.strip().splitlines()[-1]}")
    return wall, out.stat().st_size


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="armadillo_igl.obj")
    ap.add_argument("--size", action="append", help="WxH (repeatable); default 960x540, 640x360")
    ap.add_argument("--frames", type=int, default=60)
    args = ap.parse_args()
    mesh = shared_mesh(args.mesh) or ASSET
    print(f"mesh: {mesh.name}, {args.frames} frames, implicit smoothing (lam 1, noise 0.005)")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["MESHLAP_CACHE_DIR"] = tmp
        for size in args.size or ["960x540", "640x360"]:
            wall, nbytes = time_animation(mesh, size, args.frames, Path(tmp) / "smooth.gif")
            rows.append([size, wall, args.frames / wall, f"{nbytes / 1e6:.1f} MB"])
    print_table(["size", "wall s (target < 30)", "frames/s", "GIF"], rows)


if __name__ == "__main__":
    main()
