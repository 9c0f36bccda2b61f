"""The grading harness: the one program that runs beside a student's file.

A standalone script: the standard library and numpy (scipy.sparse to rebuild a sparse input or
carry a sparse answer), never meshlap — the checker mounts this file alone into the sandbox
(:mod:`.isolation`), so no reference, no checker state and no meshlap module is in the student's
process to be reached through ``sys.modules`` or ``gc``. It is run as
``python -I -B harness.py CONFIG`` (``CONFIG`` a JSON object, :func:`main`), as the sandbox's
user, with its standard output and error (the student's prints) going to the checker's capped
log, never to the checker's own output.

What it does, in order: set the limits the checker chose (soft = hard, so the student cannot
raise them: CPU seconds, file size, processes, open files, no core dumps; after numpy is
imported, the address space: its own size plus the student's budget); refuse meshlap to the
import system; arm the :class:`Fence`; say ``ready``; then obey the checker's commands, one
JSON line each on the ``commands`` descriptor, answering one JSON line each on ``replies``:

=====================================  ========================================================
command                                reply
=====================================  ========================================================
``{"op": "import"}``                   ``{"ev": "imported", "functions": [...]}`` or
                                       ``{"ev": "import_error", "kind", "key", "text"}``
``{"op": "call", "id", "func",         ``{"ev": "answer", "id", "tag", "hot"}`` (the answer's
"kind", "inputs", "args", "profile"}`` arrays in ``outputs/<id>.npz``) or ``{"ev": "raised",
                                       "id", "kind", "key", "text"}``
``{"op": "quit"}``                     (exits)
=====================================  ========================================================

Every command carries a fresh nonce that its reply repeats: a line the student's code writes on
the channel cannot answer a command it has not seen. The checker trusts none of it: it owns the
clock (wall time between command and reply, CPU time from ``/proc``), it reads an answer as
plain arrays only (no pickle, dtype and size checked), and a task without an answer has failed.
The :class:`Fence` (audit hooks, PEP 578) names what the student tried — a window, a process,
a file outside the folder, the network, C calls through ctypes — for the report; the sandbox's
walls are the namespaces and limits around this process, not the fence.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import os
import resource
import signal
import sys
import threading
import traceback
from typing import Any

FORBIDDEN = ("meshlap_core", "meshlap_app", "meshlap")
"""Top-level package names a student's file may not import."""
WHY = (
    "an exercise file may not import meshlap ({name!r}): the checker compares your answer "
    "with meshlap's own, so calling meshlap would check nothing. Use numpy, scipy (and libigl)."
)
STUDENT_MODULE = "student_exercises"
"""The module name the student's file is imported as."""
WINDOW_MODULES = (
    "polyscope",
    "tkinter",
    "_tkinter",
    "turtle",
    "PyQt5",
    "PyQt6",
    "PySide2",
    "PySide6",
    "pyglet",
    "glfw",
    "vedo",
    "pyvista",
    "open3d",
    "meshplot",
    "OpenGL",
    "wx",
    "kivy",
)
"""Top-level packages that open windows (the checker runs headless, unattended)."""
WINDOW_LIBRARIES = ("libx11", "libxcb", "libgl", "libegl", "libglfw", "libwayland", "libvulkan")
PROCESS_EVENTS = (
    "subprocess.Popen",
    "os.system",
    "os.fork",
    "os.forkpty",
    "os.exec",
    "os.posix_spawn",
    "os.spawn",
    "os.startfile",
    "pty.spawn",
)
"""Audit events that start a process."""
NETWORK_EVENTS = (
    "socket.connect",
    "socket.bind",
    "socket.sendto",
    "socket.sendmsg",
    "socket.getaddrinfo",
    "socket.gethostbyname",
)
PATH_EVENTS = {  # event -> positions of its path arguments (and of dir_fd, or None)
    "os.mkdir": ((0,), 2),
    "os.rmdir": ((0,), 1),
    "os.remove": ((0,), 1),
    "os.rename": ((0, 1), 2),
    "os.symlink": ((0, 1), 2),
    "os.link": ((0, 1), 2),
    "os.truncate": ((0,), None),
    "os.chmod": ((0,), 2),
    "os.chown": ((0,), 3),
    "os.utime": ((0,), 3),
    "os.listdir": ((0,), None),
    "os.scandir": ((0,), None),
    "os.mkfifo": ((0,), 2),
    "os.mknod": ((0,), 3),
    "sqlite3.connect": ((0,), None),
    "shutil.rmtree": ((0,), None),
}
READ_ONLY_EVENTS = ("os.listdir", "os.scandir")
KINDS = ("matrix", "array", "ring", "eigen")
LIMITS = {
    "cpu": "RLIMIT_CPU",
    "fsize": "RLIMIT_FSIZE",
    "nproc": "RLIMIT_NPROC",
    "nofile": "RLIMIT_NOFILE",
    "core": "RLIMIT_CORE",
}
TEXT_CAP = 16000
"""Characters of a traceback sent back (the checker caps a reply line too)."""
SAMPLE_SECONDS = 0.003
"""The profiler's interval on a timed call: where the student's time goes, by line."""


