"""Keep a student's file from calling meshlap itself, and (:class:`Fence`) from opening
windows, starting processes or opening files outside its folder.

The checker compares a student's answer with meshlap's own: a file that imports ``meshlap_core``
(or ``meshlap_app``) and returns the reference would pass every task while checking nothing.
Two fences, both in the sandboxed worker (:mod:`.sandbox`):

- :func:`scan` reads the file before it runs: an ``import``/``from`` of meshlap anywhere in it
  (module level or inside a function), or ``importlib.import_module("meshlap_core...")`` /
  ``__import__("meshlap_core...")`` with a literal name, refuses the whole file, every task
  reported ``import_error`` with the line;
- :func:`install` wraps ``builtins.__import__`` and ``importlib.import_module`` so that a name
  built at run time (``"meshlap" + "_core"``) is refused too when the student's file, or a
  module beside it, asks for it: an ``ImportError`` whose message says why, reported as the
  task's error with the student's line.

meshlap's own modules keep importing each other lazily (the reference runs in the same worker
for the speed comparison). What the fences do not stop is a determined cheat reaching the
already-imported modules through ``sys.modules`` or ``gc``: they are there so that no honest
shortcut passes, not as a security boundary between a student and the grader.
"""

from __future__ import annotations

import ast
import builtins
import importlib
import os
import sys
from collections.abc import Callable
from typing import Any

from ..errors import MeshError
from ..io.reader import read_input

FORBIDDEN = ("meshlap_core", "meshlap_app", "meshlap")
"""Top-level package names a student's file may not import."""
WHY = (
    "an exercise file may not import meshlap ({name!r}): the checker compares your answer "
    "with meshlap's own, so calling meshlap would check nothing. Use numpy, scipy (and libigl)."
)


def forbidden(name: str) -> bool:
    """``name`` is meshlap or one of its modules."""
    return name.split(".")[0] in FORBIDDEN


def _literal_import(node: ast.Call) -> str | None:
    func = node.func
    called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
    if called not in ("import_module", "__import__") or not node.args:
        return None
    arg = node.args[0]
    return arg.value if isinstance(arg, ast.Constant) and isinstance(arg.value, str) else None


def scan(path: str) -> str | None:
    """What is refused in the student file ``path`` (the first meshlap import, with its line),
    or ``None`` (also when the file does not parse: importing it reports that)."""
    try:
        source = read_input(path, what="student file").decode("utf-8")
        tree = ast.parse(source, filename=path)
    except (MeshError, OSError, SyntaxError, UnicodeDecodeError, ValueError):
        return None
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        elif isinstance(node, ast.Call) and (literal := _literal_import(node)):
            names = [literal]
        for name in names:
            if forbidden(name):
                return f"line {node.lineno}: " + WHY.format(name=name)
    return None


def _asked_by_student(namespace: dict[str, Any] | None, student: str, folder: str) -> bool:
    if not namespace:
        return False
    name = str(namespace.get("__name__", ""))
    if name == student:
        return True
    if name.startswith("meshlap_"):
        return False  # meshlap's own lazy imports
    file = namespace.get("__file__")
    return bool(file) and os.path.realpath(str(file)).startswith(folder + os.sep)


def install(student: str, path: str) -> None:
    """Refuse meshlap to the module named ``student`` and to modules in the folder of its file
    ``path`` (this process only: call it in the sandboxed worker)."""
    folder = os.path.dirname(os.path.realpath(path))
    real_import: Callable[..., Any] = builtins.__import__
    real_import_module: Callable[..., Any] = importlib.import_module

    def guarded_import(
        name: str, globals: Any = None, locals: Any = None, fromlist: Any = (), level: int = 0
    ) -> Any:
        asker = globals if globals is not None else sys._getframe(1).f_globals
        if level == 0 and forbidden(name) and _asked_by_student(asker, student, folder):
            raise ImportError(WHY.format(name=name), name=name)
        return real_import(name, globals, locals, fromlist, level)

    def guarded_import_module(name: str, package: str | None = None) -> Any:
        asker = sys._getframe(1).f_globals
        if forbidden(name) and _asked_by_student(asker, student, folder):
            raise ImportError(WHY.format(name=name), name=name)
        return real_import_module(name, package)

    builtins.__import__ = guarded_import
    importlib.import_module = guarded_import_module  # type: ignore[assignment]


# ---- the sandbox's fences: windows, processes, files outside the student's folder ------------

WINDOW_MODULES = (
    "polyscope", "tkinter", "_tkinter", "turtle", "PyQt5", "PyQt6", "PySide2", "PySide6",
    "pyglet", "glfw", "vedo", "pyvista", "open3d", "meshplot", "OpenGL", "wx", "kivy",
)  # fmt: skip
"""Top-level packages that open windows: a student file may not import them in the checker (it
runs headless, unattended; a window would wait for a user who is not there)."""
WINDOW_LIBRARIES = ("libx11", "libxcb", "libgl", "libegl", "libglfw", "libwayland", "libvulkan")
"""Shared libraries (``ctypes``) that open windows or graphics contexts (lower case prefixes)."""
PROCESS_EVENTS = (
    "subprocess.Popen", "os.system", "os.fork", "os.forkpty", "os.exec", "os.posix_spawn",
    "os.spawn", "os.startfile", "pty.spawn",
)  # fmt: skip
"""Audit events (PEP 578) that start a process."""
FENCE_WHY = {
    "opens_window": "your file opens a window ({what}): the checker runs without a screen and "
    'nobody would close it. Keep plots and viewers under `if __name__ == "__main__":`.',
    "spawns_process": "your file starts a process ({what}): a check runs your functions "
    "only; compute in Python (numpy, scipy, libigl).",
    "outside_folder": "your file opens {what}, outside its own folder: a check may read or "
    "write only files beside your exercises file.",
}
"""Why a fence stopped the student, by diagnosis key (:data:`.diagnose.DIAGNOSES`)."""


