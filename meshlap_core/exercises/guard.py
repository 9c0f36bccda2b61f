"""Keep a student's file from calling meshlap itself.

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
