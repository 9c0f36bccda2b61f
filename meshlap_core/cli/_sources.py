"""What the diffusion commands (``geodesic``, ``heat``, ``filter``) share: the ``--vertex``
flag, named like ``inspect`` and ``onering`` (0-based, after the loader's repairs), and the
output path checks made before any work."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..diffusion import check_sources
from ..errors import MeshError
from ..io import check_output_path


def add_vertex_flag(p: argparse.ArgumentParser, several: bool = True) -> None:
    """``--vertex I`` (required; repeatable when ``several``)."""
    p.add_argument(
        "--vertex",
        type=int,
        action="append" if several else "store",
        required=True,
        help="source vertex index (0-based, after repairs)"
        + ("; repeat for several" if several else ""),
    )


def vertices(args: argparse.Namespace, n: int) -> np.ndarray:
    """The ``--vertex`` values checked against ``n`` vertices (errors name ``--vertex``)."""
    return check_sources(args.vertex, n, "--vertex")


def output(path: str | None, mesh: str, suffixes: tuple[str, ...], flag: str) -> Path | None:
    """The output path checked before the work (``None`` when not asked)."""
    if path is None:
        return None
    if not path.strip():
        raise MeshError(f"the output path is empty (give a file name or leave {flag} out)", flag)
    return check_output_path(Path(path), overwrite_inputs=(mesh,), suffixes=suffixes)
