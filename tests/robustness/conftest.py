"""The small mesh the robustness tests run commands on."""

from __future__ import annotations

from pathlib import Path

import pytest

from meshlap_core import primitives, save_mesh


@pytest.fixture
def mesh(tmp_path: Path) -> Path:
    """The level-1 icosphere (42 vertices) written to ``tmp_path/sphere.obj``."""
    path = tmp_path / "sphere.obj"
    save_mesh(path, *primitives.icosphere(1))
    return path
