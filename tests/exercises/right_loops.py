"""A correct student file written with plain Python loops over the faces (no per-vertex numpy
calls): slower than the vectorized reference, but well within 100×."""

import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def _sub(p, q):
    return (p[0] - q[0], p[1] - q[1], p[2] - q[2])


def _dot(u, w):
    return u[0] * w[0] + u[1] * w[1] + u[2] * w[2]


def _cross_norm(u, w):
    cx = u[1] * w[2] - u[2] * w[1]
    cy = u[2] * w[0] - u[0] * w[2]
    cz = u[0] * w[1] - u[1] * w[0]
    return math.sqrt(cx * cx + cy * cy + cz * cz)


def uniform_laplacian(V, F):
    n = len(V)
    nbrs = [set() for _ in range(n)]
    for a, b, c in F.tolist():
        nbrs[a].update((b, c))
        nbrs[b].update((a, c))
        nbrs[c].update((a, b))
    rows, cols, vals = [], [], []
    for i in range(n):
        if nbrs[i]:
            for j in nbrs[i]:
                rows.append(i)
                cols.append(j)
                vals.append(1.0 / len(nbrs[i]))
            rows.append(i)
            cols.append(i)
            vals.append(-1.0)
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def cotan_laplacian(V, F):
    n = len(V)
    P = V.tolist()
    rows, cols, vals = [], [], []
    for f in F.tolist():
        for k in range(3):
            o, i, j = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
            u, w = _sub(P[i], P[o]), _sub(P[j], P[o])
            twice_area = _cross_norm(u, w)
            if twice_area == 0.0:  # a triangle of zero area adds nothing
                continue
            h = 0.5 * _dot(u, w) / twice_area
            rows += [i, j, i, j]
            cols += [j, i, i, j]
            vals += [h, h, -h, -h]
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()


def barycentric_areas(V, F):
    P = V.tolist()
    A = [0.0] * len(V)
    for a, b, c in F.tolist():
        third = _cross_norm(_sub(P[b], P[a]), _sub(P[c], P[a])) / 6.0
        A[a] += third
        A[b] += third
        A[c] += third
    return np.array(A)


def voronoi_areas(V, F):
    P = V.tolist()
    A = [0.0] * len(V)
    for f in F.tolist():
        area = 0.5 * _cross_norm(_sub(P[f[1]], P[f[0]]), _sub(P[f[2]], P[f[0]]))
        dots = []
        for k in range(3):
            dots.append(_dot(_sub(P[f[(k + 1) % 3]], P[f[k]]), _sub(P[f[(k + 2) % 3]], P[f[k]])))
        for k in range(3):
            if min(dots) < 0:
                A[f[k]] += area / 2 if dots[k] < 0 else area / 4
                continue
            j, m = f[(k + 1) % 3], f[(k + 2) % 3]
            # edge k-j is opposite corner m, edge k-m opposite corner j
            cot_m = dots[(k + 2) % 3] / (2 * area)
            cot_j = dots[(k + 1) % 3] / (2 * area)
            lj = _dot(_sub(P[j], P[f[k]]), _sub(P[j], P[f[k]]))
            lm = _dot(_sub(P[m], P[f[k]]), _sub(P[m], P[f[k]]))
            A[f[k]] += (lj * cot_m + lm * cot_j) / 8
    return np.array(A)


def angle_defect(V, F, boundary):
    n = len(V)
    P = V.tolist()
    total = [0.0] * n
    used = [False] * n
    edge_count = {}
    for f in F.tolist():
        for k in range(3):
            o, i, j = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
            u, w = _sub(P[i], P[o]), _sub(P[j], P[o])
            total[o] += math.atan2(_cross_norm(u, w), _dot(u, w))
            used[o] = True
            e = (min(i, j), max(i, j))
            edge_count[e] = edge_count.get(e, 0) + 1
    on_boundary = [False] * n
    for (i, j), count in edge_count.items():
        if count == 1:
            on_boundary[i] = on_boundary[j] = True
    d = []
    for v in range(n):
        if not used[v]:
            d.append(0.0)
        elif not on_boundary[v] or boundary == "2pi":
            d.append(2 * math.pi - total[v])
        elif boundary == "pi":
            d.append(math.pi - total[v])
        else:
            d.append(0.0)
    return np.array(d)


def explicit_step(V, F, lam):
    return V + lam * (uniform_laplacian(V, F) @ V)


