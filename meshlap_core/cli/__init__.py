"""The ``meshlap`` command line.

Each subcommand lives in its own module of this package with two functions:
``register(sub)`` adds its argparse sub-parser (and ``set_defaults(func=run)``), and
``run(args) -> int`` does the work. ``main`` turns every :class:`MeshError` (and unreadable
files) into one line ``meshlap: error: <file>: <problem>`` on stderr and exit code 2.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading


def _quiet_interrupt(signum: int, frame: object) -> None:
    """SIGINT while this package is being imported: one line, exit 130, no traceback."""
    sys.stderr.write("meshlap: interrupted\n")
    os._exit(130)


# Run as the program (the ``meshlap`` script, or ``python -m meshlap_core.cli`` while runpy
# locates the module, when ``sys.argv[0]`` is still "-m"): until ``main`` starts the command,
# SIGINT exits 130 with one line instead of a traceback from inside numpy / scipy / libigl.
# A program that merely imports this package keeps Python's handler.
if (
    os.path.basename(sys.argv[0] if sys.argv else "") in ("meshlap", "-m")
    and threading.current_thread() is threading.main_thread()
    and signal.getsignal(signal.SIGINT) is signal.default_int_handler
):
    signal.signal(signal.SIGINT, _quiet_interrupt)

import argparse  # noqa: E402
import codecs  # noqa: E402
import importlib  # noqa: E402
import io  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Sequence  # noqa: E402

from .._version import __version__  # noqa: E402
from ..errors import MeshError, MeshWarning, printable  # noqa: E402

#: ASCII spellings of the symbols meshlap prints, for a stream that cannot encode them
#: (``PYTHONIOENCODING=ascii``, ``LC_ALL=C`` with an older Python, a latin-1 terminal)
ASCII_SPELLINGS: dict[str, str] = {
    "χ": "chi",
    "λ": "lambda",
    "κ": "kappa",
    "ν": "nu",
    "μ": "mu",
    "α": "alpha",
    "β": "beta",
    "θ": "theta",
    "σ": "sigma",
    "Δ": "Delta",
    "π": "pi",
    "≤": "<=",
    "≥": ">=",
    "≠": "!=",
    "≈": "~",
    "±": "+-",
    "×": "x",
    "·": "*",
    "−": "-",
    "–": "-",
    "—": "--",
    "→": "->",
    "←": "<-",
    "…": "...",
    "²": "^2",
    "³": "^3",
    "⁻": "^-",
    "¹": "^1",
    "₁": "1",
    "₂": "2",
    "ᵀ": "^T",
    "√": "sqrt",
    "∞": "inf",
    "°": " deg",
    "‖": "||",
}


def _ascii_fallback(exc: UnicodeError) -> tuple[str, int]:
    """Codec error handler ``meshlap-ascii``: the ASCII spelling of each character the stream
    cannot encode (``χ`` → ``chi``), ``?`` for one without a spelling."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    bad = exc.object[exc.start : exc.end]
    return "".join(ASCII_SPELLINGS.get(ch, "?") for ch in bad), exc.end


codecs.register_error("meshlap-ascii", _ascii_fallback)


class _ClosedStream(io.TextIOBase):
    """Stands in for a standard stream that was closed when meshlap started (``>&-``,
    ``2>&-``: Python then sets ``sys.stdout``/``sys.stderr`` to None); records whether anything
    was written, so that lost output is an error rather than a silent success."""

    def __init__(self, name: str) -> None:
        super().__init__()
        self.name = name
        self.lost = False

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        self.lost = self.lost or bool(text)
        return len(text)

    def fileno(self) -> int:
        raise OSError(9, "Bad file descriptor")


def prepare_streams() -> None:
    """Make the standard streams safe to print on before a command runs: a closed stdout or
    stderr becomes a :class:`_ClosedStream`, and a stream whose encoding cannot spell ``χ``
    or ``λ`` writes their ASCII spellings (:data:`ASCII_SPELLINGS`) instead of raising
    ``UnicodeEncodeError``."""
    for name in ("stdout", "stderr"):
        stream = getattr(sys, name)
        if stream is None:
            setattr(sys, name, _ClosedStream(f"<{name}>"))
            continue
        encoding = getattr(stream, "encoding", None) or "ascii"
        try:
            "χλκ≤−".encode(encoding)
        except (UnicodeEncodeError, LookupError):
            if hasattr(stream, "reconfigure"):
                with contextlib.suppress(Exception):
                    stream.reconfigure(errors="meshlap-ascii")


