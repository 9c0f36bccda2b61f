"""How much a map to the plane distorts each face: angles, areas, flips.

From each face's Jacobian ``J`` (:mod:`.jacobian`) and its singular values ``σ₁ ≥ σ₂``:

* **angle distortion** ``σ₁/σ₂`` (the quasi-conformal ratio, ≥ 1; 1 exactly where the map is
  conformal: a small circle on the face maps to a circle);
* **area distortion** ``log(σ₁σ₂)`` (0 where the map keeps areas, negative where it shrinks
  them), measured after the map's global scale is normalized: the map is first scaled by
  ``s = √(Σ_f A_f / Σ_f |a_f|)`` (``A_f`` the face's area on the surface, ``a_f`` in the
  plane), so that the total areas agree and only the *relative* change is counted; every
  ``σ`` reported is that of the normalized map;
* **flipped** faces: signed area in the plane below ``−τ_f`` (the map reverses their
  orientation; ``τ_f = 8ε(|d₁||d₂| + |u|(|d₁| + |d₂|))`` the round-off of the face's signed area
  from its edge vectors ``d₁, d₂`` in the plane and the coordinates' size ``|u|``);
  **collapsed** faces: ``|a_f| ≤ τ_f`` (flattened to a segment, or too small to tell their
  orientation; their ``σ₂`` is at round-off, so they are left out of the means);
* for a click, :meth:`Distortion.ellipse`: the ellipse a small circle on the face maps to
  (semi-axes ``σ₁``, ``σ₂`` along the left singular vectors; the surface directions mapped to
  them are the right singular vectors, in 3-D).

:meth:`Distortion.summary` is one row of the distortion table: area-weighted means (by ``A_f``)
and maxima of the angle distortion and of ``|log σ₁σ₂|``, and the counts of flipped and
collapsed faces.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import MeshError
from ..types import FloatArray, IntArray, as_faces, as_vertices, real_array
from .jacobian import FaceFrames, face_frames, jacobians, singular_values


@dataclass(frozen=True)
class FaceEllipse:
    """What a clicked face does to a small circle: its Jacobian and the ellipse.

    Attributes
    ----------
    face : int
    sigma1, sigma2 : float
        Singular values of the normalized map (``σ₁ ≥ σ₂``).
    flipped : bool
    jacobian : (2,2) float
        ``J`` of the normalized map, in the face's frame.
    frame : (3,2) float
        The face's frame ``(e₁, e₂)`` (columns) on the surface.
    uv_axes : (2,2) float
        Columns: the unit directions in the plane of the ellipse's major and minor axes.
    surface_axes : (3,2) float
        Columns: the unit tangent directions on the face that map onto them.
    center_3d : (3,) float
        The face's centroid.
    center_uv : (2,) float
        Its image (the centroid of the face in the layout).
    scale : float
        The normalizing scale ``s`` (the layout itself is the normalized map divided by it).
    """

    face: int
    sigma1: float
    sigma2: float
    flipped: bool
    jacobian: FloatArray
    frame: FloatArray
    uv_axes: FloatArray
    surface_axes: FloatArray
    center_3d: FloatArray
    center_uv: FloatArray
    scale: float

    def polylines(self, radius: float, count: int = 64) -> tuple[FloatArray, FloatArray]:
        """A circle of ``radius`` around the face's centroid on the surface and its image in
        the layout: ``(circle (count,3), ellipse (count,2))`` (closed when repeated)."""
        t = np.linspace(0.0, 2.0 * np.pi, int(count), endpoint=False)
        unit = np.stack([np.cos(t), np.sin(t)], axis=1) * float(radius)
        circle = self.center_3d + unit @ self.frame.T
        ellipse = self.center_uv + unit @ (self.jacobian / self.scale).T
        return circle, ellipse


@dataclass(frozen=True, eq=False)
class Distortion:
    """Per-face distortion of one map (see the module for the definitions).

    Attributes
    ----------
    sigma1, sigma2 : (m,) float
        Singular values of the normalized map, ``σ₁ ≥ σ₂ ≥ 0``.
    angle : (m,) float
        ``σ₁/σ₂`` (``inf`` on collapsed faces).
    area : (m,) float
        ``log(σ₁σ₂)`` (``-inf`` on collapsed faces).
    signed_area : (m,) float
        The faces' signed areas in the layout (before normalization).
    flipped, collapsed : (m,) bool
    face_area : (m,) float
        The faces' areas on the surface.
    scale : float
        ``s``: the normalized map is ``s·uv``.
    jacobian : (m,2,2) float
        ``J`` of the normalized map.
    """

    sigma1: FloatArray
    sigma2: FloatArray
    angle: FloatArray
    area: FloatArray
    signed_area: FloatArray
    flipped: np.ndarray
    collapsed: np.ndarray
    face_area: FloatArray
    scale: float
    jacobian: FloatArray
    frames: FaceFrames
    V: FloatArray
    F: IntArray
    uv: FloatArray

    def summary(self) -> dict[str, Any]:
        """One row of the distortion table: ``angle_mean``, ``angle_max`` (of ``σ₁/σ₂``),
        ``area_mean``, ``area_max`` (of ``|log σ₁σ₂|``; means weighted by the surface area,
        over the faces that are not collapsed), ``flipped``, ``collapsed``, ``faces``."""
        ok = ~self.collapsed
        w = self.face_area[ok]
        total = float(w.sum())
        absarea = np.abs(self.area[ok])
        angle = self.angle[ok]
        return {
            "angle_mean": float(w @ angle / total) if total > 0 else float("nan"),
            "angle_max": float(angle.max(initial=1.0)),
            "area_mean": float(w @ absarea / total) if total > 0 else float("nan"),
            "area_max": float(absarea.max(initial=0.0)),
            "flipped": int(np.count_nonzero(self.flipped)),
            "collapsed": int(np.count_nonzero(self.collapsed)),
            "faces": len(self.F),
        }

    def ellipse(self, face: Any) -> FaceEllipse:
        """The Jacobian, singular values and ellipse of one face (for a click).

        Raises
        ------
        MeshError
            ``face`` not an integer in ``[0, m)`` (named ``face``).
        """
        f = _face_index(face, len(self.F))
        J = self.jacobian[f]
        U, S, Vt = np.linalg.svd(J)
        frame = np.stack([self.frames.e1[f], self.frames.e2[f]], axis=1)
        return FaceEllipse(
            face=f,
            sigma1=float(S[0]),
            sigma2=float(S[1]),
            flipped=bool(self.flipped[f]),
            jacobian=J.copy(),
            frame=frame,
            uv_axes=U,
            surface_axes=frame @ Vt.T,
            center_3d=self.V[self.F[f]].mean(axis=0),
            center_uv=self.uv[self.F[f]].mean(axis=0),
            scale=self.scale,
        )


def _face_index(face: Any, m: int) -> int:
    """``face`` as an int in ``[0, m)`` or a :class:`MeshError` naming ``face``."""
    raw = real_array(face, "face", "face index")
    if raw.ndim != 0 or (raw.dtype.kind not in "iu" and not float(raw).is_integer()):
        raise MeshError(f"must be one integer face index, got {face!r}", "face")
    f = int(raw)
    if not 0 <= f < m:
        raise MeshError(f"face {f} is out of range; the mesh has {m} faces", "face")
    return f


def _roundoff(uv: FloatArray, d1: FloatArray, d2: FloatArray) -> FloatArray:
    """The round-off of each face's signed area ``½ d₁ × d₂`` ``(m,)``: the cross product's
    own (``ε|d₁||d₂|``) and that of the differences ``d = u_j − u₀`` of coordinates of size
    ``|u|`` (``ε|u|`` per component), with a safety factor 8."""
    l1, l2 = np.linalg.norm(d1, axis=1), np.linalg.norm(d2, axis=1)
    size = float(np.abs(uv).max(initial=0.0))
    return 8.0 * np.finfo(float).eps * (l1 * l2 + size * (l1 + l2))


def check_uv(uv: Any, n: int, name: str = "uv") -> FloatArray:
    """``uv`` as a finite ``(n,2)`` float64 array (a copy), else :class:`MeshError`."""
    raw = real_array(uv, name, "texture coordinates")
    arr = np.array(raw, dtype=np.float64)
    if arr.shape != (n, 2):
        raise MeshError(f"should have shape ({n},2); shape is {arr.shape}", name)
    if not np.isfinite(arr).all():
        bad = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        raise MeshError(f"vertex {bad} has a NaN or infinite coordinate", name)
    return arr


def measure_distortion(V: Any, F: Any, uv: Any, frames: FaceFrames | None = None) -> Distortion:
    """The per-face distortion of the map ``uv`` of the mesh ``(V, F)``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
        A mesh without zero-area faces (a :class:`~meshlap_core.flatten.disk.Disk`'s).
    uv : (n,2) float
        The map: one point of the plane per vertex.
    frames : FaceFrames, optional
        :func:`~meshlap_core.flatten.jacobian.face_frames` of ``(V, F)``, when the caller has
        them.

    Returns
    -------
    Distortion

    Examples
    --------
    A flat grid mapped by ``(x, y) → (2x, y)``: after the map's area is scaled to the
    surface's, every face has σ₁ = √2, σ₂ = 1/√2, angle distortion σ₁/σ₂ = 2 and no area
    distortion:

    >>> import numpy as np
    >>> from meshlap_core import grid, measure_distortion
    >>> V, F = grid(5, 5)
    >>> d = measure_distortion(V, F, V[:, :2] * [2, 1])
    >>> bool(np.allclose(d.angle, 2) and np.allclose(d.area, 0, atol=1e-12))
    True
    >>> int(d.flipped.sum())
    0
    """
    V = as_vertices(V)
    F = as_faces(F, len(V))
    uv = check_uv(uv, len(V))
    fr = face_frames(V, F) if frames is None else frames
    Jraw = jacobians(fr, F, uv)
    d1, d2 = uv[F[:, 1]] - uv[F[:, 0]], uv[F[:, 2]] - uv[F[:, 0]]
    signed = 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    tol = _roundoff(uv, d1, d2)
    flipped = signed < -tol
    collapsed = np.abs(signed) <= tol
    layout = float(np.abs(signed).sum())
    scale = float(np.sqrt(fr.area.sum() / layout)) if layout > 0 else 1.0
    J = Jraw * scale
    s1, s2 = singular_values(J)
    with np.errstate(divide="ignore", invalid="ignore"):
        angle = np.where(collapsed, np.inf, s1 / np.where(collapsed, 1.0, s2))
        area = np.where(collapsed, -np.inf, np.log(np.where(collapsed, 1.0, s1 * s2)))
    return Distortion(
        sigma1=s1,
        sigma2=s2,
        angle=angle,
        area=area,
        signed_area=signed,
        flipped=flipped,
        collapsed=collapsed,
        face_area=fr.area,
        scale=scale,
        jacobian=J,
        frames=fr,
        V=V,
        F=F,
        uv=uv,
    )
