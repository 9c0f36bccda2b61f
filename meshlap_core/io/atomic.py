"""Output paths checked before any work, and files written atomically (temp file, fsync,
``os.replace``): used by every writer of meshes, scalars, reports and caches."""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO, Any

from ..errors import MeshError

PathLike = str | os.PathLike

_CAUSES = {
    errno.ENOSPC: "no space left on device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EROFS: "read-only file system",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.EPIPE: "broken pipe",
    errno.EIO: "input/output error",
    errno.EFBIG: "file too large",
}


def os_cause(exc: BaseException) -> str:
    """The cause of an :class:`OSError` in a few words (``"no space left on device"``,
    ``"read-only file system"``, ...): never a raw ``[Errno N]`` prefix, nor a second line (an
    ffmpeg command) that some libraries append.

    Parameters
    ----------
    exc : BaseException

    Returns
    -------
    str
    """
    code = getattr(exc, "errno", None)
    if code in _CAUSES:
        return _CAUSES[code]
    text = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return text.strip().splitlines()[0] if text.strip() else type(exc).__name__


def unwritable_cause(folder: PathLike) -> str:
    """Why this process cannot write in ``folder``: ``"read-only file system"`` when it is on
    one, else ``"permission denied"``.

    Parameters
    ----------
    folder : str or PathLike

    Returns
    -------
    str
    """
    with contextlib.suppress(OSError, AttributeError):
        if os.statvfs(folder).f_flag & os.ST_RDONLY:
            return "read-only file system"
    return "permission denied"


def _discard(f: IO[Any], tmp: Path) -> None:
    """Close ``f`` and remove ``tmp`` whatever happens: the close may flush and fail again
    (a full disk: ENOSPC a second time), yet the descriptor is closed by then (``io`` closes the
    raw file even when the flush raises), and the unlink must run regardless."""
    with contextlib.suppress(Exception):
        f.close()
    with contextlib.suppress(OSError):
        os.unlink(tmp)


def _resolved(path: PathLike) -> Path:
    return Path(os.path.abspath(os.fspath(path))).resolve(strict=False)


_SPECIAL = (
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
)


def _existing_kind(target: Path) -> str | None:
    """What is at ``target`` without following a symbolic link: ``None`` (nothing), ``"file"``,
    ``"link"``, ``"directory"`` or the kind of special file (``"a character device"``, ...)."""
    try:
        mode = os.lstat(target).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError:
        return None  # (not readable: the write will say why)
    if stat.S_ISLNK(mode):
        return "link"
    if stat.S_ISDIR(mode):
        return "directory"
    if stat.S_ISREG(mode):
        return "file"
    return next((name for test, name in _SPECIAL if test(mode)), "a special file")


def _check_output_path(path: PathLike, overwrite_inputs: Iterable[PathLike]) -> Path:
    """The one rule for outputs: a new regular file replaces whatever name ``path`` is. A
    symbolic link there is replaced itself (never written through: what it points to is left
    alone); a directory, a device, a FIFO or a socket there is refused, as is an input."""
    target = Path(os.fspath(path))
    if not os.fspath(path):
        raise MeshError("the output path is empty", "path")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise MeshError("the output directory does not exist", os.fspath(parent))
    kind = _existing_kind(target)
    if kind == "directory":
        raise MeshError("the output path is a directory", os.fspath(target))
    if kind not in (None, "file", "link"):
        raise MeshError(
            f"the output path is {kind}, not a regular file; meshlap writes only regular "
            "files (choose another name)",
            os.fspath(target),
        )
    res = _resolved(target)
    for inp in overwrite_inputs:
        same = _resolved(inp) == res or _absolute(inp) == _absolute(target)
        if not same and target.exists() and Path(os.fspath(inp)).exists():
            with contextlib.suppress(OSError):
                same = os.path.samefile(target, inp)
        if same:
            raise MeshError(
                "refusing to overwrite an input file; choose a different output path",
                os.fspath(target),
            )
    return target


def _absolute(path: PathLike) -> Path:
    """``path`` made absolute without resolving links (the name itself, not its target)."""
    return Path(os.path.abspath(os.fspath(path)))


