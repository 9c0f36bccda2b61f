"""The one reader of every file meshlap reads: meshes, session files, cache entries.

Each file is checked *before* a byte is parsed: it must exist, be a regular file (not a
directory, a FIFO that would block, a device such as ``/dev/zero`` that never ends) and be at
most a size limit that depends on what it is (:data:`SIZE_LIMITS`, stated in
``docs/bad-input.md``). It is then opened non-blocking and read with bounds on size and time.
Every refusal is a :class:`~meshlap_core.errors.MeshError` naming the file.

:func:`read_json` adds the JSON layer: UTF-8 only, and a document nested too deeply or holding
an integer beyond Python's digit limit is bad input (one line naming the file), not an internal
error.
"""

from __future__ import annotations

import json
import os
import stat
import sys
import time
from typing import Any, BinaryIO

from ..errors import MeshError

#: the largest file of each kind meshlap reads (bytes)
SIZE_LIMITS: dict[str, int] = {
    "mesh file": 8 * 2**30,  # 8 GiB: about 150 M triangles as binary PLY
    "session file": 16 * 2**20,  # 16 MiB: a saved session is a few kB
    "cache file": 8 * 2**30,  # 8 GiB: a basis of 1000 modes on 1 M vertices
    "JSON file": 16 * 2**20,
    "image file": 256 * 2**20,  # a screenshot the report cropped (its own output)
}
MESH_SIZE_LIMIT = SIZE_LIMITS["mesh file"]
JSON_SIZE_LIMIT = SIZE_LIMITS["session file"]
#: bytes read at most from a file that reports size 0 (procfs-like files that stream)
UNSIZED_READ_LIMIT = 64 * 2**20
#: seconds a read may take (checked between reads of a file; local disks read GBs in that)
READ_TIME_LIMIT = 300.0


def input_path(path: Any) -> str:
    """``path`` as a string (``os.fspath``; bytes decoded as the file system does).

    Raises
    ------
    MeshError
        ``path`` is not a path.
    """
    try:
        return os.fsdecode(os.fspath(path))
    except TypeError:
        raise MeshError(f"expected a file path, got {type(path).__name__}", "path") from None


def kind_of(mode: int) -> str:
    """What a non-regular file is, in words (``"a named pipe (FIFO)"``, ``"a device"``)."""
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a named pipe (FIFO)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "a socket" if stat.S_ISSOCK(mode) else "a special file"


def _size_words(n: int) -> str:
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n} bytes"


def _check_stat(st: os.stat_result, src: str, what: str, max_bytes: int) -> None:
    if stat.S_ISDIR(st.st_mode):
        raise MeshError(f"is a directory, not a {what}", src)
    if not stat.S_ISREG(st.st_mode):
        raise MeshError(
            f"not a regular file ({kind_of(st.st_mode)}); a {what} must be a regular file", src
        )
    if st.st_size > max_bytes:
        raise MeshError(
            f"the file is {_size_words(st.st_size)}; a {what} may be at most "
            f"{_size_words(max_bytes)}",
            src,
        )


def check_input(path: Any, *, what: str = "mesh file", max_bytes: int | None = None) -> str:
    """Check that ``path`` is a regular file of at most ``max_bytes`` bytes, without opening it.

    Parameters
    ----------
    path : str or PathLike
    what : str
        What the file should be (``"mesh file"``, ``"session file"``, ``"cache file"``),
        used in messages and, when ``max_bytes`` is None, to look up :data:`SIZE_LIMITS`.
    max_bytes : int, optional

    Returns
    -------
    src : str
        The path as a string.

    Raises
    ------
    MeshError
        No such file, a directory, a FIFO, device or socket, a file over the limit, or one
        that cannot be examined; the message names the file.
    """
    src = input_path(path)
    limit = SIZE_LIMITS.get(what, MESH_SIZE_LIMIT) if max_bytes is None else int(max_bytes)
    try:
        st = os.stat(src)
    except FileNotFoundError:
        raise MeshError("no such file", src) from None
    except PermissionError:
        raise MeshError("cannot read the file: permission denied", src) from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the name
        why = getattr(exc, "strerror", None) or exc
        raise MeshError(f"cannot read the file: {why}", src) from None
    _check_stat(st, src, what, limit)
    return src


