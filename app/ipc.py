"""The one way across processes: child processes from one fork server, and large arrays through
files in shared memory (no polyscope, no imgui).

**Child processes.** :class:`Child` starts ``target(conn, *args)`` in a child of a fork server
(a clean process that imported :data:`CHILD_PRELOAD` once, so a child starts in milliseconds;
never a fork of the window's process with its GL context and threads), with a pipe to it. The
child first takes the parent's current environment (the fork server's is that of the moment
it started). :func:`call` is the one-shot use: ``fn(*args, progress=reporter)`` in a child,
its progress reports and partial results relayed to the caller's reporter, its result or
error brought back; the jobs (:func:`meshlap_app.jobs.in_child`), the Check picture
(:func:`meshlap_app.screenshots.difference_png`) use it, and the smoothing stepper
(:mod:`meshlap_app.smoother_process`) keeps a :class:`Child` for a whole session of
commands. Cancel, a time limit or the end of the caller end the child at once; a child that
dies is a :class:`~meshlap_core.errors.MeshError` naming its exit code, and the files it
left in shared memory are removed.

**Large arrays.** Pickled whole and sent through a pipe, the 692k-vertex preview (``V``,
``F`` and a field, 53 MB) costs a pickle, a pipe write in 64 kB pieces, a read and an
unpickle: 0.3–0.6 s on a loaded machine before the window can show it; the eigenvectors at
k = 100 are 550 MB. :func:`pack` pickles a message with protocol 5 and writes its
out-of-band buffers (numpy arrays of at least :data:`SHARED_MIN_BYTES`) one after the other
into one file in ``/dev/shm``; the pipe carries the small pickle, the file's path and the
buffers' sizes (:class:`Packed`). :func:`unpack` maps the file (``mmap``), unlinks it at once
(the mapping stays valid) and unpickles the arrays over the mapping, copying nothing.
:class:`SharedBlock` is a file both processes map and keep (the smoother's positions and
normals, written by the child, read by the window).

Every file is named ``meshlap-ipc-<maker's pid>-…``: one that is never opened (its job
cancelled, its maker ended while sending) is removed by the next :func:`pack` or
:class:`SharedBlock` once its maker has ended (:func:`remove_stale`).
"""

from __future__ import annotations

import contextlib
import mmap
import multiprocessing
import os
import pickle
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshlap_core.errors import MeshError

SHARED_PREFIX = "meshlap-ipc-"
"""Name prefix of the files in shared memory, followed by the maker's pid and ``-``."""

SHARED_MIN_BYTES = 1 << 20
"""Arrays smaller than this travel inside the pickle (a file is not worth it)."""

CHILD_PRELOAD = (
    "numpy",
    "scipy.sparse",
    "meshlap_core.io",
    "meshlap_core.curvature",
    "meshlap_core.spectral",  # the eigenbasis job (app/state/spectral.py)
    "meshlap_core.smoothing",  # the stepper process (app/smoother_process.py)
)
"""Modules the fork server imports once, so each child starts in milliseconds."""

POLL_SECONDS = 0.05
"""How often a parent waiting for its child checks Cancel and its time limit."""


# ---------------------------------------------------------------------- files in shared memory
@dataclass
class Packed:
    """A message pickled for another process.

    Attributes
    ----------
    data : bytes
        The pickle (protocol 5), without the large buffers.
    path : str
        The shared-memory file holding the large buffers one after the other ("" when none).
    sizes : tuple of int
        The byte size of each buffer in the file, in pickling order.
    """

    data: bytes
    path: str = ""
    sizes: tuple[int, ...] = ()


def shared_folder() -> str:
    """``/dev/shm`` where it exists (memory, not disk), else the temporary folder."""
    return "/dev/shm" if os.path.isdir("/dev/shm") else tempfile.gettempdir()


def _new_file() -> tuple[int, str]:
    """A new file in :func:`shared_folder` named after this process (stale ones removed)."""
    folder = shared_folder()
    remove_stale(folder)
    return tempfile.mkstemp(prefix=f"{SHARED_PREFIX}{os.getpid()}-", dir=folder)


