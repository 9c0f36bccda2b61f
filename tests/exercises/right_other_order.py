"""A correct student file from edge lengths only (law of cosines, Heron), sparse LIL assembly,
rings that start elsewhere, and scipy's sparse eigsh with shift-invert: unlike the reference.
The deformations and maps: the strong form Δ² = M⁻¹C M⁻¹C (not symmetric), constraints by
replacing rows (no elimination), covariances transposed and summed face by face in reverse
order, and LSCM as per-face Cauchy–Riemann least squares in each face's own frame."""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def _lengths(V, F):
    """ln[f, k]: the length of the edge opposite corner k."""
    return np.stack(
        [np.linalg.norm(V[F[:, (k + 1) % 3]] - V[F[:, (k + 2) % 3]], axis=1) for k in range(3)],
        axis=1,
    )


def _heron(ln):
    s = ln.sum(axis=1) / 2
    return np.sqrt(np.maximum(s * (s - ln[:, 0]) * (s - ln[:, 1]) * (s - ln[:, 2]), 0))


def _cot(ln):
    A = _heron(ln)
    l2 = ln**2
    num = [l2[:, (k + 1) % 3] + l2[:, (k + 2) % 3] - l2[:, k] for k in range(3)]
    return np.stack(  # a triangle of zero area: cot 0, it adds nothing
        [np.divide(x, 4 * A, out=np.zeros_like(x), where=A > 0) for x in num], axis=1
    )


def uniform_laplacian(V, F):
    n = len(V)
    L = sp.lil_matrix((n, n))
    nbrs = [set() for _ in range(n)]
    for f in F[::-1].tolist():  # faces in reverse order: the result must not depend on it
        for k in range(3):
            nbrs[f[k]].update((f[(k + 1) % 3], f[(k + 2) % 3]))
    for i, ns in enumerate(nbrs):
        if ns:
            L.rows[i] = sorted(ns | {i})
            L.data[i] = [-1.0 if j == i else 1.0 / len(ns) for j in L.rows[i]]
    return L


def cotan_laplacian(V, F):
    n = len(V)
    Fr = np.roll(F, 1, axis=1)  # rotate every face's corners: same triangles
    cot = _cot(_lengths(V, Fr))
    W = sp.csr_matrix((n, n))
    for k in range(3):
        i, j = Fr[:, (k + 1) % 3], Fr[:, (k + 2) % 3]
        W = W + sp.csr_matrix((cot[:, k] / 2, (i, j)), shape=(n, n))
    W = W + W.T
    return W - sp.diags(np.asarray(W.sum(axis=1)).ravel())


def barycentric_areas(V, F):
    a = _heron(_lengths(V, F)) / 3
    return np.asarray(
        sp.csr_matrix((np.tile(a, 3), (F.T.ravel(), np.zeros(3 * len(F), int))), shape=(len(V), 1))
        .toarray()
        .ravel()
    )


def angle_defect(V, F, boundary):
    ln = _lengths(V, F)
    l2 = ln**2
    ang = np.stack(
        [
            np.arccos(
                np.clip(
                    (l2[:, (k + 1) % 3] + l2[:, (k + 2) % 3] - l2[:, k])
                    / (2 * ln[:, (k + 1) % 3] * ln[:, (k + 2) % 3]),
                    -1,
                    1,
                )
            )
            for k in range(3)
        ],
        axis=1,
    )
    n = len(V)
    total = np.bincount(F.ravel(), ang.ravel(), minlength=n)
    directed = {(a, b) for f in F.tolist() for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0]))}
    on_b = np.zeros(n, bool)
    for a, b in directed:
        if (b, a) not in directed:
            on_b[[a, b]] = True
    base = np.full(n, 2 * np.pi)
    base[on_b] = {"pi": np.pi, "2pi": 2 * np.pi, "zero": np.nan}[boundary]
    d = base - total
    if boundary == "zero":
        d[on_b] = 0.0
    d[np.bincount(F.ravel(), minlength=n) == 0] = 0.0
    return d


