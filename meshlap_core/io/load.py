"""Loading: the file read, the format chosen by extension, the result validated."""

from __future__ import annotations

import os
import stat
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import MeshError, check_cancel
from ..types import FloatArray
from ..validate import Mesh, validate_mesh
from ._scan import Parsed
from .atomic import PathLike
from .obj import parse_obj
from .off import _parse_off
from .ply import _parse_ply
from .stl import _parse_stl

MESH_FORMATS: tuple[str, ...] = (".obj", ".off", ".ply", ".stl")
#: bytes read at most from a file that reports size 0 (procfs-like files that stream)
UNSIZED_READ_LIMIT = 64 * 2**20
#: seconds a read may take (checked between reads of a file; local disks read GBs in that)
READ_TIME_LIMIT = 300.0


def load_mesh(
    path: PathLike,
    *,
    repair: bool = True,
    progress: Callable[[float, str], None] | None = None,
    cancel: Any = None,
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
    >>> mesh = load_mesh("bunny.obj")            # doctest: +SKIP
    >>> mesh.V.shape, mesh.report.repairs        # doctest: +SKIP
    ((3485, 3), [])
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
    parsed = _parse_ply(data, src)
    if name not in parsed.vertex_props:
        have = ", ".join(sorted(parsed.vertex_props)) or "none"
        raise MeshError(f"the vertex element has no property {name!r} (properties: {have})", src)
    return parsed.vertex_props[name]


def _read_input(path: PathLike) -> tuple[Path, str, bytes]:
    try:
        src = os.fspath(path)
    except TypeError:
        raise MeshError(f"expected a file path, got {type(path).__name__}", "path") from None
    p = Path(src)
    if not p.exists():
        raise MeshError("no such file", src)
    if p.is_dir():
        raise MeshError("is a directory, not a mesh file", src)
    ext = p.suffix.lower()
    if ext not in MESH_FORMATS:
        what = f"unknown mesh format {p.suffix!r}" if ext else "the file name has no extension"
        raise MeshError(f"{what}; supported formats: {', '.join(MESH_FORMATS)}", src)
    try:
        mode = p.stat().st_mode
    except OSError as exc:
        raise MeshError(f"cannot read the file: {exc.strerror or exc}", src) from None
    if not stat.S_ISREG(mode):  # a FIFO would block forever, /dev/zero would never end
        raise MeshError(f"not a regular file ({_kind(mode)}); meshlap reads mesh files only", src)
    data = read_bounded(p, src)
    if not data or data.isspace():
        raise MeshError(
            "the file is empty" if not data else "the file contains only whitespace", src
        )
    return p, src, data


def _parse(ext: str, data: bytes, src: str) -> Parsed:
    if ext == ".obj":
        return parse_obj(data, src)
    if ext == ".off":
        return _parse_off(data, src)
    if ext == ".ply":
        return _parse_ply(data, src)
    return _parse_stl(data, src)


def _kind(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "a named pipe (FIFO)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "a socket" if stat.S_ISSOCK(mode) else "a special file"


def read_bounded(path: PathLike, src: str) -> bytes:
    """The bytes of a regular file, read with bounds on size and time.

    A file is read up to the size it reports (one byte more is the evidence that it lied);
    one that reports size 0 (procfs and sysfs files do) up to :data:`UNSIZED_READ_LIMIT`.
    The file is opened non-blocking, so a kernel stream with no data ready (``/proc/kmsg``)
    answers at once instead of hanging, and reading stops after :data:`READ_TIME_LIMIT`
    seconds (checked between reads).

    Raises
    ------
    MeshError
        Unreadable, not a regular file, more data than reported, a stream with no data
        ready, or too slow; the message names ``src``.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(path, flags | getattr(os, "O_BINARY", 0))
    except PermissionError:
        raise MeshError("cannot read the file: permission denied", src) from None
    except OSError as exc:
        raise MeshError(f"cannot read the file: {exc.strerror or exc}", src) from None
    with os.fdopen(fd, "rb", buffering=0) as f:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):  # replaced since it was checked
            raise MeshError(
                f"not a regular file ({_kind(st.st_mode)}); meshlap reads mesh files only", src
            )
        return _read_chunks(f, st.st_size, src)


def _read_chunks(f: Any, size: int, src: str) -> bytes:
    limit = size if size > 0 else UNSIZED_READ_LIMIT
    chunks: list[bytes] = []
    got = 0
    t0 = time.monotonic()
    while True:
        try:
            # one read of the whole reported size; an unsized file in 1 MB reads (procfs files
            # such as pagemap only accept multiples of 8 bytes)
            chunk = f.read(size + 1 - got if size else 1 << 20)
        except OSError as exc:
            raise MeshError(f"cannot read the file: {exc.strerror or exc}", src) from None
        if chunk is None:
            raise MeshError(
                "the file has no data ready: a kernel or device stream, not a mesh file", src
            )
        if not chunk:
            break
        chunks.append(chunk)
        got += len(chunk)
        if got > limit:
            more = (
                f"{size:,} bytes (still being written?)"
                if size
                else f"{UNSIZED_READ_LIMIT // 2**20} MB (a kernel or device file, not a mesh file)"
            )
            raise MeshError(f"the file reports size {size:,} but streams more than {more}", src)
        if time.monotonic() - t0 > READ_TIME_LIMIT:
            raise MeshError(f"reading took over {READ_TIME_LIMIT:.0f} s; stopped", src)
    return chunks[0] if len(chunks) == 1 else b"".join(chunks)