def pack(value: Any) -> Packed:
    """``value`` pickled, its arrays of at least :data:`SHARED_MIN_BYTES` written to a file in
    shared memory (in the process that sends it; dtype, shape and memory order kept)."""
    big: list[pickle.PickleBuffer] = []

    def out_of_band(buf: pickle.PickleBuffer) -> bool:
        if buf.raw().nbytes < SHARED_MIN_BYTES:
            return True  # serialised in band
        big.append(buf)
        return False

    data = pickle.dumps(value, protocol=5, buffer_callback=out_of_band)
    if not big:
        return Packed(data)
    fd, path = _new_file()
    try:
        with os.fdopen(fd, "wb") as f:
            for buf in big:
                f.write(buf.raw())
    except BaseException:
        discard(Packed(data, path))
        raise
    return Packed(data, path, tuple(buf.raw().nbytes for buf in big))


def unpack(packed: Packed) -> Any:
    """The value :func:`pack` pickled (in the process that receives it): its large arrays are
    writable views of the shared-memory file, mapped, then unlinked."""
    if not packed.path:
        return pickle.loads(packed.data)
    try:
        with open(packed.path, "r+b") as f:
            total = sum(packed.sizes)
            mapped = mmap.mmap(f.fileno(), total) if total else b""
    finally:
        discard(packed)
    view = memoryview(mapped)
    buffers, at = [], 0
    for size in packed.sizes:
        buffers.append(view[at : at + size])
        at += size
    return pickle.loads(packed.data, buffers=buffers)


def discard(packed: Any) -> None:
    """Remove the file of a :class:`Packed` message that will not be opened (or was)."""
    path = getattr(packed, "path", "")
    if path:
        with contextlib.suppress(OSError):
            os.unlink(path)


def remove_stale(folder: str, pid: int | None = None) -> None:
    """Remove the files ``meshlap-ipc-<maker>-*`` in ``folder`` whose maker process has ended
    (``pid``: only the files of that process, which the caller knows has ended)."""
    with contextlib.suppress(OSError):
        for name in os.listdir(folder):
            if not name.startswith(SHARED_PREFIX):
                continue
            try:
                maker = int(name[len(SHARED_PREFIX) :].split("-", 1)[0])
            except ValueError:
                continue
            keep = _running(maker) if pid is None else maker != pid
            if keep:
                continue
            with contextlib.suppress(OSError):
                os.unlink(os.path.join(folder, name))


def _running(pid: int) -> bool:
    """Whether process ``pid`` exists (another user's counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


class SharedBlock:
    """A block of memory two processes map: a file in shared memory (see the module
    docstring), made by :meth:`create` in one process and mapped by :meth:`attach` in the
    other. Once both have mapped it, :meth:`unlink` removes the file and the memory stays
    shared until both have closed it (nothing is left behind if either process dies).

    Attributes
    ----------
    path : str
        The file (to give to the other process).
    buf : mmap.mmap
        The mapping (``len(buf)`` bytes; :meth:`array` makes views of it).
    """

    def __init__(self, path: str, buf: mmap.mmap) -> None:
        self.path = path
        self.buf = buf

    @classmethod
    def create(cls, size: int) -> SharedBlock:
        """A new zero-filled block of ``size`` bytes (at least one)."""
        fd, path = _new_file()
        try:
            os.ftruncate(fd, max(1, int(size)))
            buf = mmap.mmap(fd, max(1, int(size)))
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(path)
            raise
        finally:
            os.close(fd)
        return cls(path, buf)

    @classmethod
    def attach(cls, path: str) -> SharedBlock:
        """The block another process made (:meth:`create`), mapped here."""
        with open(path, "r+b") as f:
            return cls(path, mmap.mmap(f.fileno(), 0))

    def array(self, shape: tuple[int, ...], dtype: Any, offset: int = 0) -> np.ndarray:
        """A view of the block: ``shape`` and ``dtype`` starting ``offset`` bytes in."""
        return np.ndarray(shape, dtype=dtype, buffer=self.buf, offset=offset)

    def unlink(self) -> None:
        """Remove the file (the mappings stay valid); idempotent."""
        with contextlib.suppress(OSError):
            os.unlink(self.path)

    def close(self) -> None:
        """Unmap the block here (while views of it live, it stays mapped until they go)."""
        with contextlib.suppress(BufferError):
            self.buf.close()


# ---------------------------------------------------------------------- child processes
NO_CHILD = (OSError, ValueError, RuntimeError, TypeError, AttributeError, pickle.PicklingError)
"""What starting a child may raise where none can start (no fork server, an unpicklable
target or argument): :class:`Child` turns it into :class:`NoChildProcess`."""


class NoChildProcess(RuntimeError):
    """No child process can start here (no fork server, or the target does not pickle): the
    caller runs the work in its own process instead."""


def error_message(exc: BaseException) -> str:
    """The one-line message of an error a job or a child reports: a ``MeshError`` as it is,
    an ``OSError`` as ``file: reason``, anything else as ``Type: message``."""
    if isinstance(exc, MeshError):
        return str(exc)
    if isinstance(exc, OSError):
        name = getattr(exc, "filename", None)
        return f"{name}: {exc.strerror or exc}" if name else str(exc)
    return f"{type(exc).__name__}: {exc}"


def context() -> Any:
    """The fork server's multiprocessing context (its preload: :data:`CHILD_PRELOAD`)."""
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(list(CHILD_PRELOAD))
    return ctx


