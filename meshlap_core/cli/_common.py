"""Helpers shared by the subcommands: argument parsing, JSON output, statistics, field output."""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError, printable


def parse_list(text: str, kind: type, name: str) -> list[Any]:
    """Parse ``"5,15,50"`` into ``[5, 15, 50]`` (``kind`` int or float).

    A bad list raises :class:`MeshError` naming the argument ``name``.
    """
    try:
        values = [kind(t) for t in text.split(",") if t.strip()]
    except ValueError:
        msg = f"expected a comma-separated list of {kind.__name__}s, got {text!r}"
        raise MeshError(msg, name) from None
    if not values:
        raise MeshError("the list is empty", name)
    if kind is float and not all(math.isfinite(v) for v in values):
        raise MeshError(f"values must be finite, got {text!r}", name)
    return values


def shown(path: Any) -> str:
    """A file name as printed on a terminal: control characters, escape sequences and
    undecodable bytes escaped (:func:`~meshlap_core.errors.printable`), never printed raw."""
    return printable(os.fsdecode(path) if isinstance(path, bytes) else str(path))


def number_text(text: str, flag: str) -> float:
    """A number typed on the command line as a float (``nan`` and ``inf`` pass: the core's
    check of the value names what is wrong); anything else refused naming ``flag``."""
    try:
        return float(text)
    except (TypeError, ValueError):
        raise MeshError(f"expected a number, got {text!r}", flag) from None


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, float | np.floating):
        f = float(obj)
        return f if math.isfinite(f) else None
    return obj


def emit_json(obj: dict[str, Any]) -> None:
    """Print exactly one JSON object on stdout (NaN/inf become null, numpy types plain)."""
    sys.stdout.write(json.dumps(_jsonable(obj)) + "\n")


def summary_stats(values: np.ndarray) -> dict[str, float]:
    """``min, max, mean, median, p01, p99`` of the finite entries of ``values``."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {k: float("nan") for k in ("min", "max", "mean", "median", "p01", "p99")}
    p01, med, p99 = np.percentile(v, [1, 50, 99])
    return {
        "min": float(v.min()),
        "max": float(v.max()),
        "mean": float(v.mean()),
        "median": float(med),
        "p01": float(p01),
        "p99": float(p99),
    }


def save_field(out: Path | None, V: Any, F: Any, values: Any, source: Any) -> None:
    """Write the per-vertex field ``values`` ``(n,)`` to ``out``: a ``.ply`` is the mesh
    ``(V, F)`` with the field as its vertex quality, any other suffix a scalars file
    (:func:`~meshlap_core.io.save_scalars`); nothing when ``out`` is ``None``. The input mesh
    ``source`` is never overwritten."""
    if out is None:
        return
    from ..io import save_mesh, save_scalars

    if Path(out).suffix.lower() == ".ply":
        save_mesh(out, V, F, scalars=values, overwrite_inputs=(source,))
    else:
        save_scalars(out, values, overwrite_inputs=(source,))


def add_json_flag(p: argparse.ArgumentParser) -> None:
    """Add the common ``--json`` flag."""
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def print_report(source: Any, report: Any) -> None:
    """The loader's repairs and warnings on stderr, one line each (``--json`` keeps them too).

    ``meshlap: <file>: repaired: ...`` and ``meshlap: <file>: warning: ...``. Commands call it
    once their work has succeeded, so that a failing run prints its error line alone.
    """
    shown = printable(str(source))
    for r in getattr(report, "repairs", []):
        sys.stderr.write(f"meshlap: {shown}: repaired: {r}\n")
    for w in getattr(report, "warnings", []):
        sys.stderr.write(f"meshlap: {shown}: warning: {w}\n")


class _RenamedFlag(argparse.Action):
    """A flag's old spelling: using it (with or without a value) exits 2 naming the new flag."""

    def __init__(self, option_strings: list[str], dest: str, *, new: str, **kwargs: Any) -> None:
        self.new = new
        super().__init__(option_strings, dest, nargs="?", default=argparse.SUPPRESS, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        parser.error(f"{option_string}: renamed; use {self.new}")


def add_renamed_flag(p: argparse.ArgumentParser, old: str, new: str) -> None:
    """Keep ``old``, a flag renamed to ``new``, for one release as a clear error.

    ``meshlap CMD OLD ...`` prints ``meshlap: error: OLD: renamed; use NEW`` and exits 2;
    ``new`` is the replacement as users should read it, e.g. ``"--area (the area kind,
    barycentric|voronoi)"``. The old flag is hidden from ``--help``.
    """
    p.add_argument(
        old, action=_RenamedFlag, new=new, dest=f"renamed_{old.lstrip('-')}", help=argparse.SUPPRESS
    )
