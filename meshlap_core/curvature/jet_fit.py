"""The scale-aware curvature estimator: a weighted osculating jet over a ball in world units.

At every vertex ``x_i`` the vertices within distance ``r`` (a world length, not a ring count)
define a local frame: the normal is the weighted mean of their angle-weighted normals (so it
follows the face orientation), and ``(t1, t2)`` span the plane orthogonal to it. The height
``z`` of the neighbours above that plane is fitted in the weighted least-squares sense by the
degree-2 jet ``z = c₀ + c₁x + c₂y + ½(a x² + 2b xy + c y²)`` with the compactly supported weights
``w = (1 − d²/r²)²``, and the curvature of the fitted graph at ``(0, 0)`` (with its slope, so
an imperfect frame does not bias it) gives ``κ₁ ≥ κ₂`` and their directions: the shape operator
``I⁻¹ II`` with ``I = [[1 + c₁², c₁c₂], [c₁c₂, 1 + c₂²]]`` and ``II = −[[a, b], [b, c]] / W``,
``W = √(1 + c₁² + c₂²)`` (the minus: positive where the graph bends away from its ``+z``
normal, the project's sign).

A ball of radius ``r`` averages the noise of ``~πr²ρ`` vertices (``ρ`` the vertex density): the
noise in the curvature falls like ``σ/(r² √(πr²ρ))`` while the bias of the jet grows like
``r²``, so a larger radius trades resolution for robustness. The automatic default
:func:`default_jet_radius` estimates the noise and grows the radius with it.

References
----------
F. Cazals & M. Pouget, "Estimating differential quantities using polynomial fitting of
osculating jets", SGP 2003 (degree-2 jets, convergence of the fit).
N. Amenta & Y. J. Kil / Yang & Qian, "Direct computing of surface curvatures for point-set
surfaces", 2007 (fits over a world-radius ball, the scale the user chooses).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..errors import MeshError
from ..laplacian import mean_edge_length, uniform_laplacian
from ..noise import bbox_diagonal
from ..options import MAX_FIT_PAIRS
from ..types import FloatArray, IntArray, as_mesh
from .fields import _face_geometry, _normals_from
from .principal import PrincipalCurvatures, eig_sym2, tangent_frames

JET_RADIUS_EDGES = 3.0
"""The automatic radius is at least this many mean edge lengths (enough neighbours to fit)."""
JET_RADIUS_GAIN = 0.47
"""``C`` of the automatic radius ``C (σ̂ h D³)^(1/5)`` (calibrated once on the torus R = 3,
r = 1 with 32k vertices: 0.47 at 0.1 % and 0.75 at 1 % normal noise)."""
MAX_PAIRS = 2_000_000
"""Neighbour pairs processed at once (bounds the memory of one chunk to ~300 MB)."""


def estimate_normal_noise(V: FloatArray, F: IntArray) -> float:
    """Robust estimate ``σ̂`` of the noise along the normals (world units).

    The offset of every vertex from its neighbours' centroid along its normal,
    ``r_i = −(L_u x)_i · n_i``, has standard deviation ``σ √(1 + 1/d_i)`` for independent
    noise ``N(0, σ²)`` along the normals at valence ``d_i`` (about ``1.08 σ`` at valence 6);
    ``σ̂ = 1.4826 · median|r_i| / 1.08`` (the median absolute deviation, so that features do
    not count as noise). On a clean mesh it is of the order ``h²κ``, not zero.
    """
    V, F = as_mesh(V, F)
    fn, theta = _face_geometry(V, F)
    N = _normals_from(F, len(V), fn, theta)
    res = np.einsum("ij,ij->i", uniform_laplacian(F, len(V)) @ V, N)
    used = np.zeros(len(V), dtype=bool)
    used[F.ravel()] = True
    return float(1.4826 * np.median(np.abs(res[used])) / 1.08) if used.any() else 0.0


def default_jet_radius(V: FloatArray, F: IntArray) -> float:
    """The automatic radius ``max(3 h, C (σ̂ h D³)^(1/5))``.

    ``h`` the mean edge length, ``σ̂`` :func:`estimate_normal_noise`, ``D`` the bounding-box
    diagonal (the length scale of the shape), ``C =`` :data:`JET_RADIUS_GAIN`. The power 1/5
    balances the jet's bias (``∝ r²``) against the noise it averages (the curvature's standard
    deviation ``∝ σ/(r² √(r²/h²))``): the optimum grows only like ``(σ h)^(1/5)``.
    """
    V, F = as_mesh(V, F)
    if len(F) == 0:
        raise MeshError("the jet fit needs a mesh with edges", "F")
    h = mean_edge_length(V, F)
    sigma = estimate_normal_noise(V, F)
    D = bbox_diagonal(V)
    if not D > 0:
        return JET_RADIUS_EDGES * h
    # C (σ h D³)^(1/5) written as C D (σ h / D²)^(1/5): no overflow at 1e74 (D⁵ would be
    # 1e370) nor underflow at 1e-55
    return max(JET_RADIUS_EDGES * h, JET_RADIUS_GAIN * D * ((sigma / D) * (h / D)) ** 0.2)


def _sums(S: sp.csr_matrix, cols: list[np.ndarray]) -> np.ndarray:
    """``S @ c`` for every column ``c`` (one contiguous sparse product each), ``(m, len(cols))``."""
    out = np.empty((S.shape[0], len(cols)))
    for k, c in enumerate(cols):
        out[:, k] = S @ np.ascontiguousarray(c)
    return out


def _chunk(
    X: list[np.ndarray], Nv: FloatArray, tree: cKDTree, idx: np.ndarray, r: float
) -> tuple[FloatArray, ...]:
    """The jet coefficients (slopes ``c1, c2``; second derivatives ``a, b, c``) and frames of
    the centres ``idx``; ``X`` the three coordinate arrays of all vertices."""
    P0 = np.stack([x[idx] for x in X], axis=1)
    pairs = cKDTree(P0).sparse_distance_matrix(tree, r, output_type="ndarray")
    i, j, d = pairs["i"].astype(np.int64), pairs["j"].astype(np.int64), pairs["v"]
    keep = j != idx[i]  # the centre itself (distance 0) is not always listed: add it once
    m = len(idx)
    i = np.concatenate([i[keep], np.arange(m)])
    j = np.concatenate([j[keep], idx])
    d = np.concatenate([d[keep], np.zeros(m)])
    w = (1.0 - (d / r) ** 2) ** 2
    S = sp.csr_matrix((w, (i, np.arange(len(i)))), shape=(m, len(i)))
    # frame normal: the weighted mean of the angle-weighted normals (the face orientation);
    # the jet's slope terms absorb its tilt
    nrm = _sums(S, [np.ascontiguousarray(Nv[j, k]) for k in range(3)])
    ln = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.where(ln > 1e-12, nrm / np.maximum(ln, 1e-300), Nv[idx])
    t1, t2 = tangent_frames(nrm)
    D = [(X[k][j] - P0[i, k]) / r for k in range(3)]  # scaled for conditioning
    x = D[0] * t1[i, 0] + D[1] * t1[i, 1] + D[2] * t1[i, 2]
    y = D[0] * t2[i, 0] + D[1] * t2[i, 1] + D[2] * t2[i, 2]
    z = D[0] * nrm[i, 0] + D[1] * nrm[i, 1] + D[2] * nrm[i, 2]
    # the normal equations of the basis (1, x, y, x²/2, xy, y²/2) hold the weighted moments
    # Σ w xᵖ yᵠ for p + q ≤ 4: 14 distinct ones (not the 20 products of basis pairs)
    x2, xy, y2 = x * x, x * y, y * y
    mono = {(1, 0): x, (0, 1): y, (2, 0): x2, (1, 1): xy, (0, 2): y2}
    mono |= {(3, 0): x2 * x, (2, 1): x2 * y, (1, 2): x * y2, (0, 3): y2 * y}
    mono |= {(4, 0): x2 * x2, (3, 1): x2 * xy, (2, 2): x2 * y2, (1, 3): xy * y2, (0, 4): y2 * y2}
    powers = list(mono)
    zs = [z, x * z, y * z, 0.5 * x2 * z, xy * z, 0.5 * y2 * z]
    sums = _sums(S, [mono[k] for k in powers] + zs)
    moment = {k: sums[:, c] for c, k in enumerate(powers)}
    moment[(0, 0)] = np.asarray(S.sum(axis=1)).ravel()
    # basis function k is coef[k] · x^px y^py
    exps = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]
    coefs = [1.0, 1.0, 1.0, 0.5, 1.0, 0.5]
    A = np.empty((m, 6, 6))
    for a in range(6):
        for b in range(a, 6):
            e = (exps[a][0] + exps[b][0], exps[a][1] + exps[b][1])
            A[:, a, b] = A[:, b, a] = coefs[a] * coefs[b] * moment[e]
    rhs = sums[:, len(powers) :]
    A += 1e-10 * np.eye(6) * (np.trace(A, axis1=1, axis2=2)[:, None, None] + 1e-300)
    cnt = np.bincount(i, minlength=m)
    few = np.flatnonzero(cnt < 6)
    if len(few):  # too few neighbours for a jet (6 unknowns): no estimate, said so
        raise _TooFew(int(idx[few[0]]), int(cnt[few[0]]), len(few))
    coef = np.linalg.solve(A, rhs[:, :, None])[:, :, 0]
    c1, c2 = coef[:, 1], coef[:, 2]
    a, b, c = coef[:, 3] / r, coef[:, 4] / r, coef[:, 5] / r  # back to world units
    return c1, c2, a, b, c, t1, t2, nrm


class _TooFew(Exception):
    """A vertex of a chunk has fewer than 6 vertices in its ball (vertex, count, how many)."""


def _shape_operator(c1, c2, a, b, c, t1, t2, nrm) -> tuple[FloatArray, ...]:
    Wn = np.sqrt(1.0 + c1 * c1 + c2 * c2)
    E, Fm, G = 1.0 + c1 * c1, c1 * c2, 1.0 + c2 * c2
    e, f, g = -a / Wn, -b / Wn, -c / Wn
    # I = L Lᵀ (Cholesky); principal values are the eigenvalues of L⁻¹ II L⁻ᵀ
    l11 = np.sqrt(E)
    l21 = Fm / l11
    l22 = np.sqrt(np.maximum(G - l21 * l21, 1e-300))
    m11, m21, m22 = 1.0 / l11, -l21 / (l11 * l22), 1.0 / l22
    s11 = m11 * m11 * e
    s12 = m11 * (m21 * e + m22 * f)
    s22 = m21 * m21 * e + 2 * m21 * m22 * f + m22 * m22 * g
    k1, k2, co, si = eig_sym2(s11, s12, s22)
    # parameter directions w = L⁻ᵀ y, then tangent vectors (1, 0, c1)·w₀ + (0, 1, c2)·w₁
    pu = t1 + c1[:, None] * nrm
    pv = t2 + c2[:, None] * nrm
    dirs = []
    for y0, y1 in ((co, si), (-si, co)):
        w0, w1 = m11 * y0 + m21 * y1, m22 * y1
        d = w0[:, None] * pu + w1[:, None] * pv
        dirs.append(d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300))
    normal = (nrm - c1[:, None] * t1 - c2[:, None] * t2) / Wn[:, None]
    return k1, k2, dirs[0], dirs[1], normal


def jet_curvatures(V: FloatArray, F: IntArray, radius: float | None = None) -> PrincipalCurvatures:
    """Principal curvatures and directions from a weighted degree-2 jet over a ball of world
    radius ``radius`` around every vertex (Cazals & Pouget 2003; see the module notes).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
        Used for the orientation (the angle-weighted normals) and the default radius only.
    radius : float, optional
        World units; ``None`` for :func:`default_jet_radius`. Larger is smoother and more
        robust to noise, smaller follows finer detail.

    Returns
    -------
    PrincipalCurvatures
        ``normal`` is the fitted surface's normal at the vertex.

    Raises
    ------
    MeshError
        A radius that is not a positive finite number; one whose ball holds (nearly) the
        whole mesh (at least half its bounding-box diagonal: the jet would fit one quadric
        to all of it, not the surface around the vertex); one asking more fitting work than
        :data:`~meshlap_core.options.MAX_FIT_PAIRS` (both checked before the fit); or a
        vertex with fewer than 6 vertices in its ball (a radius below the edge length: the
        jet has 6 unknowns). The automatic radius is named as such.

    Examples
    --------
    On a sphere of radius ½ both principal curvatures are 2:

    >>> from meshlap_core import icosphere, jet_curvatures
    >>> V, F = icosphere(3)
    >>> pc = jet_curvatures(0.5 * V, F)
    >>> round(float(pc.k1.mean()), 1), round(float(pc.k2.mean()), 1), pc.estimator
    (2.1, 2.1, 'jet')
    """
    V, F = as_mesh(V, F)
    auto = radius is None
    what = "the automatic radius" if auto else "the fit radius"
    if auto:
        r = default_jet_radius(V, F)
    else:
        if isinstance(radius, bool | np.bool_ | str | bytes):
            raise MeshError(f"must be a positive number (world units), got {radius!r}", "radius")
        try:
            r = float(radius)  # type: ignore[arg-type]
        except (TypeError, ValueError, OverflowError):
            raise MeshError(
                f"must be a positive number (world units), got {radius!r}", "radius"
            ) from None
    if not (np.isfinite(r) and r > 0):
        raise MeshError(f"{what} must be a positive finite number, got {r!r}", "radius")
    n = len(V)
    D = bbox_diagonal(V)
    if r >= 0.5 * D:
        raise MeshError(
            f"{what} {r:.4g} is at least half the mesh's bounding-box diagonal ({D:.4g}): each "
            "ball holds (nearly) the whole mesh and the jet would fit one quadric to all of "
            f"it; use a radius below {0.5 * D:.4g} (a few edge lengths to a tenth of the size)",
            "radius",
        )
    fn, theta = _face_geometry(V, F)
    Nv = _normals_from(F, n, fn, theta)
    tree = cKDTree(V)
    X = [np.ascontiguousarray(V[:, k]) for k in range(3)]
    sample = V[:: max(1, n // 200)]
    per = max(1, int(tree.count_neighbors(cKDTree(sample), r) / max(1, len(sample))))
    if n * per > MAX_FIT_PAIRS:
        most = r * np.sqrt(MAX_FIT_PAIRS / (n * per))  # (a ball's count grows like r²)
        raise MeshError(
            f"{what} {r:.4g} holds ~{per} vertices per ball: ~{n * per:.1e} vertex-neighbour "
            f"pairs to fit, more than {MAX_FIT_PAIRS:.0e} (minutes of work); use a radius "
            f"below about {most:.3g} on this mesh",
            "radius",
        )
    step = max(1, MAX_PAIRS // per)
    out = [np.zeros(n), np.zeros(n), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))]
    for s in range(0, n, step):
        idx = np.arange(s, min(n, s + step))
        try:
            res = _shape_operator(*_chunk(X, Nv, tree, idx, r))
        except _TooFew as few:
            vertex, count, _ = few.args
            raise MeshError(
                f"{what} {r:.4g} is too small: vertex {vertex} has {count} vertices within it "
                f"and the jet needs 6 (the mean edge length is {mean_edge_length(V, F):.4g}); "
                "use a larger radius",
                "radius",
            ) from None
        for o, x in zip(out, res, strict=True):
            o[idx] = x
    return PrincipalCurvatures(out[0], out[1], out[2], out[3], out[4], "jet")
