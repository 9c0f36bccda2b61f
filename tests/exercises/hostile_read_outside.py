"""Hostile: a task reads a file outside its folder (here the test suite's conftest.py beside
this folder: it could as well be another student's submission, or the reference). Expected:
``refused``, diagnosis ``outside_folder``; a task reading a file *inside* its own folder (its
own source) is fine and passes."""

from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def barycentric_areas(V, F):
    (HERE.parent / "conftest.py").read_text()  # outside the folder: refused
    P = V[F]
    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    return np.bincount(F.ravel(), np.repeat(A / 3.0, 3), minlength=len(V))


def mean_curvature_normal(V, F):
    assert "mean_curvature_normal" in (HERE / Path(__file__).name).read_text()  # inside: fine
    n = len(V)
    P = V[F]
    CV = np.zeros((n, 3))  # the cotangent stiffness times V
    area = np.zeros(n)
    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    for c in range(3):
        i, j, k = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[j] - V[i], V[k] - V[i]
        dot, cross = np.einsum("ij,ij->i", u, w), np.linalg.norm(np.cross(u, w), axis=1)
        cot = np.divide(dot, cross, out=np.zeros(len(F)), where=cross > 0)
        d = V[k] - V[j]  # the edge opposite corner i, weight ½ cot(angle at i)
        np.add.at(CV, j, 0.5 * cot[:, None] * d)
        np.add.at(CV, k, -0.5 * cot[:, None] * d)
    dots = np.stack(
        [np.einsum("ij,ij->i", P[:, (c + 1) % 3] - P[:, c], P[:, (c + 2) % 3] - P[:, c])
         for c in range(3)], axis=1,
    )  # fmt: skip
    cots = np.divide(dots, 2 * A[:, None], out=np.zeros_like(dots), where=A[:, None] > 0)
    obtuse = (dots < 0).any(axis=1)
    for c in range(3):
        lj = ((P[:, (c + 1) % 3] - P[:, c]) ** 2).sum(1)
        lk = ((P[:, (c + 2) % 3] - P[:, c]) ** 2).sum(1)
        vor = (lj * cots[:, (c + 2) % 3] + lk * cots[:, (c + 1) % 3]) / 8
        np.add.at(area, F[:, c], np.where(obtuse, np.where(dots[:, c] < 0, A / 2, A / 4), vor))
    inv = np.divide(1.0, area, out=np.zeros(n), where=area > 0)
    return -0.5 * inv[:, None] * CV  # Δx = −2Hn
