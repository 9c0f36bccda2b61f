"""Small meshes the tests build (beside :mod:`meshlap_core.primitives`)."""

from __future__ import annotations

import numpy as np

from meshlap_core import primitives


def perturbed_grid(seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The screenshot's mesh (docs/make_screenshots.py): obtuse triangles, negative weights."""
    V, F = primitives.grid(10, 10)
    V = V.copy()
    V[:, :2] += np.random.default_rng(seed).uniform(-0.3, 0.3, (len(V), 2)) / 9.0
    V[:, 2] += 0.15 / 9.0 * np.sin(3 * V[:, 0]) * np.cos(2 * V[:, 1])
    return V, F
