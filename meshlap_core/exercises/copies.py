"""Each submission is checked in a copy of its own, and only its own.

- A student's file: the file (under the name it was given, a symbolic link followed) and the
  modules beside it that it imports (``import helpers`` with ``helpers.py`` or a package
  ``helpers/`` there, transitively) — not the rest of its folder.
- A student's folder (what course sites export, one folder per student): the whole folder,
  helper modules and data files included, up to :data:`COPY_BYTES` and :data:`COPY_FILES`; a
  symbolic link is followed only to a regular file inside the same folder, special files
  (FIFOs, devices, sockets) are skipped, each skip said in the report.

The worker then sees the copy only (:mod:`.isolation`): what it writes stays in the copy, what
it reads is what the student submitted.
"""

from __future__ import annotations

import ast
import os
import shutil
import stat
from dataclasses import dataclass
from pathlib import Path

from ..errors import MeshError, printable
from ..io.reader import read_input

COPY_BYTES = 64 * 2**20
"""Bytes of a student's folder copied at most."""
COPY_FILES = 2000
"""Files of a student's folder copied at most."""
KINDS = {
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFIFO: "a named pipe (FIFO)",
    stat.S_IFSOCK: "a socket",
    stat.S_IFDIR: "a folder",
}


@dataclass(frozen=True)
class Submission:
    """One student's work.

    Attributes
    ----------
    name : str
        The student in reports (the file's stem, or the folder's name).
    path : Path
        The student's exercises file (as given: it may be a symbolic link).
    folder : Path or None
        The student's folder, copied whole; None: the file and the modules it imports.
    among_others : bool
        The file lies among other students' files (a class folder of ``.py`` files): a module
        beside it that defines a task is another submission, and is not copied.
    """

    name: str
    path: Path
    folder: Path | None = None
    among_others: bool = False


def student_file(path: str | os.PathLike) -> Path:
    """``path`` checked to be a regular file one can read as a student's file.

    Raises
    ------
    MeshError
        Missing, a folder, a device (``/dev/null``), a FIFO or a socket.
    """
    p = Path(path)
    try:
        mode = os.stat(p).st_mode  # follows a symbolic link; never opens (a FIFO would block)
    except FileNotFoundError:
        raise MeshError("no such file", printable(os.fspath(p))) from None
    except OSError as exc:
        raise MeshError(f"cannot read it ({exc.strerror})", printable(os.fspath(p))) from None
    if not stat.S_ISREG(mode):
        kind = KINDS.get(stat.S_IFMT(mode), "not a regular file")
        raise MeshError(f"{kind}, not a Python file", printable(os.fspath(p)))
    return p


SOURCE_BYTES = 16 * 2**20
"""The largest student source file the checker parses (never runs): for the tasks it defines,
the modules it imports, the loop a slow answer spends its time in."""


def read_source(path: Path) -> str | None:
    """The student's file ``path`` as text (through the checked reader: no FIFO, no device,
    at most :data:`SOURCE_BYTES`), or None when it cannot be read."""
    try:
        return read_input(path, what="student file", max_bytes=SOURCE_BYTES).decode(
            "utf-8", errors="replace"
        )
    except (MeshError, OSError):
        return None


def parse_source(path: Path) -> ast.Module | None:
    """The student's file ``path`` parsed (never run), or None when it cannot be read or
    parsed (running it then says why)."""
    text = read_source(path)
    try:
        return None if text is None else ast.parse(text)
    except (SyntaxError, ValueError):
        return None


def defines_tasks(path: Path, names: tuple[str, ...]) -> bool:
    """``path`` defines a top-level function named like a task (parsed, never run)."""
    tree = parse_source(path)
    if tree is None:
        return False
    return any(isinstance(n, ast.FunctionDef) and n.name in names for n in tree.body)


def _imported_siblings(source: Path, folder: Path) -> set[str]:
    """Top-level names ``source`` imports that are modules or packages in ``folder``."""
    tree = parse_source(source)
    if tree is None:
        return set()
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return {
        n for n in names if (folder / f"{n}.py").is_file() or (folder / n / "__init__.py").is_file()
    }


def _copy_file(src: Path, dst: Path) -> int:
    """Copy a regular file's bytes (never a FIFO or device: checked first); its size."""
    if not stat.S_ISREG(os.stat(src).st_mode):
        return 0
    dst.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(src, dst)
    return dst.stat().st_size


def _copy_tree(src: Path, dst: Path, root: Path, notes: list[str], budget: list[int]) -> None:
    """Copy ``src`` into ``dst`` within the submission ``root`` (see module); ``budget`` is
    ``[bytes, files]`` left."""
    dst.mkdir(parents=True, exist_ok=True)
    for entry in sorted(os.scandir(src), key=lambda e: e.name):
        if entry.name.startswith(".") or entry.name == "__pycache__":
            continue
        path, target = Path(entry.path), dst / entry.name
        shown = printable(os.fspath(path.relative_to(root)))
        if entry.is_symlink():
            real = Path(os.path.realpath(path))
            if not real.is_relative_to(os.path.realpath(root)):
                notes.append(f"skipped {shown}: a link to something outside the submission")
                continue
            if not real.is_file():
                notes.append(f"skipped {shown}: a link to a folder (not followed)")
                continue
        if entry.is_dir(follow_symlinks=False):
            _copy_tree(path, target, root, notes, budget)
        elif entry.is_file():
            size = os.stat(path).st_size
            if size > budget[0] or budget[1] <= 0:
                notes.append(
                    f"skipped {shown}: the copy is limited to {COPY_FILES} files and "
                    f"{COPY_BYTES // 2**20} MiB"
                )
                continue
            budget[0] -= _copy_file(path, target)
            budget[1] -= 1
        else:
            notes.append(f"skipped {shown}: not a regular file")


def copy_submission(
    sub: Submission, into: Path, tasks: tuple[str, ...] = ()
) -> tuple[str, list[str]]:
    """Copy ``sub`` into the empty folder ``into`` (``tasks``: the task names, to tell another
    student's file from a helper module when ``sub.among_others``).

    Returns
    -------
    main : str
        The student's file, relative to ``into``.
    notes : list of str
        What was left out, and why.
    """
    notes: list[str] = []
    if sub.folder is not None:
        _copy_tree(sub.folder, into, sub.folder, notes, [COPY_BYTES, COPY_FILES])
        return os.fspath(sub.path.relative_to(sub.folder)), notes
    folder = sub.path.parent
    _copy_file(sub.path, into / sub.path.name)
    done, todo = {sub.path.stem}, [sub.path]
    while todo:
        for name in sorted(_imported_siblings(todo.pop(), folder) - done):
            done.add(name)
            module = folder / f"{name}.py"
            linked = module if module.is_file() else folder / name
            if linked.is_symlink() and not Path(os.path.realpath(linked)).is_relative_to(
                os.path.realpath(folder)
            ):
                notes.append(f"not copied: {printable(module.name)}, a link out of the folder")
                continue
            if sub.among_others and module.is_file() and defines_tasks(module, tasks):
                notes.append(f"not copied: {printable(module.name)}, another student's file")
                continue
            if module.is_file():
                _copy_file(folder / f"{name}.py", into / f"{name}.py")
                todo.append(folder / f"{name}.py")
            else:
                _copy_tree(folder / name, into / name, folder, notes, [COPY_BYTES, COPY_FILES])
    return sub.path.name, notes
