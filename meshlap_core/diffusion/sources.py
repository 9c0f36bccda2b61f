"""Source vertices of a diffusion or a distance: checked once, named like ``meshlap onering``.

A source is a vertex index, 0-based, counted after the loader's repairs (the numbering that
``meshlap inspect`` and ``meshlap onering`` print).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ..errors import MeshError
from ..types import IntArray


def check_sources(sources: int | Iterable[int], n: int, name: str = "vertex") -> IntArray:
    """The distinct source vertices as a sorted ``(s,)`` int64 array.

    Parameters
    ----------
    sources : int or iterable of int
        Vertex indices in ``0 … n−1``.
    n : int
        Number of vertices.
    name : str
        The argument an error is attributed to (the CLI passes ``"--vertex"``).

    Raises
    ------
    MeshError
        No source, a non-integer, or an index out of range (the message gives the range).
    """
    arr = np.atleast_1d(np.asarray(sources))
    if arr.size == 0:
        raise MeshError("give at least one source vertex", name)
    if arr.dtype.kind not in "iu":
        if arr.dtype.kind != "f" or not np.all(np.isfinite(arr)) or np.any(arr != np.round(arr)):
            raise MeshError(f"vertex indices must be integers, got {arr.tolist()!r}", name)
    arr = arr.astype(np.int64).ravel()
    bad = arr[(arr < 0) | (arr >= n)]
    if bad.size:
        raise MeshError(
            f"vertex {int(bad[0])} is out of range (the mesh has {n} vertices: 0..{n - 1})", name
        )
    return np.unique(arr)


def unit_heat(sources: IntArray, mass: np.ndarray) -> np.ndarray:
    """A unit of heat at each source: ``u₀ = Σ_s e_s / m_s``, so ``∫ u₀ = 1ᵀ M u₀`` is the
    number of sources.

    Parameters
    ----------
    sources : (s,) int
    mass : (n,) float
        Lumped vertex areas (positive at the sources).

    Returns
    -------
    u0 : (n,) float
    """
    u0 = np.zeros(len(mass))
    np.add.at(u0, sources, 1.0 / mass[sources])
    return u0
