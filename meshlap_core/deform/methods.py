"""One entry point for every method: build a deformer by name, or deform once.

The methods side by side on the same handles (:data:`~meshlap_core.options.DEFORM_METHODS`):

==============  ====================================  ===========================================
method          minimizes                             per drag
==============  ====================================  ===========================================
laplacian       ``‖Δx − δ‖²_M`` (+ soft constraints)   one back-substitution
harmonic        ``∫|∇d|²`` of the displacement          one back-substitution
biharmonic      ``∫(Δd)²``                             one back-substitution
triharmonic     ``∫|∇Δd|²``                            one back-substitution
arap            ``Σ w_ij‖(x_i−x_j) − R_i(p_i−p_j)‖²``   one local/global iteration
==============  ====================================  ===========================================
"""

from __future__ import annotations

from typing import Any

from ..linalg.common import ProgressCallback
from ..options import DEFORM_METHODS, HARMONIC_ORDERS, DeformMethod, check_choice
from ..types import FloatArray
from .arap import ArapDeformer, check_iters
from .base import Deformer
from .harmonic import HarmonicDeformer
from .laplacian_coordinates import LaplacianCoordinates


def make_deformer(
    method: DeformMethod,
    V: FloatArray,
    F: Any,
    handles: Any,
    fixed: Any = None,
    *,
    progress: ProgressCallback | None = None,
    cancel: Any = None,
    **options: Any,
) -> Deformer:
    """The deformer of ``method`` for one handle set (its precomputation done).

    Parameters
    ----------
    method : {"laplacian", "harmonic", "biharmonic", "triharmonic", "arap"}
    V : (n,3) float
    F : (m,3) int
    handles : (h,) int
    fixed : (f,) int, optional
    progress, cancel :
        For the precomputation (see :class:`~meshlap_core.deform.harmonic.HarmonicDeformer`).
    **options :
        The method's own: ``constraints``, ``weight`` (laplacian); ``energy``, ``rotations``
        (arap).
    """
    check_choice(method, DEFORM_METHODS, "deformation method", "method")
    hooks = {"progress": progress, "cancel": cancel}
    if method == "arap":
        return ArapDeformer(V, F, handles, fixed, **hooks, **options)
    if method == "laplacian":
        return LaplacianCoordinates(V, F, handles, fixed, **hooks, **options)
    return HarmonicDeformer(V, F, handles, fixed, k=HARMONIC_ORDERS[method], **hooks, **options)


def deform_mesh(
    V: FloatArray,
    F: Any,
    handles: Any,
    targets: Any,
    method: DeformMethod = "arap",
    fixed: Any = None,
    *,
    iters: int = 10,
    **options: Any,
) -> FloatArray:
    """Deform once: the shape ``(n,3)`` with the ``handles`` at ``targets`` ``(h,3)``.

    ``iters`` ARAP iterations from the rest pose (ignored by the linear methods); ``options``
    as :func:`make_deformer`.

    Examples
    --------
    >>> from meshlap_core.primitives import icosphere
    >>> V, F = icosphere(2)
    >>> U = deform_mesh(V, F, [0], V[[0]] + 0.1, "biharmonic", fixed=[100])
    >>> U.shape
    (162, 3)
    """
    solver = make_deformer(method, V, F, handles, fixed, **options)
    if isinstance(solver, ArapDeformer):
        solver.set_targets(targets)
        return solver.run(check_iters(iters)).copy()
    return solver.update(targets).copy()