class Refused(PermissionError):
    """The fence stopped the student (``key``: the diagnosis, ``what``: what was tried)."""

    def __init__(self, key: str, what: str) -> None:
        super().__init__(f"the checker's sandbox refused this: {what} ({key})")
        self.key = key
        self.what = what


class _NoMeshlap:
    """A meta path finder, first in line: meshlap does not import in the student's process."""

    def __init__(self) -> None:
        self.asked: str | None = None

    def find_spec(self, name: str, path: Any = None, target: Any = None) -> None:
        if name.split(".")[0] in FORBIDDEN:
            self.asked = self.asked or name
            raise ImportError(WHY.format(name=name), name=name)


def _forget_meshlap() -> _NoMeshlap:
    """Take meshlap off ``sys.path`` and the import system (an editable install's finder),
    and refuse it to any later import."""
    sys.path[:] = [
        p
        for p in sys.path
        if not any(os.path.isdir(os.path.join(p or ".", pkg)) for pkg in FORBIDDEN)
    ]
    sys.meta_path[:] = [f for f in sys.meta_path if "meshlap" not in type(f).__module__]
    for name in [m for m in sys.modules if "meshlap" in m]:
        del sys.modules[name]
    finder = _NoMeshlap()
    sys.meta_path.insert(0, finder)
    return finder


def _under(path: str, roots: tuple[str, ...]) -> bool:
    return any(path == r or path.startswith(r.rstrip(os.sep) + os.sep) for r in roots)


def _library_roots() -> tuple[str, ...]:
    """Where Python, numpy, scipy and libigl read their own files (lazy imports, data)."""
    import site

    roots = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix, "/usr"}
    with_site = [*site.getsitepackages(), site.getusersitepackages()]
    roots.update(p for p in with_site if isinstance(p, str))
    return tuple(sorted(os.path.realpath(r) for r in roots if r))


