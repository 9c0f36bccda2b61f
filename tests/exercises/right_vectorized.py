"""A correct student file, vectorized numpy/scipy, written from the formulas (not from meshlap)."""

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def _edges(F):
    return np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])


def uniform_laplacian(V, F):
    n = len(V)
    e = _edges(F)
    e = np.unique(np.sort(np.concatenate([e, e[:, ::-1]]), axis=1), axis=0)
    i = np.concatenate([e[:, 0], e[:, 1]])
    j = np.concatenate([e[:, 1], e[:, 0]])
    A = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    deg = np.asarray(A.sum(axis=1)).ravel()
    inv = np.where(deg > 0, 1.0 / np.maximum(deg, 1), 0.0)
    return sp.diags(inv) @ A - sp.diags((deg > 0).astype(float))


def _cots(V, F):
    cots = np.zeros((len(F), 3))
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        dot, cross = np.einsum("ij,ij->i", u, w), np.linalg.norm(np.cross(u, w), axis=1)
        cots[:, c] = np.divide(dot, cross, out=np.zeros(len(F)), where=cross > 0)  # area 0: 0
    return cots


def cotan_laplacian(V, F):
    n = len(V)
    cots = _cots(V, F)
    rows, cols, vals = [], [], []
    for c in range(3):  # corner c is opposite the edge (c+1, c+2)
        i, j = F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        w = 0.5 * cots[:, c]
        rows += [i, j, i, j]
        cols += [j, i, i, j]
        vals += [w, w, -w, -w]
    return sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    ).tocsr()


def _face_areas(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def barycentric_areas(V, F):
    return np.bincount(F.ravel(), np.repeat(_face_areas(V, F) / 3, 3), minlength=len(V))


def voronoi_areas(V, F):
    cots = _cots(V, F)
    area = _face_areas(V, F)
    out = np.zeros(len(V))
    ang_cos = np.zeros((len(F), 3))
    for c in range(3):
        u = V[F[:, (c + 1) % 3]] - V[F[:, c]]
        w = V[F[:, (c + 2) % 3]] - V[F[:, c]]
        ang_cos[:, c] = np.einsum("ij,ij->i", u, w)
    obtuse = ang_cos < 0
    any_obtuse = obtuse.any(axis=1)
    for c in range(3):
        j, k = (c + 1) % 3, (c + 2) % 3
        # edge c-j is opposite corner k, edge c-k opposite corner j
        lij = np.sum((V[F[:, j]] - V[F[:, c]]) ** 2, axis=1)
        lik = np.sum((V[F[:, k]] - V[F[:, c]]) ** 2, axis=1)
        vor = (lij * cots[:, k] + lik * cots[:, j]) / 8
        a = np.where(any_obtuse, np.where(obtuse[:, c], area / 2, area / 4), vor)
        out += np.bincount(F[:, c], a, minlength=len(V))
    return out


def mass_matrix(V, F):
    return sp.diags(voronoi_areas(V, F))


def mean_curvature_normal(V, F):
    a = voronoi_areas(V, F)
    Cx = cotan_laplacian(V, F) @ V
    return -0.5 * np.divide(Cx, a[:, None], out=np.zeros_like(Cx), where=a[:, None] > 0)


def _angles(V, F):
    th = np.zeros((len(F), 3))
    for c in range(3):
        u = V[F[:, (c + 1) % 3]] - V[F[:, c]]
        w = V[F[:, (c + 2) % 3]] - V[F[:, c]]
        th[:, c] = np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), np.einsum("ij,ij->i", u, w))
    return th


def mean_curvature(V, F):
    th = _angles(V, F)
    fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    length = np.linalg.norm(fn, axis=1, keepdims=True)
    fn = np.divide(fn, length, out=np.zeros_like(fn), where=length > 0)  # area 0: no normal
    N = np.zeros_like(V)
    for c in range(3):
        np.add.at(N, F[:, c], th[:, c : c + 1] * fn)
    norm = np.linalg.norm(N, axis=1, keepdims=True)
    N = np.divide(N, norm, out=np.zeros_like(N), where=norm > 0)
    return np.sum(mean_curvature_normal(V, F) * N, axis=1)


