"""Every script in ``examples/`` runs on the bundled mesh and its numbers are right."""

from __future__ import annotations

import ast
import itertools
import runpy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def _example(name: str):
    return runpy.run_path(str(ROOT / "examples" / name))["main"]


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_examples_use_only_the_public_api(path):
    import meshlap_core

    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("meshlap"):
            assert node.module == "meshlap_core", f"{path.name} imports from {node.module}"
            for alias in node.names:
                assert alias.name in meshlap_core.__all__, alias.name


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_examples_run_as_scripts(path):
    res = subprocess.run(
        [sys.executable, str(path)], capture_output=True, text=True, timeout=300, cwd=ROOT
    )
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip()


def test_curvature_example_satisfies_gauss_bonnet(capsys):
    out = _example("curvature_of_a_mesh.py")()
    assert out["chi"] == 2
    assert out["total_K"] == pytest.approx(4 * np.pi, abs=1e-9)
    assert out["median_H"] > 0  # a sphere-like mesh, outward normals: H > 0 (Δx = −2Hn)


def test_spectral_example_errors_never_increase_with_k(capsys):
    sweep = _example("spectral_k_sweep.py")(k=40)
    assert all(b <= a + 1e-12 for a, b in itertools.pairwise(sweep))
    assert sweep[-1] < sweep[0]


def test_implicit_smoothing_example_denoises(capsys):
    errors = _example("implicit_smoothing.py")(steps=5)
    assert errors[1] < errors[0]  # one implicit step removes part of the noise
