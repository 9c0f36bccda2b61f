"""Hostile: a task starts processes (a shell command; a multiprocessing pool); the student even
catches the refusal and returns a right answer. Expected: ``refused`` with the diagnosis
``spawns_process`` for both tasks, and the right ``one_ring`` still passes."""

import multiprocessing
import subprocess

import numpy as np
import scipy.sparse as sp


def uniform_laplacian(V, F):
    subprocess.run(["echo", "hello from a child"], check=False)
    n = len(V)
    i = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
    j = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
    A = sp.coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)).tocsr()
    A.data[:] = 1.0
    deg = np.asarray(A.sum(axis=1)).ravel()
    inv = np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)
    return (sp.diags(inv) @ A - sp.diags((deg > 0).astype(float))).tocsr()


def _square(x):
    return x * x


def barycentric_areas(V, F):
    try:
        with multiprocessing.get_context("spawn").Pool(2) as pool:
            pool.map(_square, range(4))
    except PermissionError:
        pass  # caught: the checker refuses the task all the same
    P = V[F]
    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    return np.bincount(F.ravel(), np.repeat(A / 3.0, 3), minlength=len(V))


def one_ring(F, n):
    """Right: each vertex's neighbours counter-clockwise (starting anywhere on a closed ring,
    at the boundary edge's start on an open one)."""
    nxt = [dict() for _ in range(n)]
    for a, b, c in F.tolist():
        nxt[a][b] = c
        nxt[b][c] = a
        nxt[c][a] = b
    rings = []
    for i in range(n):
        succ = nxt[i]
        if not succ:
            rings.append([])
            continue
        targets = set(succ.values())
        start = next((k for k in succ if k not in targets), next(iter(succ)))
        ring, k = [start], succ.get(start)
        while k is not None and k != start:
            ring.append(k)
            k = succ.get(k)
        rings.append(ring)
    return rings
