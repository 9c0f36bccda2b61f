"""A smoothing stepper in a persistent child process (issue 21): the window keeps drawing while
the implicit system is factorized and while each step is solved.

CHOLMOD (scikit-sparse), cholespy and libigl hold the GIL while they factorize ``W − λK``
(4–10 s at 692k vertices), so a worker *thread* froze the window for as long. Here the
stepper (:class:`meshlap_core.smoothing.Smoother`, built by
:meth:`~.state.smoothing.SmoothingState.build`: noise, operators, factorization, stable λ)
lives in a child process (:class:`meshlap_app.ipc.Child`, from the one fork server), and stays
there: the factor never crosses a process boundary. The window holds a
:class:`RemoteSmoother`, a proxy with the stepper's interface (``V``, ``V0``, ``iteration``,
``history``, ``stability``, ``step``, ``reset``, ``set_lam`` ...) whose commands travel
through a pipe and whose positions come back through one :class:`meshlap_app.ipc.SharedBlock`
(its file is unlinked once both processes have mapped it)::

    [ V0, the noisy input (n,3) float64 | slot 0 | slot 1 ]
    slot: [ V current (n,3) float64 | normals (n,3) float32 | display P, N (2,n,3) float32 ]

(the mesh itself reaches the child as a :func:`meshlap_app.ipc.pack` message, mapped once at
its start).
*play* may ask for several steps at once (:meth:`RemoteSmoother.request_step` with a count),
and keeps up to :data:`PIPELINE` requests on their way: the child starts the next batch as
soon as it has answered one, while the window uploads and draws. Answer ``k`` goes to slot
``k % PIPELINE`` and the window copies it out when it reads the answer, before it sends the
request that would reuse the slot. With the window's display transform (sent with each
request) the child also writes the positions and normals as polyscope takes them
(:func:`display_arrays`): a play frame's upload is two buffer copies.

Besides the synchronous calls (a session replayed in the window, one request per run of steps:
:meth:`RemoteSmoother.steps`; ``meshlap animate`` steps in its own process, offline), a step
can be asked for and collected later (:meth:`RemoteSmoother.request_step`,
:meth:`RemoteSmoother.poll`): the window asks, keeps drawing, and uploads the positions when
they arrive. The child also computes the vertex normals polyscope's smooth shading uses
(:func:`vertex_normals`, the same area-weighted sum as polyscope's
``SurfaceMesh::computeVertexNormals``), so the window updates two vertex buffers instead of
re-deriving the whole geometry on its own thread.

Cancel: :meth:`RemoteSmoother.start` ends the child at once; a proxy that is closed or
garbage-collected ends its child and frees the block. Where no child process can start,
:func:`build` builds the stepper in the calling thread instead (the pure in-process path).
"""

from __future__ import annotations

import weakref
from collections import deque
from typing import Any

import numpy as np
import scipy.sparse as sp

from meshlap_core.errors import MeshError
from meshlap_core.smoothing import check_lam
from meshlap_core.types import FloatArray, IntArray

from .ipc import (
    Child,
    ChildReporter,
    NoChildProcess,
    Packed,
    SharedBlock,
    discard,
    error_message,
    pack,
    unpack,
)
from .jobs import Reporter
from .state.kept_steps import KeptSteps


