"""Project promises: README's commands (and the install page's), CI in sync, a headless core,
ruff clean."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = text.split("```", 2)[1]
    return [ln for ln in block.splitlines()[1:] if ln.strip() and not ln.startswith("#")]


def test_readme_starts_with_the_two_commands_and_ci_runs_the_second():
    text = (ROOT / "README.md").read_text()
    assert text.index("```") < 400, "the set-up commands come first"
    view_cmd, test_cmd = readme_commands()[:2]
    assert "meshlap view" in view_cmd and "pip install" in view_cmd
    assert "pytest" in test_cmd and "[test]" in test_cmd
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    assert test_cmd in ci


def test_install_page_repeats_the_readme_commands():
    text = (ROOT / "docs" / "install.md").read_text()
    block = text.split("```", 2)[1]
    commands = [ln for ln in block.splitlines()[1:] if ln.strip() and not ln.startswith("#")]
    assert commands == readme_commands()[:2]


def test_ci_runs_the_fast_solver_step_of_the_install_page():
    readme = (ROOT / "README.md").read_text()
    assert "**Fast solver (optional).**" in readme and "docs/install.md#fast-solver" in readme
    text = (ROOT / "docs" / "install.md").read_text()
    block = text.split("**Fast solver (optional).**", 1)[1].split("```", 2)[1]
    steps = [ln for ln in block.splitlines()[1:] if ln.strip()]
    assert any("apt-get install" in ln for ln in steps) and any("[fast]" in ln for ln in steps)
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    for ln in steps:
        assert ln in ci, ln


def test_core_never_imports_polyscope():
    code = (
        "import importlib, pkgutil, sys, meshlap_core, meshlap_core.cli\n"
        "for m in pkgutil.walk_packages(meshlap_core.__path__, 'meshlap_core.'):\n"
        "    if not m.name.endswith('__main__'):\n"
        "        importlib.import_module(m.name)\n"
        "import meshlap_app.state\n"
        "assert 'polyscope' not in sys.modules, 'polyscope imported'\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr


@pytest.mark.parametrize("args", [["check"], ["format", "--check"]], ids=["check", "format"])
def test_ruff_clean(args):
    ruff = shutil.which("ruff") or str(Path(sys.executable).parent / "ruff")
    if not Path(ruff).exists():
        pytest.skip("ruff is not installed (it comes with the [test] extra)")
    res = subprocess.run([ruff, *args, str(ROOT)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stdout + res.stderr


def test_assets_are_what_the_script_makes():
    import numpy as np

    from meshlap_core import primitives
    from meshlap_core.io import load_mesh

    mesh = load_mesh(ROOT / "assets" / "bumpy.obj")
    V, F = primitives.bumpy_sphere(4)
    assert mesh.F.shape == F.shape
    np.testing.assert_allclose(mesh.V, V, atol=1e-6)
