"""Loading: the file read, the format chosen by extension, the result validated."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError, check_cancel
from ..types import FloatArray, IntArray
from ..validate import Mesh, validate_mesh
from ._scan import Parsed
from .atomic import PathLike
from .obj import parse_obj
from .off import parse_off
from .ply import parse_ply
from .reader import READ_TIME_LIMIT, UNSIZED_READ_LIMIT, check_input, read_input
from .stl import parse_stl

MESH_FORMATS: tuple[str, ...] = (".obj", ".off", ".ply", ".stl")
__all__ = [
    "MESH_FORMATS",
    "READ_TIME_LIMIT",
    "UNSIZED_READ_LIMIT",
    "load_mesh",
    "load_vertex_scalars",
    "read_bounded",
]


def load_mesh(
    path: PathLike,
    *,
    repair: bool = True,
    progress: Callable[[float, str], None] | None = None,
    cancel: Any = None,
    on_parsed: Callable[[FloatArray, IntArray], None] | None = None,
) -> Mesh:
    """Load an OBJ, OFF, PLY (ASCII / binary) or STL (ASCII / binary) triangle mesh.

    The format is chosen by the extension (case-insensitive). The result is validated (and,
    with ``repair=True``, repaired) by :func:`meshlap_core.validate.validate_mesh`.

    Parameters
    ----------
    path : str or PathLike
    repair : bool
        Remove degenerate / duplicate faces and unreferenced vertices (always reported).
    progress : callable, optional
        ``progress(fraction, message)`` at the start of each phase (reading, parsing,
        validating; fractions 0, 0.1, 0.5 by their typical share of the time) and at the end.
    cancel : threading.Event or callable, optional
        Checked between the phases: once set (or returning ``True``) loading stops with
        :class:`~meshlap_core.errors.Cancelled`.
    on_parsed : callable, optional
        ``on_parsed(V, F)`` with the file's vertices ``(n,3) float64`` and triangles
        ``(m,3) int64`` as parsed, before validation, when every face is a triangle with
        in-range indices and every coordinate is finite (a viewer shows them at once while
        the validation runs; validation may still repair or refuse them). The arrays are the
        parser's: not to be modified.

    Returns
    -------
    mesh : Mesh
        ``mesh.V (n,3) float64``, ``mesh.F (m,3) int64``, ``mesh.report`` (repairs, warnings,
        manifoldness), ``mesh.vertex_map`` (index of each vertex in the file).

    Raises
    ------
    MeshError
        Missing / unreadable / empty file, a directory, an unknown extension, or any problem
        with the contents (the message names the file).

    Examples
    --------
    A write / read round trip gives back exactly the same arrays:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from meshlap_core import icosphere, load_mesh, save_mesh
    >>> V, F = icosphere(2)
    >>> path = Path(tempfile.mkdtemp()) / "sphere.obj"
    >>> save_mesh(path, V, F)
    >>> mesh = load_mesh(path)
    >>> mesh.V.shape, np.array_equal(mesh.V, V), np.array_equal(mesh.F, F), mesh.report.repairs
    ((162, 3), True, True, [])
    """

    def phase(fraction: float, message: str) -> None:
        check_cancel(cancel, "loading")
        if progress is not None:
            progress(fraction, message)

    phase(0.0, "reading the file")
    p, src, data = _read_input(path)
    phase(0.1, f"parsing {len(data) / 2**20:.0f} MB")
    parsed = _parse(p.suffix.lower(), data, src)
    del data  # the parsed arrays are copies: free the file's bytes before validating
    if on_parsed is not None:
        _hand_over(parsed, on_parsed)
    phase(0.5, f"validating {len(parsed.V):,} vertices")
    mesh = validate_mesh(
        parsed.V,
        parsed.faces,
        src,
        repair=repair,
        vertex_map=parsed.vertex_map,
        repairs=parsed.repairs,
        warnings=parsed.warnings,
    )
    phase(1.0, "loaded")
    return mesh


def load_vertex_scalars(path: PathLike, name: str = "quality") -> FloatArray:
    """Read one per-vertex scalar property (default ``quality``) from a PLY file.

    The values are in the file's vertex order (use ``mesh.vertex_map`` to follow a repaired
    mesh): ``load_vertex_scalars(p)[mesh.vertex_map]``.

    Parameters
    ----------
    path : str or PathLike
        A ``.ply`` file.
    name : str
        The vertex property.

    Returns
    -------
    values : (n,) float64

    Raises
    ------
    MeshError
        Not a PLY file, or the vertex element has no such property.
    """
    p, src, data = _read_input(path)
    if p.suffix.lower() != ".ply":
        raise MeshError(
            f"per-vertex scalars can only be read from .ply files, not {p.suffix!r}", src
        )
    parsed = parse_ply(data, src)
    if name not in parsed.vertex_props:
        have = ", ".join(sorted(parsed.vertex_props)) or "none"
        raise MeshError(f"the vertex element has no property {name!r} (properties: {have})", src)
    return parsed.vertex_props[name]


def _hand_over(parsed: Parsed, on_parsed: Callable[[FloatArray, IntArray], None]) -> None:
    """Call ``on_parsed(V, F)`` when ``parsed`` is plain triangles, in range, finite."""
    V, F = parsed.V, parsed.faces
    if not (isinstance(F, np.ndarray) and F.ndim == 2 and F.shape[1] == 3 and len(F)):
        return
    if not (isinstance(V, np.ndarray) and V.ndim == 2 and V.shape[1] == 3 and len(V)):
        return
    if F.min() < 0 or F.max() >= len(V) or not np.isfinite(V).all():
        return
    on_parsed(V.astype(np.float64, copy=False), F.astype(np.int64, copy=False))


def _read_input(path: PathLike) -> tuple[Path, str, bytes]:
    src = check_input(path, what="mesh file")  # a directory, device or oversize file: refused
    p = Path(src)
    ext = p.suffix.lower()
    if ext not in MESH_FORMATS:
        what = f"unknown mesh format {p.suffix!r}" if ext else "the file name has no extension"
        raise MeshError(f"{what}; supported formats: {', '.join(MESH_FORMATS)}", src)
    data = read_input(src, what="mesh file")
    if not data or data.isspace():
        raise MeshError(
            "the file is empty" if not data else "the file contains only whitespace", src
        )
    return p, src, data


def _parse(ext: str, data: bytes, src: str) -> Parsed:
    if ext == ".obj":
        return parse_obj(data, src)
    if ext == ".off":
        return parse_off(data, src)
    if ext == ".ply":
        return parse_ply(data, src)
    return parse_stl(data, src)


def read_bounded(path: PathLike, src: str) -> bytes:
    """The bytes of a regular file, read by :func:`meshlap_core.io.reader.read_input` (the
    mesh-file size limit; bounds on size and time); ``src`` names the file in messages.

    Raises
    ------
    MeshError
        Unreadable, not a regular file, more data than reported, a stream with no data ready,
        or too slow; the message names ``src``.
    """
    try:
        return read_input(path, what="mesh file")
    except MeshError as exc:
        raise MeshError(exc.problem, src) from None
