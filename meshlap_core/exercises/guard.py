"""Refuse, before it runs, a student's file that imports meshlap itself.

The checker compares a student's answer with meshlap's own: a file that imports
``meshlap_core`` (or ``meshlap_app``) and returns the reference would pass every task while
checking nothing. :func:`scan` reads the file (parsed, never run) for an ``import``/``from`` of
meshlap anywhere in it (module level or inside a function), or
``importlib.import_module("meshlap_core...")`` / ``__import__("meshlap_core...")`` with a literal
name: the whole file is refused, every task reported ``import_error`` with the line.

A name built at run time is refused by the harness (:mod:`.harness`: meshlap is off the
student's import system and, under bubblewrap, not even in its file system); what the student's
code tries beyond that, the harness's fence names.
"""

from __future__ import annotations

import ast

from ..errors import MeshError
from ..io.reader import read_input
from .harness import FORBIDDEN, WHY

__all__ = ["FORBIDDEN", "WHY", "forbidden", "scan"]


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
