"""The mesh pencil ``K u = λ M u`` of the Laplace–Beltrami eigenproblem and its solve.

``K = −C`` (``C`` the cotangent stiffness, negative semidefinite) with ``M`` the lumped vertex
area, or the graph Laplacian ``K = D − A`` with ``M = I``. The eigensolver itself is mesh-free:
:func:`meshlap_core.linalg.eigsolve.pencil_eigenpairs`.
"""

from __future__ import annotations

import time
from typing import Any, Literal

import numpy as np
import scipy.sparse as sp

from .. import laplacian as _lap
from ..errors import MeshError
from ..linalg.common import ProgressCallback, SolveInfo
from ..linalg.eigsolve import check_k, pencil_eigenpairs
from ..options import (
    AREA_KINDS,
    LAPLACIAN_KINDS,
    MASS_AREA,
    AreaKind,
    LaplacianKind,
    check_choice,
)
from ..types import FloatArray, IntArray, as_mesh


def check_options(laplacian: str, area: str) -> None:
    """Raise :class:`MeshError` naming the argument for an unknown Laplacian or area kind."""
    check_choice(laplacian, LAPLACIAN_KINDS, "Laplacian", "laplacian")
    check_choice(area, AREA_KINDS, "area")


def problem_options(laplacian: str, area: str) -> dict[str, str]:
    """The options that define the eigenproblem, as stored in a basis and its cache file:
    ``{"laplacian": ..., "mass": area or "identity"}`` (the uniform Laplacian always uses
    ``M = I``; the key stays ``"mass"``, the name of the CLI flag and of the cache format)."""
    check_options(laplacian, area)
    return {"laplacian": laplacian, "mass": "identity" if laplacian == "uniform" else area}


def spectral_operators(
    V: FloatArray,
    F: IntArray,
    laplacian: LaplacianKind = "cotan",
    area: AreaKind = MASS_AREA,
) -> tuple[sp.csr_matrix, FloatArray]:
    """The pencil ``(K, m)`` of the eigenproblem ``K u = λ diag(m) u``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    laplacian : {"cotan", "uniform"}
        ``"cotan"``: ``K = −C`` with ``C`` the (negative semidefinite) cotangent stiffness.
        ``"uniform"``: ``K = D − A``, the graph Laplacian (``−D·L`` for the uniform Laplacian
        ``L = D⁻¹A − I``), with ``m = 1``.
    area : {"voronoi", "barycentric"}
        Lumped vertex areas used as ``m`` for ``"cotan"`` (ignored for ``"uniform"``).

    Returns
    -------
    K : (n,n) scipy.sparse.csr_matrix
        Symmetric positive semidefinite, rows summing to 0.
    m : (n,) float
        Positive masses.

    Raises
    ------
    MeshError
        No faces, or a vertex with zero mass (unreferenced, or only in degenerate faces): the
        mass matrix would be singular. :func:`meshlap_core.io.load_mesh` removes unreferenced
        vertices.
    """
    check_options(laplacian, area)
    V, F = as_mesh(V, F)
    n = len(V)
    if n == 0 or len(F) == 0:
        raise MeshError("the mesh has no faces; spectral processing needs a surface", "F")
    if laplacian == "uniform":
        A = _lap.adjacency_matrix(F, n)
        deg = np.asarray(A.sum(axis=1)).ravel()
        K = (sp.diags(deg) - A).tocsr()
        m = np.ones(n)
    else:
        K = (-_lap.cotan_stiffness(V, F)).tocsr()
        m = _lap.vertex_areas(V, F, area)
    bad = np.flatnonzero(~(m > 0))
    if len(bad):
        raise MeshError(
            f"vertex {int(bad[0])} (and {len(bad) - 1} more) has zero area: it is unreferenced "
            "or only in degenerate faces, so the mass matrix is singular; remove unreferenced "
            "vertices and degenerate faces first (meshlap's load_mesh does)",
            "V",
        )
    K.sum_duplicates()
    K.sort_indices()
    return K, m


def weyl_density(m: FloatArray, laplacian: str) -> float:
    """Expected eigenvalues per unit of ``λ``: Weyl's law ``N(λ) ≈ area·λ/4π``; for the graph
    Laplacian of a near-equilateral mesh the same count gives ``λ ≈ 4π√3·N/n``."""
    if laplacian == "cotan":
        return float(m.sum() / (4 * np.pi))
    return float(len(m) / (4 * np.pi * np.sqrt(3.0)))


def laplacian_eigenpairs(
    V: FloatArray,
    F: IntArray,
    k: int,
    *,
    laplacian: LaplacianKind = "cotan",
    area: AreaKind = MASS_AREA,
    pencil: tuple[sp.csr_matrix, FloatArray] | None = None,
    progress: ProgressCallback | None = None,
    known: tuple[FloatArray, FloatArray] | None = None,
    method: Literal["auto", "dense", "sparse"] = "auto",
    **tuning: Any,
) -> tuple[FloatArray, FloatArray, SolveInfo]:
    """The ``k`` smallest eigenpairs of ``K u = λ M u`` for a mesh (``K = −C``, see module).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    k : int
        Number of eigenpairs, ``1 <= k <= n`` (``k = n`` is the full basis).
    laplacian, area : str
        See :func:`spectral_operators`.
    pencil : (K, m), optional
        ``spectral_operators(V, F, laplacian, area)`` when the caller has it already: it is
        not assembled again.
    progress, known, method, **tuning
        See :func:`pencil_eigenpairs`.

    Returns
    -------
    lam : (k,) float
        Ascending frequencies ``>= 0`` of ``−Δ``.
    U : (n,k) float, F-ordered
        ``UᵀMU = I``.
    info : SolveInfo

    Examples
    --------
    >>> from meshlap_core.primitives import icosphere
    >>> lam, U, info = laplacian_eigenpairs(*icosphere(3), 4)
    >>> [round(float(x), 2) for x in lam]   # 0, then l(l+1) = 2 three times (unit sphere)
    [0.0, 2.0, 2.0, 2.0]
    """
    t_start = time.perf_counter()
    V, F = as_mesh(V, F)
    k = check_k(k, len(V), "k")
    check_options(laplacian, area)
    K, m = spectral_operators(V, F, laplacian, area) if pencil is None else pencil
    t_ops = time.perf_counter() - t_start
    if "density" not in tuning:
        tuning["density"] = weyl_density(m, laplacian)
    lam, U, info = pencil_eigenpairs(
        K, m, k, progress=progress, known=known, method=method, **tuning
    )
    info.timings["operators"] = t_ops
    info.timings["total"] = time.perf_counter() - t_start
    return lam, U, info
