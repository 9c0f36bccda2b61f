"""Writers: meshes (``.obj``, ``.off``, ``.ply``) and per-vertex scalars (``.csv``,
``.npy``, ``.ply``), all through :func:`~meshlap_core.io.atomic.atomic_write`."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import MeshError
from ..types import FloatArray, IntArray, as_faces, as_mesh, real_array
from .atomic import PathLike, atomic_write

WRITE_FORMATS: tuple[str, ...] = (".obj", ".off", ".ply")
SCALAR_FORMATS: tuple[str, ...] = (".csv", ".npy", ".ply")


def save_mesh(
    path: PathLike,
    V: Any,
    F: Any,
    *,
    scalars: Any = None,
    uv: Any = None,
    uv_faces: Any = None,
    overwrite_inputs: Iterable[PathLike] = (),
    binary: bool = True,
) -> None:
    """Write a triangle mesh as ``.obj``, ``.off`` or ``.ply`` (by extension), atomically.

    Parameters
    ----------
    path : str or PathLike
    V : (n,3) float
    F : (m,3) int
        0-based (written 1-based in OBJ).
    scalars : (n,) float, optional
        Per-vertex values, stored as the PLY vertex property ``quality`` (``double``); only
        ``.ply`` can carry them.
    uv : (t,2) float, optional
        Texture coordinates, written as OBJ ``vt`` lines (17 significant digits); only
        ``.obj`` can carry them.
    uv_faces : (m,3) int, optional
        The ``vt`` index of every face corner (0-based; written ``f v/vt``): a seam gives one
        vertex several texture coordinates. Default ``F`` (one ``vt`` per vertex, ``t = n``).
    overwrite_inputs : iterable of path
        Paths that must not be overwritten (the CLI passes its input file).
    binary : bool
        PLY only: ``binary_little_endian`` (default) or ``ascii``.

    Raises
    ------
    MeshError
        Unknown extension, scalars of the wrong length or on a non-PLY file, texture
        coordinates on a non-OBJ file or not finite ``(t,2)``, ``uv_faces`` of the wrong shape
        or out of range (each named), a missing output directory (named), or writing onto an
        input.

    Notes
    -----
    Coordinates are written with 17 significant digits in the text formats (and as doubles in
    binary PLY), so a write/read round trip gives back exactly the same ``V`` and ``F``.

    Examples
    --------
    A per-vertex field travels with the mesh in a PLY file (the vertex property ``quality``):

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from meshlap_core import icosphere, load_mesh, save_mesh
    >>> V, F = icosphere(1)
    >>> path = Path(tempfile.mkdtemp()) / "sphere.ply"
    >>> save_mesh(path, V, F, scalars=V[:, 2])
    >>> np.array_equal(load_mesh(path).V, V)  # binary doubles: exact
    True
    >>> b"property double quality" in path.read_bytes()
    True
    """
    ext = Path(os.fspath(path)).suffix.lower()
    if ext not in WRITE_FORMATS:
        raise MeshError(
            f"cannot write {ext!r} files; use one of {', '.join(WRITE_FORMATS)}"
            if ext
            else f"the output has no extension; use one of {', '.join(WRITE_FORMATS)}",
            os.fspath(path),
        )
    V, F = as_mesh(V, F)
    q = None
    if scalars is not None:
        if ext != ".ply":
            raise MeshError("only .ply files can carry per-vertex scalars", os.fspath(path))
        q = np.asarray(scalars, dtype=np.float64).ravel()
        if len(q) != len(V):
            raise MeshError(f"has {len(q):,} values for {len(V):,} vertices", "scalars")
    texture = None
    if uv is not None or uv_faces is not None:
        if ext != ".obj":
            raise MeshError("only .obj files can carry texture coordinates", os.fspath(path))
        texture = _texture(uv, uv_faces, F)
    if ext == ".ply":
        with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
            _write_ply(f, V, F, q, binary)
        return
    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        if ext == ".obj":
            f.write(f"# written by meshlap: {len(V)} vertices, {len(F)} faces\n".encode())
            np.savetxt(f, V, fmt="v %.17g %.17g %.17g")
            if texture is None:
                np.savetxt(f, F + 1, fmt="f %d %d %d")
            else:
                np.savetxt(f, texture[0], fmt="vt %.17g %.17g")
                corners = np.stack([F + 1, texture[1] + 1], axis=2).reshape(-1, 6)
                np.savetxt(f, corners, fmt="f %d/%d %d/%d %d/%d")
        else:
            f.write(f"OFF\n{len(V)} {len(F)} 0\n".encode())
            np.savetxt(f, V, fmt="%.17g %.17g %.17g")
            np.savetxt(f, F, fmt="3 %d %d %d")


def _texture(uv: Any, uv_faces: Any, F: IntArray) -> tuple[FloatArray, IntArray]:
    """The checked ``(uv (t,2), uv_faces (m,3))`` of :func:`save_mesh`."""
    if uv is None:
        raise MeshError("uv_faces without uv: give the texture coordinates too", "uv")
    raw = real_array(uv, "uv", "texture coordinates")
    coords = np.array(raw, dtype=np.float64)
    if coords.ndim != 2 or coords.shape[1] != 2:
        raise MeshError(f"should have shape (t,2); shape is {coords.shape}", "uv")
    if not np.isfinite(coords).all():
        bad = int(np.flatnonzero(~np.isfinite(coords).all(axis=1))[0])
        raise MeshError(f"texture coordinate {bad} is NaN or infinite", "uv")
    if uv_faces is None:
        used = int(F.max(initial=-1)) + 1
        if len(coords) < used:
            raise MeshError(
                f"has {len(coords)} coordinates but the faces use {used} vertices (give "
                "uv_faces for a map with seams)",
                "uv",
            )
        return coords, F
    FT = as_faces(uv_faces, len(coords), "uv_faces")
    if FT.shape != F.shape:
        raise MeshError(
            f"should have shape {F.shape} (one per face corner); shape is {FT.shape}", "uv_faces"
        )
    return coords, FT


def _write_ply(
    f: IO[bytes], V: FloatArray, F: IntArray, q: FloatArray | None, binary: bool
) -> None:
    props = list("xyz") + (["quality"] if q is not None else [])
    head = [
        "ply",
        f"format {'binary_little_endian' if binary else 'ascii'} 1.0",
        "comment written by meshlap",
        f"element vertex {len(V)}",
        *(f"property double {p}" for p in props),
        f"element face {len(F)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    f.write(("\n".join(head) + "\n").encode("ascii"))
    cols = V if q is None else np.column_stack([V, q])
    if binary:
        f.write(np.ascontiguousarray(cols, dtype="<f8").tobytes())
        if len(F) and F.max() > np.iinfo(np.int32).max:
            raise MeshError("too many vertices for a PLY int32 index", "F")
        rec = np.empty(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        rec["n"] = 3
        rec["i"] = F
        f.write(rec.tobytes())
    else:
        np.savetxt(f, cols, fmt=" ".join(["%.17g"] * cols.shape[1]))
        np.savetxt(f, F, fmt="3 %d %d %d")


def save_scalars(
    path: PathLike,
    values: Any,
    *,
    V: Any = None,
    F: Any = None,
    overwrite_inputs: Iterable[PathLike] = (),
) -> None:
    """Write per-vertex (or per-face) scalars as ``.csv``, ``.npy`` or ``.ply``, atomically.

    Parameters
    ----------
    path : str or PathLike
        ``.csv``: a header line ``value`` then one value per line (17 significant digits);
        ``.npy``: a 1-D float64 array; ``.ply``: the mesh with a ``quality`` vertex property
        (needs ``V`` and ``F``).
    values : (n,) float
    V : (n,3) float, optional
    F : (m,3) int, optional
        Required for ``.ply``.
    overwrite_inputs : iterable of path
        Paths that must not be overwritten.

    Raises
    ------
    MeshError
        Unknown extension, values not 1-D, ``.ply`` without ``V``/``F``, or the output
        problems of :func:`atomic_write`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from meshlap_core import save_scalars
    >>> path = Path(tempfile.mkdtemp()) / "H.csv"
    >>> save_scalars(path, [1.0, 0.5, 1 / 3])
    >>> path.read_text().splitlines()  # 17 significant digits: the values round-trip
    ['value', '1', '0.5', '0.33333333333333331']
    """
    ext = Path(os.fspath(path)).suffix.lower()
    if ext not in SCALAR_FORMATS:
        raise MeshError(
            f"cannot write scalars to {ext or 'a file without extension'!r}; use one of "
            f"{', '.join(SCALAR_FORMATS)}",
            os.fspath(path),
        )
    vals = np.asarray(values, dtype=np.float64)
    if vals.ndim != 1:
        raise MeshError(f"should be a 1-D array; shape is {vals.shape}", "values")
    if ext == ".ply":
        if V is None or F is None:
            raise MeshError("writing scalars to .ply needs the mesh (V and F)", os.fspath(path))
        save_mesh(path, V, F, scalars=vals, overwrite_inputs=overwrite_inputs)
        return
    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        if ext == ".npy":
            np.save(f, vals, allow_pickle=False)
        else:
            f.write(b"value\n")
            np.savetxt(f, vals, fmt="%.17g")
