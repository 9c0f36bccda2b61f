"""Mesh-free sparse and dense linear algebra: factorizations with inertia, block Lanczos,
spectrum slicing, the generalized symmetric eigensolver and BLAS thread control.

Nothing in this package knows about meshes: it takes matrices and returns numbers. The mesh
operators that feed it live in :mod:`meshlap_core.laplacian` and :mod:`meshlap_core.spectral`.

Modules, bottom up: :mod:`.common` (array aliases, ``SolveInfo``, the progress callback),
:mod:`.blas` (thread limits, in-place ``gemm``/``trsm``), :mod:`.factor` (``LDLᵀ`` with
inertia, the shift-invert operator), :mod:`.lanczos` (block Lanczos, DCGS2, Cholesky QR),
:mod:`.slice_worker` (one slice), :mod:`.slicing` (the slice plan and its inertia checks),
:mod:`.components` (components, null space), :mod:`.checks` (residuals, orthonormality),
:mod:`.refine` (pairs above the promised residual refined),
:mod:`.eigsolve` (:func:`~meshlap_core.linalg.eigsolve.pencil_eigenpairs`: dense or sliced).
"""