# subcommand modules of the core, in the order ``meshlap --help`` lists them; the commands
# that open or render the viewer come from the ``meshlap.commands`` entry-point group
COMMANDS: tuple[str, ...] = (
    "info",
    "curvature",
    "onering",
    "inspect",
    "surface",
    "smooth",
    "denoise_eval",
    "report",
    "spectral",
    "exercises",
    "check",
    "geodesic",
    "heat",
    "filter",
    "deform",
    "flatten",
    "curvature_study",
)
COMMAND_GROUP = "meshlap.commands"
"""Entry points of this group name modules with ``register(sub)``: other packages (the viewer)
add their commands through it."""


class _Parser(argparse.ArgumentParser):
    """argparse that exits 2 with one ``meshlap: error:`` line (no usage dump)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise SystemExit(_fail(message))


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The full parser with every subcommand registered.

    ``only``, one of :data:`COMMANDS`, registers that subcommand alone (what :func:`main` does
    when the command line names one): the other commands' modules, and the entry points'
    lookup, are not imported, which a whole ``meshlap curvature`` process notices at start-up.
    """
    parser = _Parser(prog="meshlap", description="A Laplacian geometry lab for triangle meshes.")
    parser.add_argument("--version", action="version", version=f"meshlap {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS if only not in COMMANDS else (only,):
        importlib.import_module(f"{__name__}.{name}").register(sub)
    if only in COMMANDS:
        return parser
    from importlib.metadata import entry_points

    for ep in sorted(entry_points(group=COMMAND_GROUP), key=lambda e: e.name):
        ep.load().register(sub)
    return parser


def _named_command(argv: Sequence[str]) -> str | None:
    """The built-in command ``argv`` starts with, else ``None`` (the full parser then)."""
    return argv[0] if len(argv) and argv[0] in COMMANDS else None


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``meshlap`` console script; returns the exit code.

    Exit codes: 0 success; 2 bad input or arguments (one line ``meshlap: error: ...`` on
    stderr, nothing else); 1 an internal error (one line too; set ``MESHLAP_DEBUG=1`` for the
    traceback); 130 interrupted. Warnings raised while a command runs are printed after it
    succeeds, one line ``meshlap: warning: ...`` each, and dropped when it fails.
    """
    prepare_streams()
    try:
        # imports numpy, scipy and libigl: the slow part of start-up
        parser = build_parser(_named_command(sys.argv[1:] if argv is None else argv))
    except KeyboardInterrupt:
        sys.stderr.write("meshlap: interrupted\n")
        return 130
    args = parser.parse_args(argv)
    code = _run(args)
    out = sys.stdout
    if code == 0 and isinstance(out, _ClosedStream) and out.lost:
        return _fail("<stdout>: standard output is closed; the output was not written")
    return code


def _run(args: argparse.Namespace) -> int:
    """Run the parsed command; its exit code (see :func:`main`)."""
    if signal.getsignal(signal.SIGINT) is _quiet_interrupt:  # the command handles it from here
        signal.signal(signal.SIGINT, signal.default_int_handler)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MeshWarning)
        try:
            code = int(args.func(args) or 0)
        except MeshError as exc:
            return _fail(f"{exc}")
        except MemoryError:
            src = getattr(args, "mesh", None) or getattr(args, "clean", None)
            return _fail(
                f"{src + ': ' if src else ''}out of memory (this input with these options "
                "needs more memory than this machine gives)"
            )
        except BrokenPipeError:  # `meshlap ... | head`: the reader went away
            _silence_stdout()
            return 141
        except OSError as exc:
            from ..io.atomic import os_cause

            name = getattr(exc, "filename", None)
            what = os_cause(exc)
            return _fail(f"{os.fsdecode(name)}: {what}" if name else what)
        except KeyboardInterrupt:
            sys.stderr.write("meshlap: interrupted\n")
            return 130
        except Exception as exc:  # a bug: still one line, unless debugging
            if os.environ.get("MESHLAP_DEBUG"):
                raise
            msg = str(exc).splitlines()[0] if str(exc) else ""
            what = f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__
            sys.stderr.write(
                f"meshlap: error: internal error ({what}); please report it "
                "(MESHLAP_DEBUG=1 shows the traceback)\n"
            )
            return 1
    seen: set[str] = set()
    for w in caught:
        kind = "" if issubclass(w.category, MeshWarning) else f"{w.category.__name__}: "
        line = f"meshlap: warning: {kind}{printable(' '.join(str(w.message).split()))}"
        if line not in seen:
            seen.add(line)
            sys.stderr.write(line + "\n")
    return code


def _fail(message: str) -> int:
    """Print ``meshlap: error: <message>`` (on one line, non-printable characters escaped)
    on stderr; return 2."""
    text = printable(" ".join(message.split()))
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write(f"meshlap: error: {text}\n")
    return 2


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
