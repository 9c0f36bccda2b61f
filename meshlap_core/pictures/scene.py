"""What a notebook picture shows, checked and written as plain data (arrays, numbers and
strings) for the renderer behind the ``meshlap.pictures`` entry point (the viewer's, or
matplotlib's in :mod:`.fallback`).

Every argument of :func:`~meshlap_core.pictures.show` and its siblings is checked here, with
an error naming the argument (:class:`~meshlap_core.errors.MeshError`): the mesh as every
public entry point coerces it (``V (n,3) float64``, ``F (m,3) int64``), one finite value per
vertex for a field, a vertex index in range, a camera direction, a picture size.

The colours follow the window's rule (:func:`colour_range`): a signed field on ``coolwarm``
over a range symmetric around 0, a field of one sign on ``viridis``, each clipped at the 2nd
and 98th percentiles so that one spike cannot wash the map out.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError
from ..options import CURVATURE_FIELD_LABELS, UP_AXES, check_choice, curvature_field_title
from ..types import FloatArray, IntArray, as_faces, as_vertices, real_array

CLIP_PERCENT = 2.0
"""Percentage of a field's values clipped at each end of its colour range (the window's
default clip)."""

ISOLINE_COUNTS = (0, 200)
"""Isolines per field: 0 (none) up to the window's largest count."""

SIZE_RANGE = (64, 4096)
"""Pixels allowed on each side of a picture (``meshlap animate --size``'s range)."""

COLOUR_MAPS = ("coolwarm", "viridis")
"""The window's two colour maps: signed fields (symmetric around 0) and fields of one sign."""


def subject(mesh_or_V: Any, F: Any = None, name: str = "mesh") -> tuple[FloatArray, IntArray, str]:
    """The mesh of a picture: a :class:`~meshlap_core.mesh.Mesh` (``load_mesh``), a ``(V, F)``
    pair (``icosphere(3)``), or ``V`` with ``F``; coerced, never modified.

    Returns
    -------
    V : (n,3) float64
    F : (m,3) int64
    name : str
        The file name of a loaded mesh (the window's up axis and front view follow it), else
        ``name``.

    Raises
    ------
    MeshError
        ``F`` missing or given twice, a bad shape or dtype, a non-finite coordinate, an
        index out of range, no face.
    """
    source = getattr(mesh_or_V, "source", None)
    if hasattr(mesh_or_V, "V") and hasattr(mesh_or_V, "F"):
        if F is not None:
            raise MeshError("give F only with a vertex array, not with a Mesh", "F")
        V, F = mesh_or_V.V, mesh_or_V.F
        name = Path(str(source)).name if source else name
    elif isinstance(mesh_or_V, tuple) and len(mesh_or_V) == 2 and F is None:
        V, F = mesh_or_V
    else:
        V = mesh_or_V
        if F is None:
            raise MeshError("the faces are missing: show(V, F, ...) or show(mesh, ...)", "F")
    Vc = as_vertices(V, "V")
    Fc = as_faces(F, len(Vc), "F")
    if len(Fc) == 0:
        raise MeshError("the mesh has no face to draw", "F")
    return Vc, Fc, name


def field_values(
    field: Any, V: FloatArray, F: IntArray, name: str = "field"
) -> tuple[FloatArray | None, str, bool | None]:
    """A field to colour the mesh by: ``None``, the name of one of the window's curvature
    fields (``"cotan"``, ``"uniform"``, ``"gaussian"``, ``"k1"``, ``"k2"``, ``"difference"``:
    computed here, mixed Voronoi areas) or one finite value per vertex.

    Returns
    -------
    values : (n,) float64 or None
        A new array.
    label : str
        The curvature field's label ("" for an array: the caller's label).
    signed : bool or None
        True for a curvature field (the window's symmetric map), None for an array (decided
        from its values).

    Raises
    ------
    MeshError
        An unknown field name, not one value per vertex, a NaN or infinite value (naming the
        first vertex), a boolean, complex or string array.
    """
    if field is None:
        return None, "", None
    if isinstance(field, str):
        from .. import curvature_field  # the public name (wherever the curvature code lives)

        check_choice(field, tuple(CURVATURE_FIELD_LABELS), "curvature field", name)
        values = curvature_field(V, F, field, area="voronoi")  # type: ignore[arg-type]
        return np.asarray(values, dtype=np.float64), curvature_field_title(field), True
    raw = real_array(field, name, "field values")
    values = np.array(raw, dtype=np.float64, copy=True)
    if values.shape != (len(V),):
        raise MeshError(
            f"needs one value per vertex, shape ({len(V)},); shape is {values.shape}", name
        )
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise MeshError(
            f"{bad.size} value(s) are NaN or infinite (first at vertex {int(bad[0])}); "
            "replace them (np.nan_to_num, or a value outside the range) before drawing",
            name,
        )
    return values, "", None


