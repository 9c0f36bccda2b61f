"""Hostile round 3, class test: every command, run with the most expensive combination of its
options that a check must stop (and, where that is quick, the most expensive one accepted),
under an address-space limit of 3 GiB (``RLIMIT_AS``, set in the child).

Each run must end in a clear refusal (exit 2, one line naming the option) or succeed within the
limit; never the OS killing it, a ``MemoryError`` reported as "out of memory", or an internal
error. The meshes are small, so that the runs are quick: the point is that ``--k``, ``--iters``,
``--res``, ``--frames``, ``--size`` are bounded before the work starts.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from meshlap_core import primitives, save_mesh

LIMIT = 3 * 2**30

# name -> (argv, expected exit code, a fragment of the error line)
CASES: dict[str, tuple[list[str], int, str]] = {
    "info": (["info", "{small}", "--json"], 0, ""),
    "curvature": (
        ["curvature", "{small}", "--method", "k2", "--area", "voronoi", "--out", "{out}/k.ply"],
        0,
        "",
    ),
    "inspect": (["inspect", "{small}", "--vertex", "0", "--area", "voronoi", "--json"], 0, ""),
    "onering": (["onering", "{small}", "--vertex", "0", "--json"], 0, ""),
    "spectral full basis": (
        [
            "spectral",
            "{small}",
            "--k",
            "642",
            "--reconstruct",
            "1,642",
            "--save-reconstruction",
            "{out}/rec",
            "--out",
            "{out}/b.npz",
            "--no-cache",
        ],
        0,
        "",
    ),
    "spectral k = n on 40k vertices": (
        ["spectral", "{large}", "--k", "40962", "--no-cache"],
        2,
        "--k: 40962 modes on 40962 vertices need",
    ),
    "spectral k beyond n": (["spectral", "{small}", "--k", "643"], 2, "--k"),
    "smooth 5000 implicit cotan": (
        [
            "smooth",
            "{small}",
            "--method",
            "implicit",
            "--laplacian",
            "cotan",
            "--lam",
            "0.1",
            "--iters",
            "5000",
            "--out",
            "{out}/s.obj",
            "--json",
        ],
        0,
        "",
    ),
    "smooth iters beyond 10^7": (
        ["smooth", "{small}", "--method", "implicit", "--lam", "0.1", "--iters", "10000001"],
        2,
        "--iters",
    ),
    "smooth iters beyond int64": (
        ["smooth", "{small}", "--method", "explicit", "--lam", "0.1", "--iters", "9" * 30],
        2,
        "--iters",
    ),
    "denoise-eval iters": (["denoise-eval", "{small}", "--iters", "10000001"], 2, "--iters"),
    "denoise-eval noise": (["denoise-eval", "{small}", "--noise", "1e308"], 2, "--noise"),
    "surface mesh res": (
        ["surface", "helicoid", "--mesh", "{out}/h.obj", "--res", "100000"],
        2,
        "--res",
    ),
    "surface convergence res": (
        ["surface", "sphere", "--convergence", "--res", "8,100000"],
        2,
        "--res",
    ),
    "animate frames": (
        ["animate", "--panel", "surfaces", "--theta", "--frames", "2001", "--out", "{out}/t.gif"],
        2,
        "--frames",
    ),
    "animate size": (
        [
            "animate",
            "--panel",
            "surfaces",
            "--theta",
            "--size",
            "4097x4097",
            "--out",
            "{out}/t.gif",
        ],
        2,
        "--size",
    ),
    "animate iters": (
        ["animate", "{small}", "--panel", "smoothing", "--iters", "5001", "--out", "{out}/s.gif"],
        2,
        "--iters",
    ),
    "animate noise": (
        ["animate", "{small}", "--panel", "smoothing", "--noise", "1e308", "--out", "{out}/s.gif"],
        2,
        "--noise",
    ),
    "animate k": (
        ["animate", "{small}", "--panel", "spectral", "--k", "1:100000", "--out", "{out}/k.gif"],
        2,
        "--k",
    ),
}


def _limit_memory() -> None:  # runs in the child before exec
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


@pytest.fixture(scope="module")
def meshes(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("resources")
    small, large = folder / "ico3.ply", folder / "ico6.ply"
    save_mesh(small, *primitives.icosphere(3))  # 642 vertices
    save_mesh(large, *primitives.icosphere(6))  # 40962 vertices
    return {"small": small, "large": large}


def _run(name: str, meshes: dict[str, Path], folder: Path) -> subprocess.CompletedProcess[str]:
    out = folder / name.replace(" ", "_")
    out.mkdir()
    args = [a.format(out=out, **meshes) for a in CASES[name][0]]
    env = {**os.environ, "MESHLAP_CACHE_DIR": str(out / "cache")}
    return subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=out,
        env=env,
        preexec_fn=_limit_memory,
    )


@pytest.fixture(scope="module")
def results(meshes, tmp_path_factory) -> dict[str, subprocess.CompletedProcess[str]]:
    """Every case run once, two at a time (each run is mostly the interpreter starting)."""
    folder = tmp_path_factory.mktemp("runs")
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {name: pool.submit(_run, name, meshes, folder) for name in CASES}
        return {name: f.result() for name, f in futures.items()}


@pytest.mark.parametrize("name", sorted(CASES))
def test_expensive_options_are_bounded_under_a_memory_limit(name, results):
    _, expected, words = CASES[name]
    res = results[name]
    assert res.returncode >= 0, f"killed by signal {-res.returncode}"
    assert res.returncode == expected, res.stderr
    assert "out of memory" not in res.stderr and "internal error" not in res.stderr
    if expected == 2:
        lines = res.stderr.splitlines()
        assert len(lines) == 1 and lines[0].startswith("meshlap: error: "), res.stderr
        assert words in lines[0]
        assert res.stdout == ""
