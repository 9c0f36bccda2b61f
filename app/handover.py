"""What a job's child process sends to the window: pickled, its large arrays through shared
memory instead of the pipe (no polyscope, no imgui).

A child process (:func:`meshlap_app.jobs.in_child`) sends each partial result and its result
as one message. Pickled whole and sent through the pipe, the 692k-vertex preview (``V``,
``F`` and its field, 53 MB) costs a pickle, a pipe write in 64 kB pieces, a read and an
unpickle: 0.3–0.6 s on a loaded machine before the window can show it. Here the message is
pickled with protocol 5 and its out-of-band buffers (numpy arrays larger than
:data:`SHARED_MIN_BYTES`) are written one after the other into a single file in
``/dev/shm``; the pipe carries the small pickle, the file's path and the buffers' sizes. The
window maps the file (``mmap``), unlinks it at once (the mapping stays valid) and unpickles
the arrays over the mapping, copying nothing.

A file whose message is never opened (its job cancelled, the child ended while sending) is
removed by the next :func:`pack` once its maker process has ended.
"""

from __future__ import annotations

import contextlib
import mmap
import os
import pickle
import tempfile
from dataclasses import dataclass
from typing import Any

SHARED_PREFIX = "meshlap-handover-"
SHARED_MIN_BYTES = 1 << 20
"""Arrays smaller than this travel inside the pickle (a file is not worth it)."""


@dataclass
class Packed:
    """A message pickled for another process.

    Attributes
    ----------
    data : bytes
        The pickle (protocol 5), without the large buffers.
    path : str
        The shared-memory file holding the large buffers one after the other ("" when none).
    sizes : list of int
        The byte size of each buffer in the file, in pickling order.
    """

    data: bytes
    path: str = ""
    sizes: tuple[int, ...] = ()


def shared_folder() -> str:
    """``/dev/shm`` where it exists (memory, not disk), else the temporary folder."""
    return "/dev/shm" if os.path.isdir("/dev/shm") else tempfile.gettempdir()


def pack(value: Any) -> Packed:
    """``value`` pickled, its arrays of at least :data:`SHARED_MIN_BYTES` written to a file in
    shared memory (in the process that sends it)."""
    big: list[pickle.PickleBuffer] = []

    def out_of_band(buf: pickle.PickleBuffer) -> bool:
        if buf.raw().nbytes < SHARED_MIN_BYTES:
            return True  # serialised in band
        big.append(buf)
        return False

    data = pickle.dumps(value, protocol=5, buffer_callback=out_of_band)
    if not big:
        return Packed(data)
    folder = shared_folder()
    remove_stale(folder)
    fd, path = tempfile.mkstemp(prefix=f"{SHARED_PREFIX}{os.getpid()}-", dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            for buf in big:
                f.write(buf.raw())
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(path)
        raise
    return Packed(data, path, tuple(buf.raw().nbytes for buf in big))


def unpack(packed: Packed) -> Any:
    """The value :func:`pack` pickled (in the process that receives it): its large arrays are
    views of the shared-memory file, mapped, then unlinked."""
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


def remove_stale(folder: str, prefix: str = SHARED_PREFIX) -> None:
    """Remove the files ``prefix<pid>-*`` in ``folder`` whose maker process ``pid`` has ended
    (the handover files by default; the eigenvectors' files of ``state.spectral`` too)."""
    with contextlib.suppress(OSError):
        for name in os.listdir(folder):
            if not name.startswith(prefix):
                continue
            try:
                pid = int(name[len(prefix) :].split("-", 1)[0])
                os.kill(pid, 0)
            except ProcessLookupError:
                with contextlib.suppress(OSError):
                    os.unlink(os.path.join(folder, name))
            except (ValueError, OSError):
                continue