def _boundary_vertices(F, n):
    e = np.sort(_edges(F), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    mask = np.zeros(n, bool)
    mask[uniq[count == 1].ravel()] = True
    return mask


def angle_defect(V, F, boundary):
    n = len(V)
    total = np.bincount(F.ravel(), _angles(V, F).ravel(), minlength=n)
    d = 2 * np.pi - total
    b = _boundary_vertices(F, n)
    if boundary == "pi":
        d[b] = np.pi - total[b]
    elif boundary == "zero":
        d[b] = 0.0
    d[np.bincount(F.ravel(), minlength=n) == 0] = 0.0
    return d


def one_ring(F, n):
    nxt = [dict() for _ in range(n)]
    for f in F:
        for c in range(3):
            nxt[f[c]][f[(c + 1) % 3]] = f[(c + 2) % 3]
    rings = []
    for i in range(n):
        succ = nxt[i]
        if not succ:
            rings.append(np.zeros(0, int))
            continue
        starts = set(succ) - set(succ.values())
        a = min(starts) if starts else min(succ)
        ring = [a]
        while ring[-1] in succ and succ[ring[-1]] != a:
            ring.append(succ[ring[-1]])
        rings.append(np.array(ring))
    return rings


def eigenbasis(V, F, k):
    K = -cotan_laplacian(V, F)
    M = mass_matrix(V, F)
    lam, U = sla.eigh(K.toarray(), M.toarray(), subset_by_index=[0, k - 1])
    return lam, U


def spectral_reconstruction(X, U, M):
    return U @ (U.T @ (M @ X))


def explicit_step(V, F, lam):
    return V + lam * (uniform_laplacian(V, F) @ V)


def implicit_step(V, F, lam):
    M = mass_matrix(V, F)
    C = cotan_laplacian(V, F)
    return spla.spsolve(sp.csc_matrix(M - lam * C), M @ V)


def taubin_step(V, F, lam, mu):
    L = uniform_laplacian(V, F)
    V1 = V + lam * (L @ V)
    return V1 + mu * (L @ V1)


def _face_gradient_basis(V, F):
    """(m,3,3): row c is the gradient of the hat function of corner c on each face, N×e/(2A)."""
    P = V[F]
    N = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    twice_area = np.linalg.norm(N, axis=1)
    N = N / twice_area[:, None]
    out = np.zeros((len(F), 3, 3))
    for c in range(3):
        e = P[:, (c + 2) % 3] - P[:, (c + 1) % 3]  # the edge opposite corner c, ccw
        out[:, c] = np.cross(N, e) / twice_area[:, None]
    return out, 0.5 * twice_area


def heat_geodesic(V, F, source, m):
    n = len(V)
    K = -cotan_laplacian(V, F)
    e = np.unique(np.sort(_edges(F), axis=1), axis=0)
    h = np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1).mean()
    delta = np.zeros(n)
    delta[source] = 1.0
    u = spla.spsolve((mass_matrix(V, F) + m * h * h * K).tocsc(), delta)
    B, area = _face_gradient_basis(V, F)
    grad = np.einsum("fcx,fc->fx", B, u[F])
    X = -grad / np.linalg.norm(grad, axis=1, keepdims=True)
    div = np.bincount(
        F.ravel(), (area[:, None] * np.einsum("fcx,fx->fc", B, X)).ravel(), minlength=n
    )
    keep = np.arange(n - 1)  # pin the last vertex
    phi = np.zeros(n)
    phi[keep] = spla.spsolve(K[keep][:, keep].tocsc(), div[keep])
    return phi - phi[source]


