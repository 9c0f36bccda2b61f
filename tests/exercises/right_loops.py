"""A correct student file written with plain Python loops over the faces (no per-vertex numpy
calls): slower than the vectorized reference, but well within 100×."""

import math

import numpy as np
import scipy.sparse as sp


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