class Fence:
    """Names what the student's code tries beyond computing: opening a window, starting or
    signalling a process, reading or writing outside its folder, the network, C functions
    called through ctypes. Armed from the student's import on, in every thread but the
    harness's own work (:meth:`quiet`); the first attempt is remembered even when the student
    catches the exception (:meth:`take`)."""

    def __init__(self, folder: str) -> None:
        self.folder = os.path.realpath(folder)
        self.roots = _library_roots()
        self.devices = ("/dev/null", "/dev/urandom", "/dev/random", "/dev/zero")
        self.armed = False
        self.hush = 0
        self.main = threading.get_ident()
        self.refused: Refused | None = None
        self.ctypes_dir = ""

    def install(self) -> None:
        import ctypes

        self.ctypes_dir = os.path.dirname(os.path.realpath(ctypes.__file__))
        sys.addaudithook(self._hook)
        try:
            import _posixsubprocess
        except ImportError:  # not POSIX
            return
        real = _posixsubprocess.fork_exec

        def fork_exec(*args: Any, **kwargs: Any) -> Any:  # not audited by CPython
            if self._watching():
                self._stop("spawns_process", "a child process")
            return real(*args, **kwargs)

        _posixsubprocess.fork_exec = fork_exec
        import multiprocessing.context
        import multiprocessing.process

        for owner, name in ((multiprocessing.process.BaseProcess, "start"),
                            (multiprocessing.context.BaseContext, "Pool")):  # fmt: skip
            setattr(owner, name, self._refusing(getattr(owner, name), f"multiprocessing {name}"))

    def _refusing(self, real: Any, what: str) -> Any:
        """``real`` refused while the student's code runs (a pool or process of
        ``multiprocessing``: stopped at once, before it makes its locks or children)."""

        def wrapper(*args: Any, **kwargs: Any) -> Any:
            if self._watching():
                self._stop("spawns_process", what)
            return real(*args, **kwargs)

        return wrapper

    def quiet(self) -> _Quiet:
        """``with fence.quiet():`` around the harness's own work on the main thread."""
        return _Quiet(self)

    def take(self) -> Refused | None:
        """The first refused attempt since the last ``take`` (and forget it)."""
        refused, self.refused = self.refused, None
        return refused

    def _watching(self) -> bool:
        return self.armed and not (self.hush and threading.get_ident() == self.main)

    def _stop(self, key: str, what: str) -> None:
        exc = Refused(key, what)
        if self.refused is None:
            self.refused = exc
        raise exc

    def _hook(self, event: str, args: tuple[Any, ...]) -> None:
        if not self._watching():
            return
        if event.startswith(PROCESS_EVENTS):
            self._stop("spawns_process", event)
        elif event in ("os.kill", "os.killpg") and args and args[0] != os.getpid():
            self._stop("signals_process", f"{event}({args[0]})")
        elif event in NETWORK_EVENTS:
            self._stop("uses_network", event)
        elif event == "import" and args and str(args[0]).split(".")[0] in WINDOW_MODULES:
            self._stop("opens_window", f"import {args[0]}")
        elif event.startswith("ctypes."):
            self._check_ctypes(event, args)
        elif event == "open" and args and isinstance(args[0], (str, bytes, os.PathLike)):
            mode = args[1] if len(args) > 1 and isinstance(args[1], str) else "r"
            flags = args[2] if len(args) > 2 and isinstance(args[2], int) else 0
            writes = any(c in mode for c in "wax+") or bool(flags & (os.O_WRONLY | os.O_RDWR))
            self._check_path(args[0], writes, "opens")
        elif event in PATH_EVENTS:
            where, fd_at = PATH_EVENTS[event]
            dir_fd = args[fd_at] if fd_at is not None and len(args) > fd_at else None
            for k in where:
                if len(args) > k and isinstance(args[k], (str, bytes, os.PathLike)):
                    path = self._at(args[k], dir_fd)
                    self._check_path(path, event not in READ_ONLY_EVENTS, event)

    def _check_ctypes(self, event: str, args: tuple[Any, ...]) -> None:
        """A C call, load or raw memory access made by the student's own code (the nearest
        frame outside ctypes is in the student's folder); numpy's and scipy's own are theirs."""
        frame = sys._getframe(2)
        while frame is not None and os.path.realpath(frame.f_code.co_filename).startswith(
            self.ctypes_dir
        ):
            frame = frame.f_back
        if frame is None or not _under(os.path.realpath(frame.f_code.co_filename), (self.folder,)):
            return
        if event == "ctypes.dlopen" and args and args[0]:
            name = os.path.basename(str(args[0])).lower()
            if name.startswith(WINDOW_LIBRARIES):
                self._stop("opens_window", f"the library {name}")
        self._stop("native_calls", event)

    @staticmethod
    def _at(path: Any, dir_fd: Any) -> str:
        text = os.fsdecode(path)
        if isinstance(dir_fd, int) and not os.path.isabs(text):
            return os.path.join(os.readlink(f"/proc/self/fd/{dir_fd}"), text)
        return text

    def _check_path(self, file: Any, writes: bool, what: str) -> None:
        text = os.fsdecode(file)
        if text == ":memory:" or not text:
            return
        path = os.path.realpath(text)
        if path in self.devices or _under(path, (self.folder,)):
            return
        if not writes and _under(path, self.roots):
            return
        self.armed = False  # the message is built without tripping the fence again
        try:
            self._stop("outside_folder", f"{what} {text!r}")
        finally:
            self.armed = True