def check_output_path(
    path: PathLike, overwrite_inputs: Iterable[PathLike] = (), suffixes: Iterable[str] | None = None
) -> Path:
    """Check an output path before any work is done (commands call it first, so that a
    doomed run fails in a second and leaves nothing behind).

    Parameters
    ----------
    path : str or PathLike
    overwrite_inputs : iterable of path
        Inputs the output must not replace.
    suffixes : iterable of str, optional
        Allowed extensions (lowercase, with the dot).

    Returns
    -------
    path : Path

    Raises
    ------
    MeshError
        Empty path, a missing directory (named), a directory, device, FIFO or socket as
        target (a symbolic link is fine: it is replaced, not followed), an input as target,
        or an extension not in ``suffixes``.
    """
    target = _check_output_path(path, overwrite_inputs)
    if suffixes is not None:
        allowed = tuple(suffixes)
        if target.suffix.lower() not in allowed:
            raise MeshError(
                f"unsupported output type {target.suffix or '(none)'!r}; use {', '.join(allowed)}",
                os.fspath(path),
            )
    return target


@contextlib.contextmanager
def atomic_write(
    path: PathLike,
    mode: str = "w",
    *,
    overwrite_inputs: Iterable[PathLike] = (),
    encoding: str = "utf-8",
    keep_mode: bool = True,
) -> Iterator[IO[Any]]:
    """Write a file atomically: the target appears complete or not at all.

    A temporary file is created in the target's directory (mode ``0666`` less the umask),
    written through the yielded file object, flushed, fsync'ed and renamed over the target
    with ``os.replace``. The one rule for outputs (:func:`check_output_path`): a symbolic
    link at ``path`` is replaced itself, never written through; a directory, device, FIFO
    or socket there is refused. If the ``with``
    body, the flush, the fsync or the rename raises, the temporary file is closed without
    depending on a flush (a full disk fails the flush again) and removed, and an existing
    target is left untouched.

    Parameters
    ----------
    path : str or PathLike
        The file to (re)place.
    mode : {"w", "wb"}
        Text (UTF-8, ``\\n`` newlines) or binary.
    overwrite_inputs : iterable of path
        Paths that must not be written (e.g. the command's input mesh); compared after
        resolving symlinks.
    keep_mode : bool
        Give the new file the permissions of the regular file it replaces (default; a
        replaced link passes on nothing); ``False`` creates it with the default permissions
        (the cache does, so that an entry someone made unreadable is replaced by a readable
        one).

    Yields
    ------
    f : file object

    Raises
    ------
    MeshError
        The directory does not exist (named), the target is a directory or one of
        ``overwrite_inputs``, the directory is not writable, or the file cannot be written
        (an :class:`OSError` of the write, flush, fsync or rename: the message names the target
        and the cause, e.g. "no space left on device", "read-only file system").

    Examples
    --------
    >>> with atomic_write(tmp / "values.txt") as f:   # doctest: +SKIP
    ...     f.write("1.0\\n")
    """
    if mode not in ("w", "wb"):
        raise MeshError(f"mode must be 'w' or 'wb', got {mode!r}", "mode")
    target = _check_output_path(path, overwrite_inputs)
    parent = target.parent if str(target.parent) else Path(".")
    tmp = parent / f".{target.name}.{secrets.token_hex(6)}.tmp"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    except OSError as exc:
        raise MeshError(
            f"cannot create a file in {os.fspath(parent)!r}: {os_cause(exc)}", os.fspath(target)
        ) from None
    if keep_mode and _existing_kind(target) == "file":
        # keep the permissions of the regular file being replaced; a link's target is not
        # what is replaced, so its mode is not copied (the new file gets the umask's)
        with contextlib.suppress(OSError):
            os.chmod(tmp, stat.S_IMODE(os.lstat(target).st_mode))
    try:
        f: IO[Any] = (
            os.fdopen(fd, "wb")
            if mode == "wb"
            else os.fdopen(fd, "w", encoding=encoding, newline="\n")
        )
    except BaseException:
        with contextlib.suppress(OSError):
            os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    try:
        yield f
        f.flush()
        os.fsync(f.fileno())
        f.close()
        os.replace(tmp, target)
    except OSError as exc:
        _discard(f, tmp)
        raise MeshError(f"cannot write the file: {os_cause(exc)}", os.fspath(target)) from exc
    except BaseException:
        _discard(f, tmp)
        raise
    with contextlib.suppress(OSError):  # make the rename itself durable (best effort)
        dfd = os.open(parent, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)
