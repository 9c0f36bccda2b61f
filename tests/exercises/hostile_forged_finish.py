"""Hostile: at import, the file finds the harness through ``gc`` and writes the checker's
channel itself: it announces every task and sends answers and a "finished" line, so that
nothing is ever called. Expected: no task passes (a task without its own answers has failed);
the forgery is named (``tampers``)."""

import gc
import json
import os

TASKS = ["uniform_laplacian", "cotan_laplacian", "barycentric_areas"]
for obj in gc.get_objects():
    if type(obj).__name__ == "Harness":
        for message in (
            {"ev": "imported", "functions": TASKS},
            *({"ev": "answer", "id": i, "tag": "none", "hot": []} for i in range(1, 40)),
            {"ev": "finished"},
        ):
            os.write(obj.replies, (json.dumps(message) + "\n").encode())


def uniform_laplacian(V, F):
    return None


def cotan_laplacian(V, F):
    return None