def _spokes(V, F):
    """{(i, j): w_ij} over every directed edge, w_ij = ½(cot α + cot β), summed face by face."""
    P = V.tolist()
    w = {}
    for f in F.tolist():
        for k in range(3):
            o, i, j = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
            u, v = _sub(P[i], P[o]), _sub(P[j], P[o])
            twice_area = _cross_norm(u, v)
            h = 0.0 if twice_area == 0.0 else 0.5 * _dot(u, v) / twice_area
            w[i, j] = w.get((i, j), 0.0) + h
            w[j, i] = w.get((j, i), 0.0) + h
    return w


def _stiffness(w, n):
    """K = −C from the spoke weights: K_ij = −w_ij, K_ii = Σ_j w_ij."""
    rows, cols, vals = [], [], []
    for (i, j), x in w.items():
        rows += [i, i]
        cols += [j, i]
        vals += [-x, x]
    return sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()


def _solve_with_known(Q, known_rows, known, b=None):
    n = Q.shape[0]
    is_known = [False] * n
    for r in known_rows:
        is_known[r] = True
    free = [r for r in range(n) if not is_known[r]]
    x = np.zeros((n, known.shape[1]))
    for r, value in zip(known_rows, known, strict=True):
        x[r] = value
    rhs = -(Q[free][:, list(known_rows)] @ known)
    if b is not None:
        rhs = rhs + b[free]
    x[free] = spla.splu(sp.csc_matrix(Q[free][:, free])).solve(rhs)
    return x


def biharmonic_displacement(V, F, handles, handle_displacement):
    n = len(V)
    K = _stiffness(_spokes(V, F), n)
    area = voronoi_areas(V, F)
    inv = sp.diags([1.0 / a if a > 0 else 0.0 for a in area])
    return V + _solve_with_known(K @ inv @ K, list(handles), handle_displacement)


def _closest_rotation(S):
    A, _, Bt = np.linalg.svd(S)
    R = Bt.T @ A.T
    if np.linalg.det(R) < 0:  # a reflection: flip the smallest singular value's direction
        B = Bt.T.copy()
        B[:, 2] = -B[:, 2]
        R = B @ A.T
    return R


def arap_step(V, F, U, handles, targets):
    n = len(V)
    w = _spokes(V, F)
    X = np.array(U, dtype=float)
    for h, t in zip(handles, targets, strict=True):
        X[h] = t
    S = [np.zeros((3, 3)) for _ in range(n)]
    for (i, j), x in w.items():
        S[i] += x * np.outer(V[i] - V[j], X[i] - X[j])
    R = [_closest_rotation(s) for s in S]
    b = np.zeros((n, 3))
    for (i, j), x in w.items():
        b[i] += 0.5 * x * ((R[i] + R[j]) @ (V[i] - V[j]))
    return _solve_with_known(_stiffness(w, n), list(handles), targets, b)


def tutte_map(V, F, loop, weights):
    n = len(V)
    if weights == "uniform":
        w = {}
        for f in F.tolist():
            for k in range(3):
                w[f[k], f[(k + 1) % 3]] = w[f[(k + 1) % 3], f[k]] = 1.0
    else:
        w = _spokes(V, F)
    P = V.tolist()
    walked, lengths = 0.0, []
    for k in range(len(loop)):
        lengths.append(walked)
        a, b = P[loop[k]], P[loop[(k + 1) % len(loop)]]
        walked += math.sqrt(_dot(_sub(a, b), _sub(a, b)))
    at = np.array([[math.cos(2 * math.pi * s / walked), math.sin(2 * math.pi * s / walked)]
                   for s in lengths])  # fmt: skip
    return _solve_with_known(_stiffness(w, n), list(loop), at)


def lscm(V, F, pins, pin_uv):
    n = len(V)
    w = _spokes(V, F)
    rows, cols, vals = [], [], []
    for (i, j), x in w.items():  # the Dirichlet part, diag(K, K)
        for shift in (0, n):
            rows += [i + shift, i + shift]
            cols += [j + shift, i + shift]
            vals += [-x, x]
    halfedges = set()
    for f in F.tolist():
        for k in range(3):
            halfedges.add((f[k], f[(k + 1) % 3]))
    for a, b in halfedges:
        if (b, a) not in halfedges:  # a boundary half-edge, its face on the left: −Q_A
            rows += [a, n + b, b, n + a]
            cols += [n + b, a, n + a, b]
            vals += [-0.5, -0.5, 0.5, 0.5]
    L = sp.coo_matrix((vals, (rows, cols)), shape=(2 * n, 2 * n)).tocsr()
    known_rows = [pins[0], pins[1], n + pins[0], n + pins[1]]
    known = np.array([[pin_uv[0][0]], [pin_uv[1][0]], [pin_uv[0][1]], [pin_uv[1][1]]])
    x = _solve_with_known(L, known_rows, known)[:, 0]
    return np.stack([x[:n], x[n:]], axis=1)
