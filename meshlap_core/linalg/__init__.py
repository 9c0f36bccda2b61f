"""Mesh-free sparse and dense linear algebra: factorizations with inertia, block Lanczos,
spectrum slicing, SPD solves and BLAS thread control.

Nothing in this package knows about meshes: it takes matrices and returns numbers. The mesh
operators that feed it live in :mod:`meshlap_core.laplacian` and :mod:`meshlap_core.spectral`.
"""
