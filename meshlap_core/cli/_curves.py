"""``--isolines N --curves FILE``: level curves of the per-vertex field a command writes
(``meshlap geodesic``'s distance, ``meshlap heat``'s u), as an OBJ of polylines
(``igl.isolines`` through :func:`meshlap_core.diffusion.isolines`)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from ..diffusion import isoline_values, isolines, save_polylines
from ..errors import MeshError
from ..options import MAX_ISOLINES
from ._sources import output


def add_curve_flags(p: argparse.ArgumentParser, field: str) -> None:
    """The two flags, naming the command's ``field`` in their help."""
    p.add_argument(
        "--isolines",
        type=int,
        default=0,
        help=f"number of level curves of the {field}, at most {MAX_ISOLINES} (with --curves)",
    )
    p.add_argument(
        "--curves",
        help=f"write the {field}'s level curves as an OBJ of polylines (with --isolines)",
    )


def curves_path(args: argparse.Namespace) -> Path | None:
    """The checked ``--curves`` file (``None``: no curves), before any work.

    Raises
    ------
    MeshError
        A negative count, one flag without the other, or a file that may not be written.
    """
    curves = output(args.curves, args.mesh, (".obj",), "--curves")
    if args.isolines < 0:
        raise MeshError(f"must be 0 or more, got {args.isolines}", "--isolines")
    if args.isolines > MAX_ISOLINES:  # (each level may cross every face: bounded first)
        raise MeshError(
            f"at most {MAX_ISOLINES} level curves (more than a window tells apart, and each "
            f"can cross every face), got {args.isolines}",
            "--isolines",
        )
    if (args.isolines > 0) != (curves is not None):
        raise MeshError("--isolines N and --curves FILE go together", "--isolines")
    return curves


def write_curves(
    args: argparse.Namespace,
    curves: Path | None,
    V: np.ndarray,
    F: np.ndarray,
    values: np.ndarray,
    result: dict[str, Any],
) -> None:
    """``--isolines`` evenly spaced level curves of ``values (n,)`` (finite range) to
    ``curves``; ``result`` gets ``curves`` and ``curve_segments``."""
    result["curves"] = str(curves) if curves else None
    if curves is None:
        return
    P, E, _ = isolines(V, F, values, isoline_values(values, args.isolines))
    save_polylines(curves, P, E, overwrite_inputs=(args.mesh,))
    result["curve_segments"] = len(E)
