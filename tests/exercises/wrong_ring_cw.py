"""Mistake: the one-rings run clockwise ((i, b, a) is the face for consecutive a, b)."""

import numpy as np


def one_ring(F, n):
    prev = [dict() for _ in range(n)]
    for f in F.tolist():
        for c in range(3):
            prev[f[c]][f[(c + 2) % 3]] = f[(c + 1) % 3]  # after b comes a, clockwise
    rings = []
    for i in range(n):
        step = prev[i]
        if not step:
            rings.append(np.zeros(0, int))
            continue
        starts = set(step) - set(step.values())
        first = min(starts) if starts else min(step)
        ring = [first]
        while ring[-1] in step and step[ring[-1]] != first:
            ring.append(step[ring[-1]])
        rings.append(np.array(ring))
    return rings