class Refused(PermissionError):
    """A fence stopped the student's code (``key``: the diagnosis)."""

    def __init__(self, key: str, what: str) -> None:
        super().__init__(FENCE_WHY[key].format(what=what))
        self.key = key


def _under(path: str, roots: tuple[str, ...]) -> bool:
    return any(path == r or path.startswith(r.rstrip(os.sep) + os.sep) for r in roots)


def _library_roots() -> tuple[str, ...]:
    """Where Python, numpy, scipy and libigl read their own files (lazy imports, data)."""
    import site

    roots = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix}
    with_site = [*site.getsitepackages(), site.getusersitepackages()]
    roots.update(p for p in with_site if isinstance(p, str))
    for name in ("numpy", "scipy", "igl"):
        module = sys.modules.get(name)
        file = getattr(module, "__file__", None)
        if file:
            roots.add(os.path.dirname(os.path.dirname(os.path.realpath(file))))
    return tuple(sorted(os.path.realpath(r) for r in roots if r))


class Fence:
    """Stops the student's code (only while :meth:`student` is active) from opening a window,
    starting a process, or opening a file outside its folder, and remembers the first attempt
    even when the student catches the exception (:meth:`take`).

    Built on Python's audit hooks (PEP 578: ``import``, ``open``, ``subprocess.Popen``,
    ``os.system``, ``os.fork``, ``os.exec``, ``os.posix_spawn``, ``ctypes.dlopen``...), plus
    the one process start CPython does not audit (``_posixsubprocess.fork_exec``,
    multiprocessing's spawn). An
    audit hook cannot be removed: install it in the sandboxed worker only. A pool or process of
    ``multiprocessing`` is refused at its ``start``, before multiprocessing's own complaint that
    a daemonic process (the worker) may not have children.
    """

    def __init__(self, path: str) -> None:
        self.folder = os.path.dirname(os.path.realpath(path))
        self.roots = _library_roots()
        self.allowed_files = ("/dev/null", "/dev/urandom", "/dev/random")
        self.active = False
        self.refused: Refused | None = None

    def install(self) -> None:
        """Add the audit hook and the ``fork_exec`` wrapper; take away the display (nothing
        can reach an X or Wayland server from the worker)."""
        for var in ("DISPLAY", "WAYLAND_DISPLAY"):
            os.environ.pop(var, None)
        sys.addaudithook(self._hook)
        import multiprocessing.process as mp_process

        real_start = mp_process.BaseProcess.start

        def start(process: Any) -> None:  # before multiprocessing's own daemon check
            if self.active:
                self._stop("spawns_process", "multiprocessing")
            real_start(process)

        mp_process.BaseProcess.start = start  # type: ignore[method-assign]
        try:
            import _posixsubprocess
        except ImportError:  # not POSIX
            return
        real = _posixsubprocess.fork_exec

        def fork_exec(*args: Any, **kwargs: Any) -> Any:
            if self.active:
                self._stop("spawns_process", "a child process")
            return real(*args, **kwargs)

        _posixsubprocess.fork_exec = fork_exec

    def student(self) -> _Active:
        """``with fence.student():`` around the student's code (the import, each call)."""
        return _Active(self)

    def take(self) -> Refused | None:
        """The first refused attempt since the last ``take`` (and forget it)."""
        refused, self.refused = self.refused, None
        return refused

    def _stop(self, key: str, what: str) -> None:
        exc = Refused(key, what)
        if self.refused is None:
            self.refused = exc
        raise exc

    def _hook(self, event: str, args: tuple[Any, ...]) -> None:
        if not self.active:
            return
        if event in PROCESS_EVENTS:
            self._stop("spawns_process", event)
        elif event == "import" and args and str(args[0]).split(".")[0] in WINDOW_MODULES:
            self._stop("opens_window", f"import {args[0]}")
        elif event == "ctypes.dlopen" and args and args[0]:
            name = os.path.basename(str(args[0])).lower()
            if name.startswith(WINDOW_LIBRARIES):
                self._stop("opens_window", f"the library {name}")
        elif event == "open" and args and isinstance(args[0], (str, bytes, os.PathLike)):
            self._check_open(args[0])

    def _check_open(self, file: Any) -> None:
        path = os.path.realpath(os.fsdecode(file))
        if path in self.allowed_files or _under(path, (self.folder, *self.roots)):
            return
        self.active = False  # the message is built without tripping the fence again
        try:
            self._stop("outside_folder", repr(os.fsdecode(file)))
        finally:
            self.active = True


class _Active:
    def __init__(self, fence: Fence) -> None:
        self.fence = fence

    def __enter__(self) -> Fence:
        self.fence.active = True
        return self.fence

    def __exit__(self, *exc: object) -> None:
        self.fence.active = False