def start_server() -> None:
    """Start the fork server now (the first child then starts at once).

    Raises
    ------
    NoChildProcess
        No fork server here.
    """
    try:
        from multiprocessing import forkserver

        context()
        forkserver.ensure_running()
    except Exception as exc:
        raise NoChildProcess(str(exc)) from exc


class ChildReporter:
    """The reporter a child's function is given (``progress(fraction, message)``, as the
    core's ``progress=`` arguments expect): sends each report, and each partial result
    through :func:`pack`, to the parent (which checks Cancel and ends the child)."""

    cancel = None  # the parent cancels by ending the process
    remote = True  # what the function returns is sent to another process

    def __init__(self, conn: Any) -> None:
        self.conn = conn
        self.fraction: float | None = None

    def __call__(self, fraction: float | None, message: str = "") -> None:
        self.fraction = fraction
        self.conn.send(("progress", fraction, message))

    def phase_only(self, message: str) -> None:
        self(self.fraction, message)

    def check(self) -> None:
        """Nothing to check here (the parent ends the process on Cancel)."""

    def partial(self, value: Any) -> None:
        """Send a partial result to the parent (its reporter's ``partial``)."""
        self.conn.send(("partial", pack(value)))


def _enter(conn: Any, environ: dict[str, str], target: Callable[..., Any], args: Any) -> None:
    """The child's first step: the parent's environment of now, then ``target(conn, *args)``."""
    os.environ.clear()
    os.environ.update(environ)
    target(conn, *args)


