"""The viewer's curvature fields and their labels.

Pure data (no numpy, no polyscope), so ``meshlap view``'s argument parser imports it at start-up
without loading the viewer.
"""

from __future__ import annotations

# field name -> (label shown to users, signed?)
FIELD_LABELS: dict[str, tuple[str, bool]] = {
    "uniform": ("mean curvature H (uniform Laplacian)", True),
    "cotan": ("mean curvature H (cotangent Laplace-Beltrami)", True),
    "gaussian": ("Gaussian curvature K (angle deficit)", True),
    "k1": ("principal curvature k1", True),
    "k2": ("principal curvature k2", True),
    "difference": ("H uniform - H cotangent", True),
}

FIELDS: tuple[str, ...] = tuple(FIELD_LABELS)
"""Curvature fields the viewer shows (``meshlap view --field``)."""