def open_input(path: Any, *, what: str = "mesh file", max_bytes: int | None = None) -> BinaryIO:
    """Open a checked input file for reading (binary, unbuffered; the caller closes it).

    The checks of :func:`check_input` run before the file is opened and again on the open
    descriptor (the path may have been replaced in between). The file is opened non-blocking,
    so that a FIFO swapped in cannot hang the open.

    Returns
    -------
    f : binary file object

    Raises
    ------
    MeshError
        As :func:`check_input`, or the file cannot be opened.
    """
    src = check_input(path, what=what, max_bytes=max_bytes)
    limit = SIZE_LIMITS.get(what, MESH_SIZE_LIMIT) if max_bytes is None else int(max_bytes)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(src, flags | getattr(os, "O_BINARY", 0))
    except PermissionError:
        raise MeshError("cannot read the file: permission denied", src) from None
    except OSError as exc:
        raise MeshError(f"cannot read the file: {exc.strerror or exc}", src) from None
    try:
        _check_stat(os.fstat(fd), src, what, limit)
    except BaseException:
        os.close(fd)
        raise
    return os.fdopen(fd, "rb", buffering=0)


def read_input(path: Any, *, what: str = "mesh file", max_bytes: int | None = None) -> bytes:
    """The bytes of a checked input file, read with bounds on size and time.

    A file is read up to the size it reports (one byte more is the evidence that it lied);
    one that reports size 0 (procfs and sysfs files do) up to :data:`UNSIZED_READ_LIMIT`.
    Reading stops after :data:`READ_TIME_LIMIT` seconds (checked between reads); a kernel
    stream with no data ready answers at once instead of hanging.

    Parameters
    ----------
    path : str or PathLike
    what : str
        ``"mesh file"``, ``"session file"``, ``"cache file"`` (see :data:`SIZE_LIMITS`).
    max_bytes : int, optional
        Overrides the limit of ``what``.

    Returns
    -------
    data : bytes

    Raises
    ------
    MeshError
        As :func:`open_input`; more data than reported; a stream with no data ready; too
        slow. The message names the file.
    """
    src = input_path(path)
    with open_input(src, what=what, max_bytes=max_bytes) as f:
        size = os.fstat(f.fileno()).st_size
        return _read_chunks(f, size, src, what)


def _read_chunks(f: Any, size: int, src: str, what: str) -> bytes:
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
                f"the file has no data ready: a kernel or device stream, not a {what}", src
            )
        if not chunk:
            break
        chunks.append(chunk)
        got += len(chunk)
        if got > limit:
            more = (
                f"{size:,} bytes (still being written?)"
                if size
                else f"{UNSIZED_READ_LIMIT // 2**20} MB (a kernel or device file, not a {what})"
            )
            raise MeshError(f"the file reports size {size:,} but streams more than {more}", src)
        if time.monotonic() - t0 > READ_TIME_LIMIT:
            raise MeshError(f"reading took over {READ_TIME_LIMIT:.0f} s; stopped", src)
    return chunks[0] if len(chunks) == 1 else b"".join(chunks)


def read_json(path: Any, *, what: str = "session file", max_bytes: int | None = None) -> Any:
    """Read a JSON document through :func:`read_input` (the size limit of ``what``, 16 MiB for
    a session file).

    Parameters
    ----------
    path : str or PathLike
    what : str
        What the file is, for messages and its size limit.
    max_bytes : int, optional
        Overrides the limit.

    Returns
    -------
    value : the decoded JSON value (dict, list, str, int, float, bool or None)

    Raises
    ------
    MeshError
        Everything :func:`read_input` refuses; text that is not UTF-8; not JSON (line and
        column given); nesting too deep for the parser (``RecursionError``); an integer
        beyond Python's digit limit. The message names the file.

    Examples
    --------
    >>> read_json("lecture.json")["version"]   # doctest: +SKIP
    1
    """
    src = input_path(path)
    data = read_input(src, what=what, max_bytes=max_bytes)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise MeshError(f"not a {what} (not UTF-8 text)", src) from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise MeshError(
            f"not JSON ({exc.msg} at line {exc.lineno}, column {exc.colno})", src
        ) from None
    except RecursionError:
        raise MeshError(f"not a {what}: the JSON is nested too deeply to read", src) from None
    except ValueError:  # Python's limit on the digits of an int (sys.int_info)
        raise MeshError(
            f"not a {what}: an integer in it has more than {sys.get_int_max_str_digits()} digits",
            src,
        ) from None
