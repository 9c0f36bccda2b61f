"""Hostile: a task sends the mesh out over the network (and would fetch an answer back).
Expected: REFUSED (``uses_network``); under bubblewrap there is no network at all."""

import socket

import numpy as np


def barycentric_areas(V, F):
    with socket.create_connection(("127.0.0.1", 9), timeout=2) as s:
        s.sendall(V.tobytes())
    return np.zeros(len(V))
