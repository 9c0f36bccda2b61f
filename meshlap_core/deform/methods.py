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

    Examples
    --------
    The solver of a method by its name; zero move gives the rest pose back exactly:

    >>> import numpy as np
    >>> from meshlap_core import grid, make_deformer
    >>> V, F = grid(5, 5)
    >>> left, right = np.flatnonzero(V[:, 0] == 0), np.flatnonzero(V[:, 0] == 1)
    >>> solver = make_deformer("biharmonic", V, F, right, left)
    >>> type(solver).__name__
    'HarmonicDeformer'
    >>> bool(np.array_equal(solver.update(V[right]), V))
    True
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
    >>> from meshlap_core import deform_mesh
    >>> from meshlap_core.primitives import icosphere
    >>> V, F = icosphere(2)
    >>> U = deform_mesh(V, F, [0], V[[0]] + 0.1, "biharmonic", fixed=[100])
    >>> U.shape
    (162, 3)

    One call: the x = 1 column of a grid lifted by 1 with x = 0 held; the harmonic
    displacement rises linearly with x:

    >>> import numpy as np
    >>> from meshlap_core import deform_mesh, grid
    >>> V, F = grid(5, 5)
    >>> left, right = np.flatnonzero(V[:, 0] == 0), np.flatnonzero(V[:, 0] == 1)
    >>> U = deform_mesh(V, F, right, V[right] + [0, 0, 1], method="harmonic", fixed=left)
    >>> bool(np.allclose(U[:, 2], V[:, 0]))
    True
    """
    solver = make_deformer(method, V, F, handles, fixed, **options)
    if isinstance(solver, ArapDeformer):
        solver.set_targets(targets)
        return solver.run(check_iters(iters)).copy()
    return solver.update(targets).copy()