class _Quiet:
    def __init__(self, fence: Fence) -> None:
        self.fence = fence

    def __enter__(self) -> Fence:
        self.fence.hush += 1
        return self.fence

    def __exit__(self, *exc: object) -> None:
        self.fence.hush -= 1


# ---- limits --------------------------------------------------------------------------------


def _set_limit(name: str, value: int) -> None:
    """``name`` at ``value`` (or its hard limit, if lower), soft = hard: not to be raised."""
    which = getattr(resource, name)
    _, hard = resource.getrlimit(which)
    v = value if hard == resource.RLIM_INFINITY else min(value, hard)
    resource.setrlimit(which, (v, v))


def _address_space() -> int:
    """This process's virtual size in bytes (``/proc/self/statm``)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


def apply_limits(limits: dict[str, int]) -> None:
    """Every limit but the address space (set once numpy is in: :func:`limit_memory`)."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # an oversized write fails, not the process
    for key, name in LIMITS.items():
        if key in limits:
            _set_limit(name, int(limits[key]))


def limit_memory(budget: int) -> None:
    """Address space: this process's own (interpreter, numpy) plus the student's ``budget``."""
    _set_limit("RLIMIT_AS", _address_space() + int(budget))


# ---- the student's answers as plain arrays -------------------------------------------------


class Unsendable(ValueError):
    """An answer that is not plain numbers (``key``: its diagnosis)."""

    def __init__(self, key: str, text: str) -> None:
        super().__init__(text)
        self.key = key


def _numbers(x: Any, what: str) -> Any:
    import numpy as np

    a = np.asarray(x)
    if a.dtype.kind not in "biufc":
        raise Unsendable(
            "not_numbers", f"{what} is {type(x).__name__} of dtype {a.dtype}, not numbers"
        )
    return a


def pack(answer: Any, kind: str) -> tuple[str, dict[str, Any]]:
    """The answer as ``(tag, arrays)``: ``sparse`` (CSR parts), ``pair`` (λ, U), ``ragged``
    (rings: values and offsets), ``array`` or ``none``. Runs the student's code (``__array__``,
    ``__iter__``): call it inside the fence."""
    import numpy as np

    if answer is None:
        return "none", {}
    if hasattr(answer, "tocsr") and hasattr(answer, "nnz"):  # scipy.sparse, any format
        C = answer.tocsr()
        return "sparse", {
            "data": _numbers(C.data, "the matrix"),
            "indices": np.asarray(C.indices, np.int64),
            "indptr": np.asarray(C.indptr, np.int64),
            "shape": np.asarray(C.shape, np.int64),
        }
    if kind == "eigen" and isinstance(answer, (tuple, list)) and len(answer) == 2:
        return "pair", {"lam": _numbers(answer[0], "lam"), "U": _numbers(answer[1], "U")}
    if kind == "ring" and (
        isinstance(answer, (list, tuple)) or str(getattr(answer, "dtype", "")) == "object"
    ):
        rings = [_numbers(r, f"ring {i}").ravel() for i, r in enumerate(answer)]
        offsets = np.cumsum([0] + [len(r) for r in rings]).astype(np.int64)
        values = np.concatenate(rings) if rings else np.zeros(0, np.int64)
        return "ragged", {"values": values, "offsets": offsets}
    if isinstance(answer, (str, bytes, dict, set)):
        raise Unsendable("not_numbers", f"returned a {type(answer).__name__}, not an array")
    return "array", {"value": _numbers(answer, f"the answer ({type(answer).__name__})")}