def vertex_normals(V: FloatArray, F: IntArray, incidence: Any = None) -> np.ndarray:
    """Unit vertex normals as polyscope's smooth shading computes them: the sum of the faces'
    cross products ``(b − a) × (c − a)`` (unit normal times twice the area) around each vertex,
    normalized (``SurfaceMesh::computeVertexNormals``).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    incidence : (n,m) sparse, optional
        :func:`face_incidence` of ``F`` (the sum is then one sparse product: 0.05 s instead of
        1 s of ``bincount`` at 692k vertices); made here when not given.

    Returns
    -------
    N : (n,3) float32
        Zero where no face of non-zero area touches the vertex.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if incidence is None:
        incidence = face_incidence(F, len(V))
    if len(F):
        N = np.asarray(incidence @ _face_cross(V, F))
    else:
        N = np.zeros((len(V), 3))
    norm = np.sqrt(np.einsum("ij,ij->i", N, N))
    ok = norm > 0
    N[ok] /= norm[ok, None]
    return N.astype(np.float32)


NORMALS_CHUNK = 8192
"""Faces per block of :func:`_face_cross` (its gathered coordinates stay in the cache: 130
instead of 200 ms of CPU for the normals of the 692k scan, made for every step shown)."""


def _face_cross(V: FloatArray, F: IntArray) -> np.ndarray:
    """``(b − a) × (c − a)`` of every face ``(m,3)``, coordinate by coordinate on contiguous
    arrays (3× quicker than ``np.cross``), over blocks of :data:`NORMALS_CHUNK` faces."""
    x, y, z = np.ascontiguousarray(V.T)
    FT = np.ascontiguousarray(F.T)
    cross = np.empty((len(F), 3))
    for s in range(0, len(F), NORMALS_CHUNK):
        i, j, k = FT[:, s : s + NORMALS_CHUNK]
        xi, yi, zi = x.take(i), y.take(i), z.take(i)
        ux, uy, uz = x.take(j) - xi, y.take(j) - yi, z.take(j) - zi
        vx, vy, vz = x.take(k) - xi, y.take(k) - yi, z.take(k) - zi
        c = cross[s : s + NORMALS_CHUNK]
        c[:, 0] = uy * vz - uz * vy
        c[:, 1] = uz * vx - ux * vz
        c[:, 2] = ux * vy - uy * vx
    return cross


def face_incidence(F: IntArray, n: int) -> sp.csr_matrix:
    """The ``(n,m)`` vertex–face incidence matrix (1 where vertex ``i`` is a corner of face
    ``f``), CSR from COO: ``incidence @ X`` sums a per-face ``X`` around each vertex."""
    F = np.asarray(F, dtype=np.int64)
    m = len(F)
    rows = F.ravel()
    cols = np.repeat(np.arange(m), 3)
    return sp.coo_matrix((np.ones(3 * m), (rows, cols)), shape=(n, m)).tocsr()


PIPELINE = 2
"""Most step requests on their way at once: the child starts the next batch as soon as it has
answered one, while the window uploads and draws (each answer has its own slot of the shared
block, so the child never writes the slot the window is reading)."""

Slot = tuple[np.ndarray, np.ndarray, np.ndarray]


def _blocks(block: SharedBlock, n: int, depth: int) -> tuple[np.ndarray, list[Slot]]:
    """The arrays of the shared block (see the module docstring): ``V0``, then
    ``depth`` (:data:`PIPELINE`) slots of (current positions, normals, display positions and
    normals ``(2,n,3) float32``); answer ``k`` is written into slot ``k % depth``."""
    start = block.array((n, 3), np.float64)
    slots: list[Slot] = []
    offset = 24 * n
    for _ in range(depth):
        cur = block.array((n, 3), np.float64, offset)
        normals = block.array((n, 3), np.float32, offset + 24 * n)
        shown = block.array((2, n, 3), np.float32, offset + 36 * n)
        slots.append((cur, normals, shown))
        offset += 60 * n
    return start, slots


def _block_bytes(n: int, depth: int) -> int:
    return max(1, (24 + 60 * depth) * n)


def display_arrays(
    V: FloatArray, N: np.ndarray | None, view: tuple[float, ...], out: np.ndarray
) -> None:
    """The positions ``V (n,3)`` as the window shows them, ``((V − c) s) Rᵀ + shift``, and
    their normals turned, ``N Rᵀ``, into ``out (2,n,3) float32`` (the child's part of an
    upload: the window passes them to polyscope as they are).

    ``view`` is ``(c (3), s, R (9, row-major), shift (3))`` flattened (:meth:`RemoteSmoother.
    request_step`)."""
    c, s = np.asarray(view[:3]), view[3]
    R = np.asarray(view[4:13]).reshape(3, 3)
    shift = np.asarray(view[13:16])
    perm = np.argmax(np.abs(R), axis=1)
    sign = R[np.arange(3), perm]
    if np.count_nonzero(R) != 3 or not np.all(np.abs(sign) == 1.0):  # (never made by the window)
        np.matmul((V - c) * s, R.T, out=out[0], casting="same_kind")
        out[0] += shift.astype(np.float32)
        if N is not None:
            np.matmul(N, R.T.astype(np.float32), out=out[1])
        return
    # the window's rotations are signed permutations of the axes: a column gather and a sign,
    # no matrix product (whose BLAS threads spin a core after each call: 120 instead of 80 ms
    # of the child's CPU per step shown at 692k)
    for i, (p, g) in enumerate(zip(perm, sign, strict=True)):
        col = V[:, p] - c[p]
        col *= s * g
        col += shift[i]
        out[0][:, i] = col
        if N is not None:
            out[1][:, i] = N[:, p] if g > 0 else -N[:, p]


def _snapshot(sm: Any, kept: KeptSteps | None = None) -> dict[str, Any]:
    """What the proxy mirrors of the stepper after each command (small: no per-vertex data);
    ``kept``: the steps the child keeps for stepping back (how many, from which iteration)."""
    return {
        "kept": kept.capacity if kept is not None else 0,
        "kept_from": kept.oldest if kept is not None else 0,
        "iteration": sm.iteration,
        "lam": sm.lam,
        "taubin_nu": sm.taubin_nu,
        "k_pb": sm.k_pb,
        "diverged": sm.diverged,
        "last": dict(sm.history[-1]) if sm.history else {},
        "stability": sm.stability,
        "divergence": sm.divergence_message() if sm.diverged else None,
        "n_factorizations": sm.n_factorizations,
        "volume_note": sm.volume_note,
        "closed": sm.closed,
        "box": [sm.V.min(axis=0).tolist(), sm.V.max(axis=0).tolist()] if len(sm.V) else None,
        "solver": sm.solver_report(),
        "solver_line": sm.solver_line(),
    }


def _serve(
    conn: Any,
    path: str,
    inputs: Packed,
    options: tuple[str, str, float, float, int],
    normals: bool,
    depth: int = PIPELINE,
) -> None:
    """Body of the child: build the stepper (reporting each phase), then answer commands
    (``step`` with a count, ``rewind`` to an iteration, ``reset``, ``set_lam``, ``diverge``,
    ``close``) until ``close`` or the pipe ends; after each one the positions (and normals)
    are in the shared block (the file ``path``) and a snapshot is sent. The positions of the
    last steps are kept (:class:`~.state.kept_steps.KeptSteps`) for ``rewind``; a command
    other than a step that arrives during a batch of steps ends the batch (a pause is not
    kept waiting by steps nobody will see). ``inputs``: ``(V, F)`` packed by the parent."""
    from .state.smoothing import SmoothingState

    V, F = unpack(inputs)
    block = SharedBlock.attach(path)
    start, slots = _blocks(block, len(V), depth)
    view: tuple[float, ...] | None = None  # the window's display transform, once sent
    answers = 0  # answers published: the next goes to slot answers % depth
    kept = KeptSteps(len(V))
    try:
        sm = SmoothingState.build(V, F, options, ChildReporter(conn))
        start[...] = sm.V0
        incidence = face_incidence(sm.F, len(V)) if normals else None

        def publish() -> dict[str, Any]:
            nonlocal answers
            slot = answers % depth
            cur, nrm, shown = slots[slot]
            snap = _publish(sm, cur, nrm, incidence, kept)
            if view is not None:
                display_arrays(sm.V, nrm if normals else None, view, shown)
            snap["view"], snap["slot"] = view, slot
            answers += 1
            return snap

        reply: tuple[Any, ...] = ("ready", publish())
        held: tuple[Any, ...] | None = None  # a command read during a batch of steps
        while True:
            conn.send(reply)
            try:
                cmd, *args = held if held is not None else conn.recv()
            except (EOFError, OSError):
                return
            held = None
            if cmd == "close":
                return
            try:
                if cmd == "step":  # args: how many (stops at a divergence), the view
                    held = _steps(sm, kept, args[0] if args else 1, conn)
                    view = args[1] if len(args) > 1 and args[1] is not None else view
                elif cmd == "rewind":
                    kept.rewind(sm, args[0])
                elif cmd == "reset":
                    sm.reset()
                    kept.clear()
                elif cmd == "set_lam":
                    sm.set_lam(args[0])
                elif cmd == "diverge":
                    sm.diverged = True
                reply = ("state", publish())
            except MeshError as exc:
                reply = ("error", str(exc))
    except BaseException as exc:  # reported to the parent, never lost
        _send(conn, ("error", error_message(exc)))
    finally:
        slots.clear()  # (no view of the block may outlive it)
        del start
        block.close()
        conn.close()


def _steps(sm: Any, kept: KeptSteps, count: int, conn: Any) -> tuple[Any, ...] | None:
    """Up to ``count`` steps (stopping at a divergence), each kept; between two steps a
    command that arrived is read: another step request waits its turn, anything else ends
    the batch. Returns the command read, if any (``("close",)`` when the pipe ended)."""
    held: tuple[Any, ...] | None = None
    n = max(1, int(count))
    try:
        for i in range(n):
            if sm.diverged:
                break
            if i and held is None and conn.poll():
                try:
                    held = tuple(conn.recv())
                except (EOFError, OSError):
                    return ("close",)
                if held[0] != "step":
                    break
            # the window shows the batch's last step's figures only: an implicit step (which
            # cannot diverge) is measured only when it may be the last (the count's end, or a
            # command waiting that ends the batch after it)
            last = i == n - 1 or (held is None and conn.poll())
            sm.track_history = sm.method != "implicit" or last
            sm.step()
            if not sm.diverged:
                kept.record(sm.iteration, sm.V)
    finally:
        sm.track_history = True
    return held


def _send(conn: Any, message: tuple[Any, ...]) -> None:
    try:
        conn.send(message)
    except (OSError, ValueError):  # the parent is gone
        pass


def _publish(
    sm: Any, cur: np.ndarray, nrm: np.ndarray, incidence: Any, kept: KeptSteps | None = None
) -> dict[str, Any]:
    """Write the stepper's positions (and, given the face ``incidence``, its normals) into
    the shared block; its snapshot."""
    cur[...] = sm.V
    if incidence is not None:
        nrm[...] = vertex_normals(sm.V, sm.F, incidence)
    return _snapshot(sm, kept)


def _shutdown(child: Child, block: SharedBlock) -> None:
    """End the child and free the block (idempotent; the proxy's finalizer)."""
    child.end(goodbye=("close",), grace=0.5)
    block.close()  # views still alive (a collected proxy): unmapped when they go
    block.unlink()


class RemoteSmoother:
    """A :class:`~meshlap_core.smoothing.Smoother` living in a child process (see the module
    docstring); made by :meth:`start`.

    Attributes mirror the stepper's after each command: ``iteration``, ``lam``, ``taubin_nu``,
    ``k_pb``, ``diverged``, ``stability``, ``history`` (the latest entry only, as the window's
    stepper keeps a bounded history), ``n_factorizations``, ``volume_note``, ``closed``;
    ``V`` (current positions), ``V0`` (the noisy input), ``F`` and ``reference`` (the clean
    mesh) are this process's arrays; ``normals`` the current vertex normals ``(n,3) float32``
    (``None`` unless asked for).
    """

    asynchronous = True

    def __init__(
        self,
        child: Child,
        block: SharedBlock,
        V: FloatArray,
        F: IntArray,
        options: tuple[str, str, float, float, int],
        normals: bool,
        depth: int = PIPELINE,
    ) -> None:
        self._child = child
        self._finalizer = weakref.finalize(self, _shutdown, child, block)
        self.method, self.laplacian = options[0], options[1]
        self.n = len(V)
        self.F = F
        self.reference = V
        self.depth = depth  # requests on their way at most (the child's slots)
        self._start, self._slots = _blocks(block, self.n, depth)
        self._view: tuple[float, ...] | None = None  # the view of the display arrays held
        self._display: np.ndarray | None = None  # (2,n,3) float32 copied with each step
        self._want_normals = normals
        self._V = np.zeros((self.n, 3))
        self.V0 = self._V
        self.normals: np.ndarray | None = None
        self.box: np.ndarray | None = None  # (2,3) min and max of V (the child's)
        self._queue: deque[str] = deque()  # requests on their way ("step", "rewind"), in order
        self._arrived = False  # a step's answer read, not yet collected by poll
        self.kept = 0  # steps the child keeps for stepping back, and from which iteration
        self.kept_from = 0
        self.error = ""
        self.history: list[dict[str, Any]] = []
        self._solver: dict[str, Any] = {}
        self._solver_line = ""

    # ------------------------------------------------------------------ start
    @classmethod
    def start(
        cls,
        V: FloatArray,
        F: IntArray,
        options: tuple[str, str, float, float, int],
        reporter: Reporter,
        normals: bool = True,
    ) -> RemoteSmoother:
        """Start the child and wait (checking Cancel) until it has built the stepper.

        Raises
        ------
        MeshError
            The build failed (the child's message) or the child ended.
        Cancelled
            From ``reporter`` (the child is ended).
        NoChildProcess
            No child process can start here (:func:`build` falls back).
        """
        V = np.asarray(V, dtype=np.float64)
        F = np.asarray(F, dtype=np.int64)
        depth = PIPELINE
        block = SharedBlock.create(_block_bytes(len(V), depth))
        inputs = pack((V, F))  # (pickling 50 MB to the fork server held the GIL for a second)
        try:
            work = (block.path, inputs, options, normals, depth)
            child = Child(_serve, *work, duplex=True, name="smoothing stepper")
        except BaseException:
            block.close()
            block.unlink()
            discard(inputs)
            raise
        proxy = cls(child, block, V, F, options, normals, depth)
        try:
            proxy._wait(reporter)
        except BaseException:
            proxy.close()
            raise
        finally:
            discard(inputs)  # mapped by the child as it started
            block.unlink()  # mapped by both: the memory stays, the file goes
        proxy.V0 = np.array(proxy._start)
        proxy.V0.flags.writeable = False
        return proxy

    def _wait(self, reporter: Reporter | None = None) -> dict[str, Any]:
        """The child's next answer (progress lines go to ``reporter``); adopts a snapshot."""
        _kind, snap = self._child.receive(reporter)
        self._adopt(snap)
        return snap

    @property
    def process(self) -> Any:
        """The child process (``multiprocessing.Process``)."""
        return self._child.process

    def _adopt(self, snap: dict[str, Any]) -> None:
        """Mirror a snapshot and copy the positions (and normals) out of the shared block."""
        keys = ("iteration", "lam", "taubin_nu", "k_pb", "stability", "n_factorizations")
        for key in (*keys, "kept", "kept_from"):
            setattr(self, key, snap[key])
        self._diverged = snap["diverged"]
        self._divergence = snap["divergence"]
        self.volume_note, self.closed = snap["volume_note"], snap["closed"]
        self.history = [snap["last"]] if snap["last"] else []
        self._solver, self._solver_line = snap["solver"], snap["solver_line"]
        self.box = None if snap["box"] is None else np.array(snap["box"])
        cur, nrm, shown = self._slots[snap["slot"]]
        self._V = np.array(cur)
        if self._want_normals:
            self.normals = np.array(nrm)
        self._view = snap["view"]
        self._display = None if self._view is None else np.array(shown)

    def display(self, view: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray] | None:
        """The current positions and normals ``(n,3) float32`` in the window's coordinates
        made by the child for ``view`` (see :func:`display_arrays`), or ``None`` when it made
        none for this view yet (the next step asked for with ``view`` brings them)."""
        if self._display is None or self._view != view:
            return None
        return self._display[0], self._display[1]

    # ------------------------------------------------------------------ the stepper's interface
    @property
    def V(self) -> FloatArray:
        """Current positions ``(n,3)`` (a read-only view)."""
        view = self._V.view()
        view.flags.writeable = False
        return view

    @property
    def diverged(self) -> bool:
        return self._diverged

    @diverged.setter
    def diverged(self, value: bool) -> None:
        if value and not self._diverged:
            self._call("diverge")

    def divergence_message(self) -> str | None:
        return self._divergence if self._diverged else None

    def solver_report(self) -> dict[str, Any]:
        """The child's stepper's :meth:`~meshlap_core.smoothing.Smoother.solver_report` (as of
        its last answer)."""
        return self._solver

    def solver_line(self) -> str:
        """The child's stepper's solver line (as of its last answer)."""
        return self._solver_line

    def prepare(self) -> None:
        """Nothing: the child factorized while it built the stepper."""

    def step(self) -> FloatArray:
        """One step, waiting for it (see :meth:`request_step` for the window's way)."""
        self._call("step")
        return self.V

    def steps(self, count: int) -> FloatArray:
        """``count`` steps in one request, waiting for them (a session's replay); the child
        stops at a divergence."""
        self._call("step", max(1, int(count)))
        return self.V

    def reset(self) -> None:
        self._call("reset")

    def set_lam(self, lam: float) -> None:
        """Change ``λ`` (checked here first: a bad one raises and changes nothing)."""
        self._call("set_lam", check_lam(lam))

    def _call(self, *command: Any) -> None:
        self._drain()
        self._child.send(command)
        self._wait()

    # ------------------------------------------------------------------ asynchronous steps
    @property
    def pending(self) -> bool:
        """A step (or a rewind) was asked for and its answer has not been read."""
        return bool(self._queue)

    def request_step(self, count: int = 1, view: tuple[float, ...] | None = None) -> bool:
        """Ask for ``count`` steps (shown together) and return at once (False: already
        :data:`PIPELINE` requests on their way: the child has work queued). ``view``: the
        window's display transform (:func:`display_arrays`): the child then also writes the
        positions and normals as the window uploads them."""
        if len(self._queue) >= self.depth:
            return False
        self._child.send(("step", max(1, int(count)), view))
        self._queue.append("step")
        return True

    def request_rewind(self, iteration: int) -> None:
        """Ask the child to go back to the positions of ``iteration`` (kept there, see
        :class:`~.state.kept_steps.KeptSteps`) and return at once: *pause* (the iteration on
        screen) and *step back*. The answers of the requests sent before it are thrown away
        unread when they arrive: the steps the child ran ahead are never shown. Always sent,
        also with :data:`PIPELINE` requests on their way (the slot its answer overwrites
        belongs to one of those, which is never read)."""
        self._child.send(("rewind", int(iteration)))
        self._queue.append("rewind")

    def poll(self) -> bool:
        """Read the answers of the requests that are there (never waits). True when a step's
        (or a rewind's) answer arrived since the last poll (read here or by a synchronous
        call).

        Raises
        ------
        MeshError
            The step failed (e.g. ``W − λK`` could not be factorized), the rewind found no
            kept positions, or the child ended.
        """
        while self._queue and self._child.ready():
            self._read_next()
        arrived, self._arrived = self._arrived, False
        return arrived

    def _read_next(self) -> None:
        """Read the oldest answer on its way: adopt it, or throw it away when a rewind was
        asked for after it (its positions would never be the ones shown)."""
        self._queue.popleft()
        if "rewind" in self._queue:
            try:
                self._child.receive(None)
            except MeshError:
                pass  # a step that failed, superseded by the rewind anyway
            return
        self._wait()
        self._arrived = True

    def finish(self) -> None:
        """Wait for the steps on their way (:meth:`poll` then reports them)."""
        self._drain()

    def _drain(self) -> None:
        """Wait for the requests on their way (a synchronous call comes after them)."""
        while self._queue:
            self._read_next()

    def close(self) -> None:
        """End the child and free the shared block (the proxy is unusable afterwards)."""
        self._V = np.array(self._V)  # own copies: the block goes away
        self._start, self._slots = None, []  # type: ignore[assignment]
        self._finalizer()

    @property
    def alive(self) -> bool:
        return self._finalizer.alive and self._child.alive


def build(
    V: FloatArray,
    F: IntArray,
    options: tuple[str, str, float, float, int],
    reporter: Reporter,
    in_process: Any,
) -> Any:
    """A job's ``work``: the stepper in a child process (:meth:`RemoteSmoother.start`), or
    ``in_process(V, F, options, reporter)`` where no child process can start."""
    try:
        return RemoteSmoother.start(V, F, options, reporter)
    except NoChildProcess:
        return in_process(V, F, options, reporter)
