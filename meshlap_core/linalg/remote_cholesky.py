"""A sparse Cholesky factorization held by a helper process (cholespy), solving through shared
memory: built in the background while the caller keeps working, then answering repeated
solves at cholespy's speed.

Why a process: every sparse Cholesky at hand (CHOLMOD through scikit-sparse, cholespy) holds
the GIL while it factorizes (10–25 s for cholespy at 692k unknowns), so a factorization in a
*thread* would stop the caller's own solves for as long. Why cholespy: with three right-hand
sides its solve is the fastest measured on meshes (0.10–0.12 s of CPU at 692k, against 0.19 s
for scikit-sparse's supernodal CHOLMOD on the system's OpenBLAS, whose level-3 calls on
three columns cost more than they save; ``benchmarks/bench_scan_smoothing.py``), while
CHOLMOD on OpenBLAS factorizes 2–3× faster. So a caller answers its first solves from
CHOLMOD and hands the rest over to this one (:mod:`meshlap_core.smoothing.implicit_solver`).

The helper is ``python -P -m meshlap_core.linalg.remote_cholesky`` (a fresh interpreter
importing numpy and cholespy only; ``-P``: nothing from the working folder). Plain data
crosses the boundary, never a pickle: the matrix's CSR arrays and the right-hand sides live
in two anonymous shared-memory files (``memfd``) passed as file descriptors; commands and
answers are text lines on two pipes::

    matrix file:  [ data f8 (nnz) | scale f8 (n) | indptr i4 (n+1) | indices i4 (nnz) ]
    vector file:  [ c (n,k) | slot 0 (n,k) | slot 1 (n,k) | work (n,k) ]   all f8

    parent -> helper (stdin):   "solve I O ADD"  Z_O = A^-1 (Z_I [+ c if ADD]),  "quit"
    helper -> parent (a pipe):  "ready SECONDS" | "done O SECONDS CPU" | "error MESSAGE"

The helper maps the matrix, scales it (``D A D``, ``D = diag(scale)``, when asked: that work
is the helper's, not the caller's), factorizes, unmaps it (the file's memory goes with its last
mapping) and says ``ready``; each ``solve`` reads one slot and writes the other, so the
parent reads one answer while the next is computed. The parent owns the clock and the
process: :meth:`RemoteCholesky.close` (or garbage collection, or the end of the interpreter)
kills it at once, also in the middle of its factorization; a helper started from the main
thread also dies with its parent (``PR_SET_PDEATHSIG``), and any helper exits when its
command pipe ends.
"""

from __future__ import annotations

import contextlib
import json
import mmap
import os
import select
import subprocess
import sys
import tempfile
import threading
import time
import weakref
from typing import Any

import numpy as np
import scipy.sparse as sp

from .common import FloatArray


class HelperError(RuntimeError):
    """The helper process failed (could not start, refused the matrix, or ended)."""


def _anonymous_file(size: int) -> int:
    """A file descriptor of ``size`` bytes of shared memory that no path names (``memfd``,
    else an unlinked temporary file in ``/dev/shm`` or the temporary folder)."""
    if hasattr(os, "memfd_create"):
        fd = os.memfd_create("meshlap-cholesky", 0)
    else:  # pragma: no cover - not Linux
        folder = "/dev/shm" if os.path.isdir("/dev/shm") else None
        handle, path = tempfile.mkstemp(prefix="meshlap-cholesky-", dir=folder)
        os.unlink(path)
        fd = handle
    try:
        os.ftruncate(fd, max(1, size))
    except OSError:
        os.close(fd)
        raise
    return fd


def _matrix_bytes(n: int, nnz: int) -> int:
    return 8 * (nnz + n) + 4 * (n + 1 + nnz)


def _matrix(buffer: Any, n: int, nnz: int) -> tuple[np.ndarray, ...]:
    """``data``, ``scale``, ``indptr``, ``indices`` in the matrix file (8-byte values first,
    so every array is aligned)."""
    data = np.ndarray(nnz, np.float64, buffer, 0)
    scale = np.ndarray(n, np.float64, buffer, 8 * nnz)
    indptr = np.ndarray(n + 1, np.int32, buffer, 8 * (nnz + n))
    indices = np.ndarray(nnz, np.int32, buffer, 8 * (nnz + n) + 4 * (n + 1))
    return data, scale, indptr, indices


