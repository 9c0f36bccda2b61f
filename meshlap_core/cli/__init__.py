"""The ``meshlap`` command line.

Each subcommand lives in its own module of this package with two functions:
``register(sub)`` adds its argparse sub-parser (and ``set_defaults(func=run)``), and
``run(args) -> int`` does the work. ``main`` turns every :class:`MeshError` (and unreadable
files) into one line ``meshlap: error: <file>: <problem>`` on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from .._version import __version__
from ..errors import MeshError

# subcommand modules, in the order ``meshlap --help`` lists them
COMMANDS: tuple[str, ...] = (
    "info",
    "curvature",
    "onering",
    "view",
    "surface",
    "smooth",
    "denoise_eval",
)


class _Parser(argparse.ArgumentParser):
    """argparse that exits 2 with one ``meshlap: error:`` line (no usage dump)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"meshlap: error: {message}\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """The full parser with every subcommand registered."""
    parser = _Parser(prog="meshlap", description="A Laplacian geometry lab for triangle meshes.")
    parser.add_argument("--version", action="version", version=f"meshlap {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``meshlap`` console script; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except MeshError as exc:
        sys.stderr.write(f"meshlap: error: {exc}\n")
        return 2
    except (OSError, MemoryError) as exc:
        name = getattr(exc, "filename", None)
        what = (
            exc.strerror
            if isinstance(exc, OSError) and exc.strerror
            else str(exc) or type(exc).__name__
        )
        sys.stderr.write(f"meshlap: error: {name + ': ' if name else ''}{what}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("meshlap: interrupted\n")
        return 130


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
