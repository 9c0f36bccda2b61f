"""``meshlap exercises init DIR [--force]``: write the student file of the exercises.

The file (``DIR/exercises.py``) has one stub per task (signature, shapes, conventions, the
formula and its reference, no solution); ``meshlap check DIR/exercises.py`` checks it. An
existing file is never replaced unless ``--force`` is given; the write is atomic.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from ..errors import MeshError
from ..exercises.templates import template
from ..io.atomic import atomic_write, check_output_path
from ._common import shown

FILENAME = "exercises.py"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("exercises", help="exercises that check themselves (init: the student file)")
    actions = p.add_subparsers(dest="action", metavar="ACTION")
    actions.required = True
    init = actions.add_parser("init", help=f"write DIR/{FILENAME}, one stub per task")
    init.add_argument("dir", help="folder to write into (created if missing)")
    init.add_argument("--force", action="store_true", help="replace an existing file")
    init.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if not args.dir.strip():  # (Path("") is the current folder: never chosen by accident)
        raise MeshError("the folder name is empty; name the folder to write into", "DIR")
    folder = Path(args.dir)
    if folder.exists() and not folder.is_dir():
        raise MeshError("not a folder", os.fspath(folder))
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / FILENAME
    if target.exists() and not args.force:
        raise MeshError("exists already; not replaced (use --force to start over)", target)
    check_output_path(target)
    with atomic_write(target) as f:
        f.write(template(FILENAME))
    print(f"wrote {shown(target)}")
    print(f"next: implement the functions, then run  meshlap check {shown(target)}")
    return 0