def colour_range(
    values: FloatArray, signed: bool, clip: float = CLIP_PERCENT
) -> tuple[float, float]:
    """The window's colour range of a field (its curvature view's rule): the ``clip`` and
    ``100 − clip`` percentiles, symmetric around 0 for a signed field; ``lo < hi`` always (a
    constant field gets a small range around its value).

    Parameters
    ----------
    values : (n,) float
    signed : bool
    clip : float
        Percentage clipped at each end (0: the full range), at most 49.

    Returns
    -------
    lo, hi : float
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return -1.0, 1.0
    p = float(np.clip(clip, 0.0, 49.0))
    lo, hi = (float(x) for x in np.percentile(v, [p, 100.0 - p]))
    if signed:
        r = max(abs(lo), abs(hi))
        r = r if r > 0 else 1.0
        return -r, r
    if hi <= lo:
        pad = abs(hi) * 1e-6 or 1e-6
        return lo - pad, hi + pad
    return lo, hi


def check_vertex(vertex: Any, n: int, name: str = "vertex") -> int | None:
    """A vertex index in ``0 … n−1`` (``None`` passes through).

    Raises
    ------
    MeshError
        A boolean, a non-integral number, or an index out of range (the range said).
    """
    if vertex is None:
        return None
    if isinstance(vertex, bool | np.bool_) or not isinstance(
        vertex, int | np.integer | float | np.floating
    ):
        raise MeshError(f"must be a vertex index (an integer), got {vertex!r}", name)
    if isinstance(vertex, float | np.floating) and not float(vertex).is_integer():
        raise MeshError(f"must be a vertex index (an integer), got {vertex!r}", name)
    i = int(vertex)
    if not 0 <= i < n:
        raise MeshError(f"vertex {i} is out of range (the mesh has {n} vertices: 0..{n - 1})", name)
    return i


def check_vectors(vectors: Any, n: int, name: str = "vectors") -> dict[str, Any]:
    """Vectors to draw at the vertices: ``(n,3)`` finite arrows, or the principal directions
    of a :class:`~meshlap_core.principal.PrincipalCurvatures` (``estimate_curvature``) drawn
    as the curvature lab's crosses.

    Returns
    -------
    dict
        ``{"arrows": (n,3)}`` or ``{"crosses": {"normal", "d1", "d2", "k1", "k2"}}``, or
        ``{}`` for ``None``.

    Raises
    ------
    MeshError
        A wrong shape, a non-finite value, or principal curvatures of another mesh.
    """
    if vectors is None:
        return {}
    if all(hasattr(vectors, a) for a in ("d1", "d2", "k1", "k2", "normal")):
        fields = ("normal", "d1", "d2", "k1", "k2")  # PrincipalCurvatures' arrays
        c = {a: np.array(getattr(vectors, a), dtype=np.float64) for a in fields}
        if any(len(x) != n for x in c.values()):
            raise MeshError(f"principal curvatures of another mesh (not {n} vertices)", name)
        if not all(np.isfinite(x).all() for x in c.values()):
            raise MeshError("the principal curvatures have NaN or infinite values", name)
        return {"crosses": c}
    raw = real_array(vectors, name, "vectors")
    arr = np.array(raw, dtype=np.float64, copy=True)
    if arr.shape != (n, 3):
        raise MeshError(
            f"needs one 3-vector per vertex, shape ({n}, 3); shape is {arr.shape}", name
        )
    if not np.isfinite(arr).all():
        bad = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        raise MeshError(f"vector {bad} has a NaN or infinite component", name)
    return {"arrows": arr}


def check_camera(camera: Any, name: str = "camera") -> tuple[float, float, float] | None:
    """The direction from the mesh towards the eye, ``(x, y, z)`` in the picture's y-up
    coordinates (``None``: the window's front view).

    Raises
    ------
    MeshError
        Not three finite numbers, zero, or straight along the up axis (no "right" then).
    """
    if camera is None:
        return None
    try:
        c = np.asarray(real_array(camera, name, "camera direction"), dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"must be a direction (x, y, z), got {camera!r} ({exc})", name) from None
    if c.shape != (3,) or not np.isfinite(c).all():
        raise MeshError(f"must be a direction (x, y, z) of finite numbers, got {camera!r}", name)
    norm = float(np.linalg.norm(c))
    if norm == 0 or math.hypot(c[0], c[2]) < 1e-6 * norm:
        raise MeshError(
            "must not be zero nor straight along the up axis y: tilt it, e.g. (0, 1, 0.2)", name
        )
    return float(c[0]), float(c[1]), float(c[2])


def check_size(size: Any, name: str = "size") -> tuple[int, int]:
    """``(width, height)`` in pixels, each in :data:`SIZE_RANGE`."""
    lo, hi = SIZE_RANGE
    try:
        w, h = (int(x) for x in size)
        ok = all(float(x) == int(x) for x in size)
    except (TypeError, ValueError):
        raise MeshError(f"must be (width, height) in pixels, got {size!r}", name) from None
    if not ok or not (lo <= w <= hi and lo <= h <= hi):
        raise MeshError(f"each side must be {lo} to {hi} pixels, got {size!r}", name)
    return w, h


def check_count(value: Any, name: str, lo: int, hi: int) -> int:
    """An integer in ``[lo, hi]`` (booleans and fractions refused)."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        raise MeshError(f"must be an integer from {lo} to {hi}, got {value!r}", name)
    if not lo <= int(value) <= hi:
        raise MeshError(f"must be from {lo} to {hi}, got {value}", name)
    return int(value)


def check_up(up: Any) -> str:
    """The mesh axis drawn up (the window's ``--up``)."""
    return check_choice(str(up), UP_AXES, "up axis", "up")


def pane(
    V: FloatArray,
    F: IntArray,
    field: Any,
    *,
    label: str | None,
    cmap: str | None,
    clip: float,
    isolines: int,
    vectors: Any,
    edges: bool = False,
    prefix: str = "",
) -> dict[str, Any]:
    """One mesh of a picture with its field, colours, isolines, vectors and edges, checked
    (the arguments are named ``prefix + name`` in errors)."""
    values, default_label, signed = field_values(field, V, F, prefix + "field")
    out: dict[str, Any] = {"V": V, "F": F, "field": values, "isolines": 0, "edges": bool(edges)}
    out.update(check_vectors(vectors, len(V), prefix + "vectors"))
    if values is None:
        return out
    if cmap is not None:
        check_choice(cmap, COLOUR_MAPS, "colour map", prefix + "cmap")
        signed = cmap == "coolwarm"
    elif signed is None:
        signed = bool((values < 0).any())
    if not (isinstance(clip, int | float) and 0 <= clip < 50):
        raise MeshError(f"must be a percentage from 0 to 49, got {clip!r}", "clip")
    out["range"] = colour_range(values, signed, clip)
    out["cmap"] = "coolwarm" if signed else "viridis"
    out["label"] = str(label) if label else (default_label or "field")
    out["isolines"] = check_count(isolines, prefix + "isolines", *ISOLINE_COUNTS)
    return out


RING_VIEW = "onering"
"""The window's view that draws a vertex's one-ring and its inspector (``meshlap view
--panel onering --vertex I``)."""


def build_scene(
    panes: list[dict[str, Any]],
    name: str,
    *,
    up: Any = "y",
    vertex: Any = None,
    camera: Any = None,
    turns: tuple[float, ...] = (0.0,),
    size: Any = (800, 600),
) -> dict[str, Any]:
    """The scene a renderer draws (see :func:`meshlap_app.pictures.render_frames` for its
    keys), every argument checked; ``vertex`` is a vertex of the first pane."""
    n = len(panes[0]["V"])
    i = check_vertex(vertex, n)
    return {
        "panes": panes,
        "name": name,
        "up": check_up(up),
        "panel": RING_VIEW if i is not None else None,
        "options": {"vertex": i} if i is not None else {},
        "camera": check_camera(camera),
        "turns": tuple(float(t) for t in turns),
        "size": check_size(size),
    }
