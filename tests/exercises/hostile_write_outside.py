"""Hostile: each task tries another way out of the student's folder, then returns a right
answer (so that an escape would pass unseen). The paths it aims at: the folder above its own,
``/tmp``, and the class folder named in ``target.txt`` beside it (a classmate's file there).
Expected: every task REFUSED (``outside_folder``, ``native_calls``) or failed, never passed;
nothing written or read outside the student's copy."""

import ctypes
import os
import sqlite3
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TARGET = (HERE / "target.txt").read_text().strip() if (HERE / "target.txt").exists() else "/tmp"


def _areas(V, F):
    a = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return np.bincount(F.ravel(), np.repeat(a / 3, 3), minlength=len(V))


def barycentric_areas(V, F):  # a folder made outside
    for where in (HERE.parent / "escaped_mkdir", Path(TARGET) / "escaped_mkdir"):
        try:
            os.mkdir(where)
        except OSError:
            pass
    return _areas(V, F)


def voronoi_areas(V, F):  # a link in its folder to a classmate's file, then read through it
    try:
        os.symlink(os.path.join(TARGET, "classmate.py"), HERE / "stolen.py")
        (HERE / "stolen.py").read_text()
    except OSError:
        pass
    raise NotImplementedError


def mean_curvature(V, F):  # a hard link to a classmate's file, then written through it
    try:
        os.link(os.path.join(TARGET, "classmate.py"), HERE / "hard.py")
        (HERE / "hard.py").write_text("# overwritten by a classmate\n")
    except OSError:
        pass
    raise NotImplementedError


def angle_defect(V, F, boundary):  # sqlite opens its own file
    try:
        sqlite3.connect(os.path.join(TARGET, "escaped.db")).execute("create table t (x)")
    except (sqlite3.Error, OSError):
        pass
    raise NotImplementedError


def mass_matrix(V, F):  # libc's open and write, under every Python audit
    libc = ctypes.CDLL(None)
    fd = libc.open(os.path.join(TARGET, "escaped_ctypes.txt").encode(), 0o101, 0o644)
    libc.write(fd, b"escaped\n", 8)
    raise NotImplementedError
