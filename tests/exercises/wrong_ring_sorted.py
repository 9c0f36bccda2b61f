"""Mistake: each vertex's neighbours sorted by index, not ordered around it."""

import numpy as np


def one_ring(F, n):
    nbrs = [set() for _ in range(n)]
    for a, b, c in F.tolist():
        nbrs[a].update((b, c))
        nbrs[b].update((a, c))
        nbrs[c].update((a, b))
    return [np.array(sorted(s), dtype=int) for s in nbrs]
