"""Spectral mesh processing: the Laplace–Beltrami eigenbasis, reconstruction from k modes, caching.

Sign convention: the Laplacians of this project are negative semidefinite (``Δx = −2Hn``,
:mod:`meshlap_core.laplacian`). The eigenproblem solved here is the generalized symmetric one

    K u = λ M u,      K = −C  (symmetric positive semidefinite),  M = diag(m) > 0,

whose eigenvalues ``0 = λ₀ ≤ λ₁ ≤ …`` are the non-negative frequencies of ``−Δ = −M⁻¹C``. ``C``
is the cotangent stiffness (libigl ``cotmatrix``) and ``M`` the lumped Voronoi (default) or
barycentric area; with ``laplacian="uniform"`` it is the combinatorial graph Laplacian
``K = D − A`` (the symmetric form ``−D·L`` of the uniform Laplacian ``L = D⁻¹A − I``) with the
identity as mass. Eigenvectors are ``M``-orthonormal (``UᵀMU = I``) and the spectral
reconstruction of a per-vertex field ``X`` from the first ``k`` modes is the ``M``-orthogonal
projection ``U_k U_kᵀ M X`` (projecting with ``U_kᵀ X`` instead is the classic bug: it is not a
projection unless ``M = I``, and the error stops decreasing with ``k``).

Open meshes get natural (Neumann) boundary conditions (nothing to do: ``C`` assembled from the
faces is the Neumann stiffness), and every connected component contributes one zero eigenvalue
whose eigenvector is the normalized indicator of the component (deflated exactly).

Modules:

* :mod:`.operators`: the pencil ``(K, m)`` (:func:`spectral_operators`) and
  :func:`laplacian_eigenpairs`, which hands it to the mesh-free eigensolver
  :func:`meshlap_core.linalg.eigsolve.pencil_eigenpairs` (shift-invert block Lanczos with
  spectrum slicing and inertia checks; dense ``eigh`` for small meshes);
* :mod:`.basis`: :class:`SpectralBasis`, computed once (and cached on disk, keyed by a hash of
  the mesh and the options), then answering reconstructions for any ``k`` quickly: the
  coefficients ``UᵀMX`` are kept and ``reconstruct(k)`` moves incrementally from the previous
  ``k`` or from a stored checkpoint, so a slider move costs ``O(n·|Δk|)``;
* :mod:`.cache`: the cache files and their checks.

References
----------
Lévy, "Laplace-Beltrami eigenfunctions towards an algorithm that understands geometry", 2006.
Vallet & Lévy, "Spectral geometry processing with manifold harmonics", 2008.
"""

from __future__ import annotations

from ..linalg.common import ProgressCallback, SolveInfo
from ..linalg.eigsolve import pencil_eigenpairs
from .basis import ReconstructionErrors, SpectralBasis, reconstruct
from .cache import CACHE_FORMAT, default_cache_dir, mesh_key
from .operators import laplacian_eigenpairs, problem_options, spectral_operators

__all__ = [
    "CACHE_FORMAT",
    "ProgressCallback",
    "ReconstructionErrors",
    "SolveInfo",
    "SpectralBasis",
    "default_cache_dir",
    "laplacian_eigenpairs",
    "mesh_key",
    "pencil_eigenpairs",
    "problem_options",
    "reconstruct",
    "spectral_operators",
]
