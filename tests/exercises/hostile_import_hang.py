"""Hostile: the file never finishes importing (it waits at module level). Expected: every
task ``timeout``, diagnosis ``hangs_at_import``; the checker survives."""

import time

import numpy as np

while True:  # e.g. waiting for a plot window to be closed, or for input()
    time.sleep(0.05)


def uniform_laplacian(V, F):
    return np.zeros((len(V), len(V)))
