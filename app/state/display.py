"""World → display coordinates for everything the viewer uploads (pure numpy, no polyscope)."""

from __future__ import annotations

import numpy as np


class Display:
    """World → display coordinates ``x_d = (x − c) · s`` for everything uploaded from the mesh.

    polyscope stores positions as float32 (largest 3.4e38, smallest normal 1.2e-38), while the
    loader accepts coordinates up to ``MAX_COORDINATE`` = 1e75 and extents down to 1e-60: a mesh
    near 1e74 would upload as ``inf`` and render a blank frame. Centring on the bounding box and
    scaling by a power of two (exact in float64) to a diagonal near 1 makes every accepted mesh
    representable. The panels' numbers stay in world units; only uploads go through this.
    """

    def __init__(self) -> None:
        self.centre = np.zeros(3)
        self.scale = 1.0

    def fit(self, V: np.ndarray) -> None:
        """Fit to the positions ``V (n,3)`` (bounding-box centre; diagonal → about 1)."""
        V = np.asarray(V, dtype=np.float64)
        if len(V) == 0:
            self.centre, self.scale = np.zeros(3), 1.0
            return
        lo, hi = V.min(axis=0), V.max(axis=0)
        self.centre = 0.5 * lo + 0.5 * hi  # no overflow of lo + hi near the float64 limit
        half = 0.5 * hi - 0.5 * lo
        diag = 2.0 * float(np.linalg.norm(half))
        self.scale = float(2.0 ** -np.round(np.log2(diag))) if diag > 0 else 1.0

    def points(self, P: np.ndarray) -> np.ndarray:
        """Display positions of world points ``P (k,3)``."""
        return (np.asarray(P, dtype=np.float64) - self.centre) * self.scale

    def vectors(self, D: np.ndarray) -> np.ndarray:
        """Display vectors of world displacements ``D (k,3)`` (scaled, not shifted)."""
        return np.asarray(D, dtype=np.float64) * self.scale
