"""A correct student file from edge lengths only (law of cosines, Heron), sparse LIL assembly,
rings that start elsewhere, and scipy's sparse eigsh with shift-invert: unlike the reference."""

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