def _layout(n: int, k: int) -> list[tuple[int, tuple[int, int]]]:
    """Offsets and shapes of ``c`` and the slots in the vector file."""
    block = 8 * n * k
    return [(i * block, (n, k)) for i in range(4)]  # c, slot 0, slot 1, work


def _vectors(buffer: Any, n: int, k: int) -> list[np.ndarray]:
    return [np.ndarray(shape, np.float64, buffer, off) for off, shape in _layout(n, k)]


def _end(process: subprocess.Popen, maps: list[Any], fds: list[int]) -> None:
    """Kill the helper and free what the parent holds (idempotent; the finalizer)."""
    if process.poll() is None:
        with contextlib.suppress(OSError):
            process.kill()
    with contextlib.suppress(Exception):
        process.wait(timeout=5)
    for pipe in (process.stdin,):
        if pipe is not None:
            with contextlib.suppress(OSError):
                pipe.close()
    for m in maps:
        with contextlib.suppress(BufferError, ValueError):
            m.close()  # a view still alive keeps it mapped until it goes
    maps.clear()
    for fd in fds:
        with contextlib.suppress(OSError):
            os.close(fd)
    fds.clear()


class RemoteCholesky:
    """cholespy's factorization of the symmetric positive definite ``A`` in a helper process
    (see the module docstring), built from the moment this object is made.

    Parameters
    ----------
    A : (n,n) scipy.sparse matrix
        Symmetric positive definite, both triangles stored (copied into shared memory; the
        caller may drop it).
    columns : int
        ``k``, the number of right-hand sides of every solve.
    shift : (n,k) float, optional
        ``c``: a solve may add it to its right-hand side (``add=True``).
    scale : (n,) float, optional
        Factorize ``D A D`` with ``D = diag(scale)`` instead of ``A`` (scaled by the helper).

    Attributes
    ----------
    factor_s : float or None
        The helper's factorization time (known once :meth:`ready`).
    solve_s : list of float
        The helper's own time of each solve (the latest 64).
    solve_cpu_s : list of float
        The CPU time of each (the latest 64): on a busy machine the wall time above also
        counts the time the helper waited for a core.
    error : str
        Why the helper failed ("" while it has not).
    waited_s : float
        How long the last :meth:`result` waited for its answer.

    Raises
    ------
    HelperError
        The helper process cannot start here.
    """

    def __init__(
        self,
        A: sp.spmatrix,
        columns: int,
        shift: FloatArray | None = None,
        scale: FloatArray | None = None,
    ) -> None:
        A = sp.csr_matrix(A)
        if not A.has_canonical_format:  # (a copy: the caller's matrix is never changed)
            A = A.copy()
            A.sum_duplicates()
        n, nnz, k = A.shape[0], A.nnz, int(columns)
        self.n, self.k = n, k
        self.factor_s: float | None = None
        self.solve_s: list[float] = []
        self.solve_cpu_s: list[float] = []
        self.waited_s = 0.0
        self.error = ""
        self._state = "factorizing"  # -> ready | failed | closed
        self._buffer = b""
        self._pending: int | None = None  # slot the helper is writing
        self._last = 0  # slot of the latest answer (the next input)
        self._maps: list[Any] = []
        self._fds: list[int] = []
        mat_fd = vec_fd = -1
        reply_r = reply_w = -1
        try:
            mat_fd = _anonymous_file(_matrix_bytes(n, nnz))
            with mmap.mmap(mat_fd, 0) as m:
                data, d, indptr, indices = _matrix(m, n, nnz)
                data[:] = A.data
                d[:] = 1.0 if scale is None else scale
                indptr[:] = A.indptr
                indices[:] = A.indices
                del data, d, indptr, indices
            vec_fd = _anonymous_file(32 * n * k)
            vec_map = mmap.mmap(vec_fd, 0)
            self._maps.append(vec_map)
            self._c, *self._slots = _vectors(vec_map, n, k)
            if shift is not None:
                self._c[...] = shift
            reply_r, reply_w = os.pipe()
            header = {
                "n": n,
                "nnz": nnz,
                "k": k,
                "matrix_fd": mat_fd,
                "scaled": scale is not None,
                "vector_fd": vec_fd,
                "reply_fd": reply_w,
                "parent": os.getpid(),
                # PR_SET_PDEATHSIG fires when the *thread* that started the child ends
                "die_with_parent": threading.current_thread() is threading.main_thread(),
            }
            env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
            self.process = subprocess.Popen(
                # -P: the working folder is not put on the path (a folder named like a module
                # there is never imported instead of meshlap's own)
                [sys.executable, "-P", "-m", __name__, json.dumps(header)],
                stdin=subprocess.PIPE,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                pass_fds=(mat_fd, vec_fd, reply_w),
                env=env,
            )
        except (OSError, ValueError) as exc:
            for fd in (mat_fd, vec_fd, reply_r, reply_w):
                if fd >= 0:
                    with contextlib.suppress(OSError):
                        os.close(fd)
            for m in self._maps:
                with contextlib.suppress(BufferError, ValueError):
                    m.close()
            raise HelperError(f"the helper process cannot start: {exc}") from None
        for fd in (mat_fd, vec_fd, reply_w):  # the child holds its own copies
            os.close(fd)
        self._reply = reply_r
        self._fds.append(reply_r)
        self._finalizer = weakref.finalize(self, _end, self.process, self._maps, self._fds)

    # ------------------------------------------------------------------ state
    @property
    def state(self) -> str:
        """``"factorizing"``, ``"ready"``, ``"failed"`` or ``"closed"`` (as last read)."""
        return self._state

    def ready(self) -> bool:
        """Whether the factorization is done (never waits; reads what the helper said)."""
        if self._state == "factorizing":
            self._read(0.0)
        return self._state == "ready"

    def wait_ready(self, timeout: float | None = None) -> bool:
        """Wait until the factorization is done (or failed, or ``timeout`` seconds)."""
        end = None if timeout is None else time.monotonic() + timeout
        while self._state == "factorizing":
            left = None if end is None else end - time.monotonic()
            if left is not None and left <= 0:
                break
            self._read(left)
        return self._state == "ready"

    # ------------------------------------------------------------------ solves
    @property
    def pending(self) -> bool:
        """A solve was submitted and its answer not taken."""
        return self._pending is not None

    def submit(self, z: FloatArray | None = None, add: bool = False) -> None:
        """Start the solve ``A⁻¹ (z [+ c])`` (returns at once; :meth:`result` takes it).

        ``z`` ``(n,k)`` is copied into shared memory; ``None`` solves from the latest
        answer as it is (no copy: an iteration ``z ← A⁻¹(z + c)``).

        Raises
        ------
        HelperError
            The helper is not ready or has failed.
        """
        if not self.ready():
            raise HelperError(self.error or "the helper's factorization is not ready")
        if self._pending is not None:
            self.result()  # (an answer nobody wants: taken first)
        src = self._last
        if z is not None:
            self._slots[src][...] = z
        dst = 1 - src
        self._send(f"solve {src} {dst} {int(bool(add))}\n")
        self._pending = dst

    def result(self) -> FloatArray:
        """The answer of the submitted solve, waiting for it: a read-only view of shared
        memory, valid until the next :meth:`submit` (copy it to keep it).

        Raises
        ------
        HelperError
            Nothing was submitted, or the helper ended or failed.
        """
        if self._pending is None:
            raise HelperError("no solve was submitted")
        t = time.perf_counter()
        while self._pending is not None:
            if self._state in ("failed", "closed"):
                raise HelperError(self.error or "the helper process ended")
            self._read(None)
        self.waited_s = time.perf_counter() - t
        view = self._slots[self._last].view()
        view.flags.writeable = False
        return view

    def discard(self) -> None:
        """Forget a submitted solve (its answer is awaited and dropped)."""
        if self._pending is not None:
            with contextlib.suppress(HelperError):
                self.result()

    def close(self) -> None:
        """Kill the helper (at once, also while it factorizes) and free the shared memory."""
        self._state = "closed"
        self._slots, self._c = [], None  # type: ignore[assignment]
        self._finalizer()

    @property
    def alive(self) -> bool:
        return self._finalizer.alive and self.process.poll() is None

    # ------------------------------------------------------------------ plumbing
    def _send(self, line: str) -> None:
        try:
            assert self.process.stdin is not None
            self.process.stdin.write(line.encode())
            self.process.stdin.flush()
        except (OSError, ValueError):
            self._fail("the helper process ended")
            raise HelperError(self.error) from None

    def _fail(self, message: str) -> None:
        if self._state != "closed":
            self._state = "failed"
        self.error = self.error or message
        self._pending = None

    def _read(self, timeout: float | None) -> None:
        """Read and handle the helper's lines available within ``timeout`` seconds."""
        if self._state in ("failed", "closed"):
            return
        try:
            ready, _, _ = select.select([self._reply], [], [], timeout)
        except (OSError, ValueError):
            ready = [self._reply]
        if not ready:
            return
        try:
            chunk = os.read(self._reply, 65536)
        except OSError:
            chunk = b""
        if not chunk:
            code = self.process.poll()
            self._fail(
                "the helper process ended" + ("" if code is None else f" (exit code {code})")
            )
            return
        self._buffer += chunk
        while b"\n" in self._buffer:
            line, self._buffer = self._buffer.split(b"\n", 1)
            self._handle(line.decode(errors="replace"))

    def _handle(self, line: str) -> None:
        word, _, rest = line.partition(" ")
        if word == "ready":
            self.factor_s = float(rest)
            self._state = "ready"
        elif word == "done":
            slot, seconds, cpu = rest.split()
            self._last, self._pending = int(slot), None
            self.solve_s = [*self.solve_s[-63:], float(seconds)]
            self.solve_cpu_s = [*self.solve_cpu_s[-63:], float(cpu)]
        elif word == "error":
            self._fail(rest)


