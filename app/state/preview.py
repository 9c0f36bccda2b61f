"""The quick look at a big mesh being opened: its geometry as parsed and a cheap colour field,
shown while the validation and the curvature fields finish in the background (no polyscope).

``meshlap view SCAN`` reads, validates and colours a scan in a job (:mod:`meshlap_app.jobs`);
on a 0.7–3-million-vertex scan the validation and the curvature fields take longer than the
parse. As soon as the file is parsed, the job hands a :class:`MeshPreview` to the window
(``Reporter.partial``), which shows that geometry coloured by :func:`preview_field` (labelled a
preview) until the validated mesh and its curvature fields replace it. When validation leaves
the geometry as parsed (the common case), the window keeps the structure it registered for the
preview and only uploads the final colours.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshlap_core.options import CURVATURE_FIELD_UNITS, titled
from meshlap_core.types import FloatArray, IntArray

PREVIEW_LABEL = titled(
    "preview: uniform H, curvature being computed", CURVATURE_FIELD_UNITS["uniform"]
)
"""The colour map's name on the preview (said on screen: not the final field)."""
PREVIEW_FACES = 100_000
"""A mesh with fewer faces gets no preview (validated and coloured in well under a second)."""


@dataclass
class MeshPreview:
    """A parsed, not yet validated mesh and its preview field.

    Attributes
    ----------
    name : str
        The file's name.
    V : (n,3) float64
    F : (m,3) int64
        As parsed (indices in range, coordinates finite).
    field : (n,) float64
        :func:`preview_field` of ``(V, F)``.
    vminmax : (float, float)
        Its colour range ``(−r, r)``, ``r`` the 98th percentile of ``|field|`` (one outlier
        cannot wash the map out).
    box : (2,3) float64 or None
        ``[V.min(axis=0), V.max(axis=0)]``, computed where the preview is made (the window
        fits its display to these two corners, the same fit as to ``V``, without a pass over
        millions of points on the UI thread); ``None``: ``V`` itself is used.
    """

    name: str
    V: FloatArray
    F: IntArray
    field: FloatArray
    vminmax: tuple[float, float] = (-1.0, 1.0)
    box: FloatArray | None = None

    def corners(self) -> FloatArray:
        """What the display is fitted to: :attr:`box`, else ``V``."""
        return self.V if self.box is None else self.box

    def same_geometry(self, V: FloatArray, F: IntArray) -> bool:
        """Whether the validated mesh ``(V, F)`` is exactly the geometry previewed."""
        if self.V is V and self.F is F:
            return True
        return (
            self.V.shape == np.shape(V)
            and self.F.shape == np.shape(F)
            and np.array_equal(self.F, F)
            and np.array_equal(self.V, V)
        )


def preview_field(V: FloatArray, F: IntArray) -> FloatArray:
    """Mean curvature from the uniform Laplacian, counted over the faces' half-edges.

    ``H = −½ (Δx · n̂)`` (``Δx = −2Hn``, so ``H > 0`` on a sphere with outward normals), with
    ``Δx_i = (1/d_i) Σ_(i→j) (x_j − x_i)`` summed over the half-edges ``i→j`` of the faces
    around ``i`` (each face ``(i, j, k)`` gives ``x_j + x_k − 2x_i``, i.e. ``S − 3x_i`` with
    ``S = x_i + x_j + x_k``; ``d_i`` counts them) and ``n̂`` the unit area-weighted vertex
    normal. On a closed manifold mesh each neighbour is reached by two half-edges, so ``Δx``
    is exactly the uniform Laplacian ``(D⁻¹A − I) x``; on a boundary it differs (a preview
    only). No edge table, no sparse matrix: ``bincount`` calls over the faces' corners.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
        Triangles with indices in ``[0, n)``.

    Returns
    -------
    H : (n,) float64
        0 at vertices in no face or with a zero normal.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    n = len(V)
    C = np.ascontiguousarray(F.T)  # (3, m): corner c of every face, then c + 1, ...
    count = np.bincount(C.ravel(), minlength=n).astype(np.float64)  # faces around each vertex

    def around(w: FloatArray) -> FloatArray:
        """Σ over the faces around each vertex of the per-face values ``w (m,)``."""
        out = np.bincount(C[0], weights=w, minlength=n)
        out += np.bincount(C[1], weights=w, minlength=n)
        out += np.bincount(C[2], weights=w, minlength=n)
        return out

    lap = np.empty((3, n))
    e1, e2 = np.empty((3, C.shape[1])), np.empty((3, C.shape[1]))
    for d in range(3):  # one coordinate at a time: 1-D gathers, no (m,3,3) temporary
        x = np.ascontiguousarray(V[:, d])
        x0, x1, x2 = x[C[0]], x[C[1]], x[C[2]]
        # Σ over the faces around i of (x_j + x_k − 2x_i) = Σ S_f − 3·count_i·x_i
        lap[d] = around(x0 + x1 + x2) - 3.0 * count * x
        np.subtract(x1, x0, out=e1[d])
        np.subtract(x2, x0, out=e2[d])
    (ax, ay, az), (bx, by, bz) = e1, e2
    N = np.empty((3, n))
    for d, nd in enumerate((ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)):
        N[d] = around(nd)  # area-weighted
    del e1, e2, ax, ay, az, bx, by, bz
    length = np.sqrt(np.einsum("dn,dn->n", N, N))
    degree = 2.0 * count  # half-edges leaving each vertex
    ok = (degree > 0) & (length > 0)
    H = np.zeros(n)
    H[ok] = -0.5 * np.einsum("dn,dn->n", lap[:, ok], N[:, ok]) / (degree[ok] * length[ok])
    return H


def make_preview(name: str, V: FloatArray, F: IntArray) -> MeshPreview:
    """The :class:`MeshPreview` of a parsed mesh (run in the loading job)."""
    H = preview_field(V, F)
    r = float(np.percentile(np.abs(H), 98.0)) if len(H) else 0.0
    r = r if np.isfinite(r) and r > 0 else 1.0
    box = np.array([V.min(axis=0), V.max(axis=0)]) if len(V) else None
    return MeshPreview(name, V, F, H, (-r, r), box)
