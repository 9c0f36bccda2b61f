"""World → display coordinates for everything the viewer uploads (pure numpy, no polyscope)."""

from __future__ import annotations

import numpy as np

from meshlap_core.options import DEFAULT_UP, UP_AXES, check_choice

UP_BY_MESH: dict[str, str] = {"nefertiti.obj": "z"}
"""The up axis of the meshes known not to be y-up (file name -> axis of :data:`UP_AXES`).

The rule (``meshlap view``): ``--up`` when given (or a session's ``up``); else this table's
entry for the file's name; else ``"y"``, polyscope's default and that of most scans and of
the course meshes. There is no guess from the shape: the longest axis of a bust, a dragon or
a statue says nothing reliable about which way is up."""


def up_rotation(up: str) -> np.ndarray:
    """The rotation ``R (3,3)`` (orthonormal, det +1) taking the mesh axis ``up`` to the
    display's +y: display points are ``R @ x``. ``"y"`` is the identity; ``"z"`` maps
    ``(x, y, z)`` to ``(x, z, −y)`` (a quarter turn about x), ``"x"`` to ``(−y, x, z)``.

    Raises
    ------
    MeshError
        ``up`` is not one of :data:`UP_AXES`.
    """
    check_choice(up, UP_AXES, "up axis", "--up")
    axis = "xyz".index(up[-1])
    sign = -1.0 if up.startswith("-") else 1.0
    R = np.zeros((3, 3))
    R[1, axis] = sign  # display y = ± the mesh's up axis
    # display x: the mesh axis after ``up`` (cyclically) for y and z, keeping x for z-up
    if axis == 1:
        R[0, 0], R[2, 2] = sign, 1.0  # -y: a half turn about z
    elif axis == 2:
        R[0, 0], R[2, 1] = 1.0, -sign
    else:
        R[0, 1], R[2, 2] = -sign, 1.0
    return R


class Display:
    """World → display coordinates ``x_d = (x − c) · s`` for everything uploaded from the mesh.

    polyscope stores positions as float32 (largest 3.4e38, smallest normal 1.2e-38), while the
    loader accepts coordinates up to ``MAX_COORDINATE`` = 1e75 and extents down to 1e-60: a mesh
    near 1e74 would upload as ``inf`` and render a blank frame. Centring on the bounding box and
    scaling by a power of two (exact in float64) to a diagonal near 1 makes every accepted mesh
    representable. The panels' numbers stay in world units; only uploads go through this.
    """

    def __init__(self) -> None:
        self.centre = np.zeros(3)
        self.scale = 1.0
        self.up = DEFAULT_UP
        self.rotation = np.eye(3)  # R: display = R @ ((x - c) s), the up axis to +y

    def fit(self, V: np.ndarray, up: str = DEFAULT_UP) -> None:
        """Fit to the positions ``V (n,3)`` (bounding-box centre; diagonal → about 1) with the
        mesh axis ``up`` pointing up (:func:`up_rotation`)."""
        self.rotation, self.up = up_rotation(up), up
        V = np.asarray(V, dtype=np.float64)
        if len(V) == 0:
            self.centre, self.scale = np.zeros(3), 1.0
            return
        lo, hi = V.min(axis=0), V.max(axis=0)
        self.centre = 0.5 * lo + 0.5 * hi  # no overflow of lo + hi near the float64 limit
        half = 0.5 * hi - 0.5 * lo
        diag = 2.0 * float(np.linalg.norm(half))
        self.scale = float(2.0 ** -np.round(np.log2(diag))) if diag > 0 else 1.0

    def points(self, P: np.ndarray) -> np.ndarray:
        """Display positions of world points ``P (k,3)``.

        The rotation of :func:`up_rotation` is a signed permutation of the axes: applied as a
        column gather and a sign, not a matrix product (the same numbers; no BLAS call, whose
        threads cost 0.1–0.4 s on a loaded machine for the 692k scan, on the UI thread)."""
        X = (np.asarray(P, dtype=np.float64) - self.centre) * self.scale
        R = self.rotation
        perm = np.argmax(np.abs(R), axis=1)
        sign = R[np.arange(3), perm]
        if X.ndim != 2 or np.count_nonzero(R) != 3 or not np.all(np.abs(sign) == 1.0):
            return X @ R.T  # not a signed permutation (never made by up_rotation)
        if np.array_equal(perm, [0, 1, 2]) and np.all(sign > 0):  # y up: the identity
            return X
        out = np.empty_like(X)
        for j in range(3):
            np.multiply(X[:, perm[j]], sign[j], out=out[:, j])
        return out

    def vectors(self, D: np.ndarray) -> np.ndarray:
        """Display vectors of world displacements ``D (k,3)`` (scaled, turned, not shifted)."""
        return (np.asarray(D, dtype=np.float64) * self.scale) @ self.rotation.T