# ---------------------------------------------------------------------- the helper's side
def _die_with_parent(parent: int) -> None:
    """Ask Linux to kill this process when its parent ends; exit if it already has."""
    import ctypes
    import signal

    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:
        os._exit(0)


def serve(header: dict[str, Any]) -> None:
    """The helper's body (see the module docstring): factorize, then answer solves."""
    reply = os.fdopen(header["reply_fd"], "w", buffering=1)

    def say(line: str) -> None:
        reply.write(line.replace("\n", " ") + "\n")

    if header.get("die_with_parent"):
        _die_with_parent(header["parent"])
    n, nnz, k = header["n"], header["nnz"], header["k"]
    try:
        from cholespy import CholeskySolverD, MatrixType

        t = time.perf_counter()
        with mmap.mmap(header["matrix_fd"], 0) as m:
            data, scale, indptr, indices = _matrix(m, n, nnz)
            if header.get("scaled"):  # D A D: row i times scale_i, column j times scale_j
                data *= np.repeat(scale, np.diff(indptr))
                data *= scale[indices]
            try:
                solver = CholeskySolverD(n, indptr, indices, data, MatrixType.CSR)
            except ValueError:
                say("error cholespy: the matrix is not numerically positive definite")
                return
            del data, scale, indptr, indices
        os.close(header["matrix_fd"])
        say(f"ready {time.perf_counter() - t:.6f}")
        vec_map = mmap.mmap(header["vector_fd"], 0)
        c, *slots, work = _vectors(vec_map, n, k)
        for line in sys.stdin:
            cmd = line.split()
            if not cmd or cmd[0] == "quit":
                break
            src, dst, add = int(cmd[1]), int(cmd[2]), cmd[3] == "1"
            t, cpu = time.perf_counter(), time.thread_time()
            if add:
                np.add(slots[src], c, out=work)
                solver.solve(work, slots[dst])
            else:
                solver.solve(slots[src], slots[dst])
            say(f"done {dst} {time.perf_counter() - t:.6f} {time.thread_time() - cpu:.6f}")
    except Exception as exc:  # reported to the parent, never lost
        say(f"error {type(exc).__name__}: {exc}")


if __name__ == "__main__":
    serve(json.loads(sys.argv[1]))
