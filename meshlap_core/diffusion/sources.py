"""Source vertices of a diffusion or a distance: checked once, named like ``meshlap onering``.

A source is a vertex index, 0-based, counted after the loader's repairs (the numbering that
``meshlap inspect`` and ``meshlap onering`` print).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ..errors import MeshError
from ..types import IntArray, as_field, as_indices


def check_sources(sources: int | Iterable[int], n: int, name: str = "sources") -> IntArray:
    """The distinct source vertices as a sorted ``(s,)`` int64 array.

    Parameters
    ----------
    sources : int or iterable of int
        Vertex indices in ``0 … n−1``.
    n : int
        Number of vertices.
    name : str
        The argument an error is attributed to (default ``"sources"``; the CLI passes
        ``"--vertex"``).

    Raises
    ------
    MeshError
        No source, a non-integer (``2.5``, ``True``, a complex or a string: never rounded or
        cast), or an index out of range (shown as given, ``2⁶³`` or ``1e20`` too, with the
        range).
    """
    arr = as_indices(sources, n, name)
    if arr.size == 0:
        raise MeshError("give at least one source vertex", name)
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

    Raises
    ------
    MeshError
        Bad sources (as :func:`check_sources`, naming ``sources``), masses that are not a
        finite ``(n,)`` real array, or a source whose mass is not positive.
    """
    m = as_field(mass, len(np.asarray(mass).reshape(-1)), "mass", columns=False)
    src = check_sources(sources, len(m), "sources")
    if not np.all(m[src] > 0):
        bad = int(src[np.flatnonzero(~(m[src] > 0))[0]])
        raise MeshError(f"the mass at source {bad} is not positive", "mass")
    u0 = np.zeros(len(m))
    np.add.at(u0, src, 1.0 / m[src])
    return u0
