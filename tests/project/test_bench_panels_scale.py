"""``benchmarks/bench_panels_scale.py`` (every panel driven on a big scan, issue 21) on a small
generated mesh: the drive reaches every panel and every step succeeds, so the benchmark a
2.77M scan is measured with does not rot (the scan itself is a benchmark, not a test: its
load alone takes about a minute on a shared 2-core machine)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from meshlap_core import primitives
from meshlap_core.io import save_mesh

pytest.importorskip("polyscope")

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_panels_scale.py"
PANELS = {"mesh", "curvature", "onering", "spectral", "smoothing", "surfaces", "export"}


def test_every_panel_is_driven_and_usable(python_ok, tmp_path):
    mesh = tmp_path / "torus.obj"
    save_mesh(mesh, *primitives.torus_mesh())
    out = python_ok(SCRIPT, mesh, "--k", "12", "--wait-basis").stdout
    rows = [
        [c.strip() for c in line.strip("|").split("|")]
        for line in out.splitlines()
        if line.startswith("| ") and not line.startswith("| panel")
    ]
    assert {r[0] for r in rows} == PANELS, out
    failed = [r for r in rows if r[4] != "yes"]
    assert not failed, out
    spectral = next(r for r in rows if r[0] == "spectral")
    assert "k = 12: computed" in spectral[1]
    steps = next(r for r in rows if r[1] == "3 implicit steps")
    assert len(re.findall(r"\d s", steps[5])) == 3  # each step's time is reported
    assert all(float(r[2]) >= 0 and int(r[3]) > 0 for r in rows)  # seconds, peak RSS