class Child:
    """A child process from the fork server running ``target(conn, *args)``, and this
    process's end of the pipe to it.

    Parameters
    ----------
    target : callable
        Module level (it is pickled by name); its first argument is the child's end of the
        pipe.
    *args
        Picklable (large arrays: send a :class:`Packed` or a :class:`SharedBlock`'s path).
    duplex : bool
        The parent sends messages too (:meth:`send`); else the pipe goes one way, up.
    name : str
        What the process is called in messages ("the smoothing stepper process ended ...").

    Raises
    ------
    NoChildProcess
        No child process can start here.

    Notes
    -----
    The messages the child sends up are tuples ``(kind, *payload)``: ``("progress",
    fraction, message)`` and ``("partial", Packed)`` are relayed by :meth:`receive`,
    ``("error", message)`` is raised there, any other kind is returned, each
    :class:`Packed` in its payload unpacked.
    """

    def __init__(
        self, target: Callable[..., Any], *args: Any, duplex: bool = False, name: str = "worker"
    ) -> None:
        self.name = name
        try:
            ctx = context()
            self.conn, there = ctx.Pipe(duplex=duplex)
            environ = dict(os.environ)
            self.process = ctx.Process(
                target=_enter, args=(there, environ, target, args), daemon=True
            )
            try:
                self.process.start()
            finally:
                there.close()
        except NO_CHILD as exc:
            raise NoChildProcess(f"no child process could start: {exc}") from exc

    @property
    def alive(self) -> bool:
        return self.process.is_alive()

    def ended(self) -> MeshError:
        """The error of a child that is gone (its exit code once the fork server has it)."""
        self.process.join(2.0)
        return MeshError(f"the {self.name} process ended (exit code {self.process.exitcode})")

    def ready(self) -> bool:
        """A message waits (or the child has ended): :meth:`receive` will not wait."""
        return self.conn.poll() or not self.process.is_alive()

    def send(self, message: tuple[Any, ...]) -> None:
        """Send a message down (a duplex pipe); a child that is gone raises :meth:`ended`."""
        try:
            self.conn.send(message)
        except (OSError, ValueError):
            raise self.ended() from None

    def receive(self, reporter: Any = None, timeout: float | None = None) -> tuple[Any, ...]:
        """The child's next message other than progress and partial results, which go to
        ``reporter`` (``reporter(fraction, message)``, ``reporter.partial(value)``) meanwhile.

        Raises
        ------
        MeshError
            The child sent an error, ended, or took over ``timeout`` seconds.
        Cancelled
            From ``reporter.check()`` (the caller ends the child: :meth:`end`).
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            if reporter is not None:
                reporter.check()
            if self.conn.poll(POLL_SECONDS):
                try:
                    kind, *payload = self.conn.recv()
                except (EOFError, OSError):
                    raise self.ended() from None
                payload = [unpack(p) if isinstance(p, Packed) else p for p in payload]
                if kind == "progress":
                    if reporter is not None:
                        reporter(*payload)
                elif kind == "partial":
                    if reporter is not None:
                        reporter.partial(payload[0])
                elif kind == "error":
                    raise MeshError(payload[0])
                else:
                    return (kind, *payload)
            elif not self.process.is_alive() and not self.conn.poll():
                raise self.ended()
            elif deadline is not None and time.monotonic() > deadline:
                raise MeshError(f"the {self.name} process took over {timeout:g} s")

    def end(self, goodbye: tuple[Any, ...] | None = None, grace: float = 0.0) -> None:
        """End the child (idempotent): send ``goodbye`` and wait up to ``grace`` seconds for it
        to leave, else kill it; then remove the files it left in shared memory."""
        if goodbye is not None:
            with contextlib.suppress(OSError, ValueError):
                self.conn.send(goodbye)
        with contextlib.suppress(OSError):
            self.conn.close()
        if grace > 0:
            self.process.join(grace)
        if self.process.is_alive():
            self.process.kill()
        self.process.join(5)
        if self.process.pid is not None and not self.process.is_alive():
            remove_stale(shared_folder(), self.process.pid)


def _call_main(conn: Any, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
    """The body of :func:`call`'s child: ``fn(*args, progress=reporter)``, its result (its
    large arrays through :func:`pack`) or its error sent up as one message."""
    try:
        result = fn(*args, progress=ChildReporter(conn))
    except BaseException as exc:  # reported to the parent, never lost
        conn.send(("error", error_message(exc)))
    else:
        conn.send(("result", pack(result)))
    finally:
        conn.close()


def call(
    fn: Callable[..., Any],
    *args: Any,
    reporter: Any = None,
    timeout: float | None = None,
    name: str = "worker",
) -> Any:
    """``fn(*args, progress=...)`` run in a child process; its result here.

    Parameters
    ----------
    fn : callable
        Module level (pickled by name); its arguments and result picklable.
    reporter : optional
        Gets the child's progress reports and partial results; its ``check()`` is called
        every :data:`POLL_SECONDS` (Cancel: it raises, the child is ended).
    timeout : float, optional
        Seconds the child may take, else it is ended.
    name : str
        What the process is called in messages.

    Raises
    ------
    NoChildProcess
        No child process can start here.
    MeshError
        ``fn`` failed (its message: :func:`error_message`), or the child ended or timed out.
    """
    child = Child(_call_main, fn, args, name=name)
    try:
        return child.receive(reporter, timeout)[1]
    finally:
        child.end()
