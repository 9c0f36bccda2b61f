"""How far each vertex's neighbourhood is from having moved rigidly: the rotation error.

For vertex ``i`` with rest spokes ``e_ij = p_i − p_j`` and deformed spokes ``e'_ij``,

    err_i = sqrt( min_{R ∈ SO(3)} Σ_j |w_ij| ‖e'_ij − R e_ij‖²  /  Σ_j |w_ij| ‖e_ij‖² ),

the relative RMS deviation of the one-ring from its best-fitting rotation (the local step of
ARAP with the absolute cotangent weights, so every term counts and the error is never
negative): 0 where the ring was rotated and translated, about 0.1 where its edges changed by
10 %. It compares every method alike: Laplacian coordinates under a rotation of the handles
show large errors where details kept their orientation; ARAP drives them down.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import MeshError
from ..types import FloatArray, IntArray, as_mesh, as_vertices
from .arap_energy import ArapEnergy
from .rotations import fit_rotations_stacked


def rotation_error(
    V: FloatArray, F: IntArray, U: FloatArray, *, terms: ArapEnergy | None = None
) -> tuple[FloatArray, Any]:
    """Each vertex's relative deviation from a rotation of its one-ring (module docstring).

    Parameters
    ----------
    V : (n,3) float
        Rest positions.
    F : (m,3) int
    U : (n,3) float
        Deformed positions (the same number of vertices as ``V``).
    terms : ArapEnergy, optional
        The spokes energy of ``V`` with absolute weights, from an earlier call (built when
        ``None``).

    Returns
    -------
    err : (n,) float
        0 for vertices in no face.
    terms : ArapEnergy
        Pass it back on the next call with the same ``V, F``.

    Examples
    --------
    A rotation of the whole mesh has no error; stretching by 2 along x does:

    >>> import numpy as np
    >>> from meshlap_core import grid, rotation_error
    >>> V, F = grid(5, 5)
    >>> R = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])  # 90° about z
    >>> float(rotation_error(V, F, V @ R.T)[0].max()) < 1e-12
    True
    >>> float(rotation_error(V, F, V * [2, 1, 1])[0].max()) > 0.5
    True
    """
    V, F = as_mesh(V, F)
    U = as_vertices(U, "U")
    if U.shape != V.shape:
        raise MeshError(f"U: {len(U)} deformed positions for {len(V)} vertices of V")
    return rotation_error_checked(V, F, U, terms)


def rotation_error_checked(
    V: FloatArray, F: IntArray, U: FloatArray, terms: ArapEnergy | None = None
) -> tuple[FloatArray, ArapEnergy]:
    """:func:`rotation_error` of arrays already checked (a deformer's own ``V, F`` and
    positions, on every drag: no second coercion of a big mesh)."""
    if terms is None:
        terms = ArapEnergy(V, F, "spokes", absolute=True)
    R = fit_rotations_stacked(terms.covariances(U))
    residual = terms.vertex_energy(U, R)
    scale = terms.rest_terms()
    ok = scale > 0
    err = np.zeros(len(V))
    err[ok] = np.sqrt(np.maximum(residual[ok], 0.0) / scale[ok])
    return err, terms