def _write(arrays: dict[str, Any], path: str, cap: int) -> None:
    import numpy as np

    size = sum(int(a.nbytes) for a in arrays.values())
    if size > cap:
        shapes = ", ".join(f"{k} {a.shape} {a.dtype}" for k, a in arrays.items())
        raise Unsendable(
            "dense_at_size",
            f"an answer of {size / 2**20:.0f} MiB ({shapes}): "
            f"over the {cap / 2**20:.0f} MiB an answer may take",
        )
    tmp = path + ".part"
    np.savez(tmp, **arrays)  # uncompressed, no object arrays: read back without pickle
    os.replace(tmp + ".npz", path)


# ---- the student's code --------------------------------------------------------------------


def student_traceback(exc: BaseException, folder: str) -> str:
    """The traceback of ``exc`` with the frames of the student's folder only, paths relative."""
    root = os.path.realpath(folder) + os.sep
    frames = [
        f
        for f in traceback.extract_tb(exc.__traceback__)
        if os.path.isabs(f.filename) and os.path.realpath(f.filename).startswith(root)
    ]
    lines = ["Traceback (your file only):\n", *traceback.format_list(frames)]
    lines += traceback.format_exception_only(type(exc), exc)
    text = "".join(lines).rstrip().replace(root, "")
    return text if len(text) <= TEXT_CAP else text[: TEXT_CAP - 1] + "…"


def _failure(exc: BaseException, fence: Fence, finder: _NoMeshlap, folder: str) -> dict:
    """The ``raised`` / ``import_error`` fields of an exception of the student's code."""
    refused = exc if isinstance(exc, Refused) else fence.take()
    fence.take()
    with fence.quiet():  # the traceback reads source files (linecache): the harness's work
        text = student_traceback(exc, folder)
    if refused is not None:
        return {"kind": "refused", "key": refused.key, "text": text, "what": refused.what}
    if isinstance(exc, Unsendable):
        return {"kind": "unsendable", "key": exc.key, "text": str(exc)}
    if isinstance(exc, SystemExit):
        return {"kind": "exit", "key": "calls_exit", "text": text, "what": repr(exc.code)}
    if isinstance(exc, NotImplementedError):
        return {"kind": "not_implemented", "key": None, "text": ""}
    if isinstance(exc, MemoryError):
        return {"kind": "memory", "key": None, "text": text}
    key = "imports_meshlap" if isinstance(exc, ImportError) and finder.asked else None
    finder.asked = None
    return {"kind": "error", "key": key, "text": text}


class _Sampler(threading.Thread):
    """Counts, every few milliseconds, the line of the student's folder the main thread is in
    (the innermost such frame): the report names the loop where a slow answer spends its time."""

    def __init__(self, folder: str, target: int) -> None:
        super().__init__(daemon=True)
        self.root = os.path.realpath(folder) + os.sep
        self.target = target
        self.counts: dict[tuple[str, int], int] = {}
        self.done = threading.Event()

    def run(self) -> None:
        while not self.done.wait(SAMPLE_SECONDS):
            frame = sys._current_frames().get(self.target)
            while frame is not None and not frame.f_code.co_filename.startswith(self.root):
                frame = frame.f_back
            if frame is not None and isinstance(frame.f_lineno, int):
                key = (frame.f_code.co_filename[len(self.root) :][:512], frame.f_lineno)
                self.counts[key] = self.counts.get(key, 0) + 1

    def hottest(self) -> list[list[Any]]:
        self.done.set()
        self.join(1.0)
        top = sorted(self.counts.items(), key=lambda kv: -kv[1])[:8]
        return [[file, line, n] for (file, line), n in top]