def one_ring(F, n):
    succ = [dict() for _ in range(n)]
    for f in F.tolist():
        for k in range(3):
            succ[f[k]][f[(k + 1) % 3]] = f[(k + 2) % 3]
    rings = []
    for i in range(n):
        s = succ[i]
        if not s:
            rings.append([])
            continue
        open_starts = set(s) - set(s.values())
        start = open_starts.pop() if open_starts else max(s)  # interior: start anywhere
        ring = [start]
        while ring[-1] in s and s[ring[-1]] != start:
            ring.append(s[ring[-1]])
        rings.append(ring)
    return rings


def eigenbasis(V, F, k):
    K = -cotan_laplacian(V, F).tocsc()
    m = _mixed(V, F)
    M = sp.diags(m).tocsc()
    if k >= len(V) - 1:
        import scipy.linalg as sla

        lam, U = sla.eigh(K.toarray(), M.toarray())
        return lam[:k], U[:, :k]
    lam, U = spla.eigsh(K, k=k, M=M, sigma=-1e-3 * m.sum() ** -1, which="LM")
    order = np.argsort(lam)
    U = U[:, order]
    U = U / np.sqrt(np.einsum("ik,i,ik->k", U, m, U))
    return lam[order], U


def _mixed(V, F):
    ln = _lengths(V, F)
    A = _heron(ln)
    cot = _cot(ln)
    l2 = ln**2
    out = np.zeros(len(V))
    for k in range(3):
        j, o = (k + 1) % 3, (k + 2) % 3
        vor = (l2[:, j] * cot[:, j] + l2[:, o] * cot[:, o]) / 8
        obtuse = cot < 0
        a = np.where(obtuse.any(axis=1), np.where(obtuse[:, k], A / 2, A / 4), vor)
        out += np.bincount(F[:, k], a, minlength=len(V))
    return out


def taubin_step(V, F, lam, mu):
    L = sp.csr_matrix(uniform_laplacian(V, F))
    for step in (lam, mu):
        V = V + step * (L @ V)
    return V


def _rows_replaced(A, rows, values, rhs):
    """Solve A x = rhs with the equations of ``rows`` replaced by x_r = values (no elimination:
    the system stays n × n, not symmetric)."""
    A = sp.lil_matrix(A)
    rhs = np.array(rhs, dtype=float)
    for r, value in zip(rows, values, strict=True):
        A.rows[r], A.data[r] = [r], [1.0]
        rhs[r] = value
    return spla.splu(sp.csc_matrix(A)).solve(rhs)


def biharmonic_displacement(V, F, handles, handle_displacement):
    # the strong form: (Δ² d)_i = 0 at the free vertices with Δ = M⁻¹C (not symmetric)
    D = sp.diags(1.0 / _mixed(V, F)) @ cotan_laplacian(V, F)
    d = _rows_replaced(D @ D, handles, handle_displacement, np.zeros(V.shape))
    return V + d


def arap_step(V, F, U, handles, targets):
    n = len(V)
    Fr = F[::-1]  # faces in reverse order
    half_cot = _cot(_lengths(V, Fr)) / 2  # the weight of the edge opposite each corner
    X = np.array(U, dtype=float)
    X[handles] = targets
    T = np.zeros((n, 3, 3))  # T_i = Σ_j w_ij (x_i − x_j)(p_i − p_j)ᵀ = S_iᵀ
    for k in range(3):
        j, o, w = Fr[:, (k + 1) % 3], Fr[:, (k + 2) % 3], half_cot[:, k]
        t = w[:, None, None] * np.einsum("fa,fb->fab", X[j] - X[o], V[j] - V[o])
        np.add.at(T, j, t)
        np.add.at(T, o, t)  # (the same product from the other end)
    A, _, Bt = np.linalg.svd(T)  # T = A Σ Bᵀ, so S = B Σ Aᵀ and R = A Bᵀ
    sign = np.sign(np.linalg.det(A @ Bt))
    A[:, :, 2] *= sign[:, None]
    R = A @ Bt
    b = np.zeros((n, 3))
    for k in range(3):
        j, o, w = Fr[:, (k + 1) % 3], Fr[:, (k + 2) % 3], half_cot[:, k]
        turned = 0.5 * w[:, None] * np.einsum("fab,fb->fa", R[j] + R[o], V[j] - V[o])
        np.add.at(b, j, turned)
        np.add.at(b, o, -turned)
    return _rows_replaced(-cotan_laplacian(V, F), handles, targets, b)