def _pinned_solve(Q, known_rows, known, b=None):
    """Minimize ½xᵀQx − bᵀx with the rows ``known_rows`` given: Q_ff x_f = b_f − Q_fk known."""
    n = Q.shape[0]
    known_rows = np.asarray(known_rows)
    free = np.setdiff1d(np.arange(n), known_rows)
    Q = sp.csr_matrix(Q)
    x = np.zeros((n, known.shape[1]))
    x[known_rows] = known
    rhs = -(Q[free][:, known_rows] @ known)
    if b is not None:
        rhs = rhs + b[free]
    x[free] = spla.spsolve(Q[free][:, free].tocsc(), rhs).reshape(len(free), -1)
    return x


def biharmonic_displacement(V, F, handles, handle_displacement):
    C = cotan_laplacian(V, F)
    m = voronoi_areas(V, F)
    Q = C @ sp.diags(np.divide(1.0, m, out=np.zeros_like(m), where=m > 0)) @ C
    return V + _pinned_solve(Q, handles, handle_displacement)


def arap_step(V, F, U, handles, targets):
    n = len(V)
    C = cotan_laplacian(V, F).tocsr().tocoo()
    off = C.row != C.col
    i, j, w = C.row[off], C.col[off], C.data[off]  # each directed spoke once, w_ij = C_ij
    X = np.array(U, dtype=float)
    X[handles] = targets
    e, e2 = V[i] - V[j], X[i] - X[j]
    S = np.zeros((n, 3, 3))
    np.add.at(S, i, w[:, None, None] * e[:, :, None] * e2[:, None, :])
    A, _, Bt = np.linalg.svd(S)
    B = Bt.transpose(0, 2, 1)
    flip = np.linalg.det(B @ A.transpose(0, 2, 1)) < 0
    B[flip, :, 2] *= -1.0  # the reflection fix
    R = B @ A.transpose(0, 2, 1)
    b = np.zeros((n, 3))
    np.add.at(b, i, 0.5 * w[:, None] * np.einsum("kab,kb->ka", R[i] + R[j], e))
    return _pinned_solve(-C, handles, targets, b)


def _graph_stiffness(F, n):
    e = np.unique(np.sort(_edges(F), axis=1), axis=0)
    i, j = np.concatenate([e[:, 0], e[:, 1]]), np.concatenate([e[:, 1], e[:, 0]])
    A = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    return sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A


def tutte_map(V, F, loop, weights):
    K = _graph_stiffness(F, len(V)) if weights == "uniform" else -cotan_laplacian(V, F)
    seg = np.linalg.norm(V[np.roll(loop, -1)] - V[loop], axis=1)
    theta = 2 * np.pi * np.concatenate([[0.0], np.cumsum(seg[:-1])]) / seg.sum()
    return _pinned_solve(K, loop, np.stack([np.cos(theta), np.sin(theta)], axis=1))


def lscm(V, F, pins, pin_uv):
    n = len(V)
    K = -cotan_laplacian(V, F)
    he = _edges(F)  # half-edges a -> b, their face on the left
    inner = np.isin(he[:, 1] * n + he[:, 0], he[:, 0] * n + he[:, 1])
    a, b = he[~inner, 0], he[~inner, 1]
    half = np.full(len(a), 0.5)
    QA = sp.coo_matrix(
        (np.concatenate([half, half, -half, -half]),
         (np.concatenate([a, n + b, b, n + a]), np.concatenate([n + b, a, n + a, b]))),
        shape=(2 * n, 2 * n),
    )  # fmt: skip
    L = sp.block_diag([K, K]) - QA
    rows = [pins[0], pins[1], n + pins[0], n + pins[1]]
    known = np.array([[pin_uv[0, 0]], [pin_uv[1, 0]], [pin_uv[0, 1]], [pin_uv[1, 1]]])
    x = _pinned_solve(L, rows, known)[:, 0]
    return np.stack([x[:n], x[n:]], axis=1)