class Harness:
    """The command loop (see the module's table)."""

    def __init__(self, config: dict[str, Any]) -> None:
        self.config = config
        self.folder = config["folder"]
        self.student = config["student"]
        self.cap = int(config["answer_cap"])
        self.commands = os.fdopen(int(config["commands"]), "rb", buffering=0)
        self.replies = int(config["replies"])
        self.module: Any = None
        self.nonce = ""
        self.finder = _forget_meshlap()
        self.fence = Fence(self.folder)

    def reply(self, message: dict[str, Any]) -> None:
        data = (json.dumps({**message, "nonce": self.nonce}) + "\n").encode()
        with self.fence.quiet():
            while data:
                data = data[os.write(self.replies, data) :]

    def serve(self) -> None:
        self.reply({"ev": "ready"})
        while True:
            with self.fence.quiet():
                line = self.commands.readline(1 << 20)
            if not line:
                return
            command = json.loads(line)
            self.nonce = str(command.get("nonce", ""))
            if command.get("op") == "import":
                self.load()
            elif command.get("op") == "call":
                self.call(command)
            else:
                return

    def load(self) -> None:
        sys.path.insert(0, self.folder)
        spec = importlib.util.spec_from_file_location(STUDENT_MODULE, self.student)
        try:
            if spec is None or spec.loader is None:
                raise ImportError(f"cannot import {os.path.basename(self.student)}")
            module = importlib.util.module_from_spec(spec)
            sys.modules[STUDENT_MODULE] = module
            self.fence.armed = True
            spec.loader.exec_module(module)
            refused = self.fence.take()
            if refused is not None:  # caught by the student: still refused
                raise refused
        except BaseException as exc:  # SystemExit, SyntaxError: the student's
            self.reply(
                {"ev": "import_error", **_failure(exc, self.fence, self.finder, self.folder)}
            )
            return
        self.module = module
        wanted = self.config.get("functions", [])
        found = [n for n in wanted if callable(getattr(module, n, None))]
        self.reply({"ev": "imported", "functions": found})

    def _arguments(self, command: dict[str, Any]) -> list[Any]:
        import numpy as np

        with self.fence.quiet():
            path = os.path.join(self.config["inputs"], os.path.basename(command["inputs"]))
            with np.load(path, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files}
            out: list[Any] = []
            for spec in command["args"]:
                if spec[0] == "value":
                    out.append(spec[1])
                elif spec[0] == "csr":
                    import scipy.sparse as sp

                    k = spec[1]
                    parts = (arrays[k + ".data"], arrays[k + ".indices"], arrays[k + ".indptr"])
                    out.append(sp.csr_matrix(parts, shape=tuple(arrays[k + ".shape"])))
                else:
                    out.append(arrays[spec[1]].copy())
        return out

    def call(self, command: dict[str, Any]) -> None:
        ident = int(command["id"])
        args = self._arguments(command)
        sampler = _Sampler(self.folder, threading.get_ident()) if command.get("profile") else None
        try:
            func = getattr(self.module, str(command["func"]))
            if sampler is not None:
                sampler.start()
            answer = func(*args)
            hot = sampler.hottest() if sampler is not None else []
            tag, arrays = pack(answer, str(command["kind"]))
            refused = self.fence.take()
            if refused is not None:  # caught by the student: still refused
                raise refused
            with self.fence.quiet():
                _write(arrays, os.path.join(self.config["outputs"], f"{ident}.npz"), self.cap)
        except BaseException as exc:
            if sampler is not None:
                sampler.done.set()
            self.reply(
                {"ev": "raised", "id": ident, **_failure(exc, self.fence, self.finder, self.folder)}
            )
            return
        self.reply({"ev": "answer", "id": ident, "tag": tag, "hot": hot})


PRELOADED = ("numpy", "scipy.sparse", "scipy.sparse.linalg", "scipy.linalg", "igl")
"""What the template and most students import: loaded before the student's clock starts."""


def _preload() -> None:
    for name in PRELOADED:
        try:
            importlib.import_module(name)
        except ImportError:
            continue


def main() -> None:
    """``python -I -B harness.py CONFIG``: limits, numpy, the fence, then the command loop."""
    config = json.loads(sys.argv[1])
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)  # the student's input() reads nothing, not the checker's commands
    apply_limits(config.get("limits", {}))
    _preload()  # before the address-space limit and the student's clock: the harness's cost

    harness = Harness(config)
    limit_memory(int(config.get("limits", {}).get("memory", 2 << 30)))
    harness.fence.install()
    sys.stdout.flush()
    harness.serve()
    os._exit(0)  # the student's threads end with the harness


if __name__ == "__main__":
    main()