def tutte_map(V, F, loop, weights):
    n = len(V)
    # each free row: the vertex is the weighted average of its neighbours (L uv)_i = 0, with
    # the row-normalised uniform Laplacian D⁻¹A − I for Tutte (the same rows as D − A, scaled)
    L = cotan_laplacian(V, F) if weights == "cotan" else sp.csr_matrix(uniform_laplacian(V, F))
    edges = np.diff(V[np.append(loop, loop[0])], axis=0)
    s = np.cumsum(np.linalg.norm(edges, axis=1))
    theta = 2 * np.pi * np.append(0.0, s[:-1]) / s[-1]
    at = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    return _rows_replaced(L, loop, at, np.zeros((n, 2)))


def lscm(V, F, pins, pin_uv):
    # per face, in its own orthonormal frame: E_C,f = ½ area_f ((u_x − v_y)² + (u_y + v_x)²),
    # the Cauchy–Riemann residuals; least squares with the four pinned unknowns moved right
    n, m = len(V), len(F)
    P0, P1, P2 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    ex = P1 - P0
    ex /= np.linalg.norm(ex, axis=1, keepdims=True)
    normal = np.cross(P1 - P0, P2 - P0)
    area = 0.5 * np.linalg.norm(normal, axis=1)
    ey = np.cross(normal / (2 * area[:, None]), ex)
    q1 = np.stack([np.einsum("fa,fa->f", P1 - P0, ex), np.zeros(m)], axis=1)
    q2 = np.stack([np.einsum("fa,fa->f", P2 - P0, ex), np.einsum("fa,fa->f", P2 - P0, ey)], 1)
    E = np.stack([q1, q2], axis=1)  # rows q1 − q0, q2 − q0 (q0 = 0)
    Einv = np.linalg.inv(E)  # ∇u = Einv (u1 − u0, u2 − u0)
    G = np.stack([-Einv.sum(axis=2), Einv[:, :, 0], Einv[:, :, 1]], axis=2)  # (m, 2, 3)
    s = np.sqrt(area / 2)
    rows, cols, vals = [], [], []
    for c in range(3):
        f = np.arange(m)
        # row 2f: u_x − v_y, row 2f+1: u_y + v_x; unknowns u at i, v at n + i
        rows += [2 * f, 2 * f, 2 * f + 1, 2 * f + 1]
        cols += [F[:, c], n + F[:, c], F[:, c], n + F[:, c]]
        vals += [s * G[:, 0, c], -s * G[:, 1, c], s * G[:, 1, c], s * G[:, 0, c]]
    A = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(2 * m, 2 * n)
    )
    known = np.array([pins[0], pins[1], n + pins[0], n + pins[1]])
    values = np.array([pin_uv[0, 0], pin_uv[1, 0], pin_uv[0, 1], pin_uv[1, 1]])
    free = np.setdiff1d(np.arange(2 * n), known)
    Af = A[:, free]
    x = np.zeros(2 * n)
    x[known] = values
    x[free] = spla.splu(sp.csc_matrix(Af.T @ Af)).solve(-(Af.T @ (A[:, known] @ values)))
    return np.stack([x[:n], x[n:]], axis=1)
