"""One handle set built: seeds grown into geodesic discs, the region held, and one deformer
per shown method (any thread: :func:`build_set` touches no state; no polyscope).

The slow part of a drag (the discs' exact geodesics, the farthest region, each method's
operators and factorization) happens here once per handle set; the Deform panel runs it as a
job with progress and Cancel.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshlap_core.deform import (
    Deformer,
    HandleRegions,
    edge_graph,
    farthest_region,
    grow_handles,
    make_deformer,
)
from meshlap_core.types import FloatArray, IntArray

from .moves import diagonal


@dataclass
class Built:
    """What a build job made for one handle set (any thread; adopted on the UI thread).

    Attributes
    ----------
    key : tuple
        What it was built from (:meth:`DeformState.setup_key`).
    regions : HandleRegions
        The seeds' discs.
    fixed : (f,) int
        The vertices held at rest.
    deformers : dict
        method name -> its :class:`~meshlap_core.deform.Deformer`.
    region_of : dict
        method name -> ``(h,)`` the seed index of each of that deformer's handles (its order).
    graph : sparse matrix
        The mesh's edge graph (kept for the next build).
    seconds : float
        The whole build.
    """

    key: tuple[Any, ...]
    regions: HandleRegions
    fixed: IntArray
    deformers: dict[str, Deformer]
    region_of: dict[str, IntArray]
    graph: Any
    seconds: float


def build_set(
    V: FloatArray,
    F: IntArray,
    key: tuple[Any, ...],
    graph: Any = None,
    progress: Any = None,
    cancel: Any = None,
) -> Built:
    """Grow the handles, find the fixed region and build each method's deformer (any thread:
    touches no state; ``progress(fraction, message)`` and ``cancel`` between phases).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    key : tuple
        :meth:`DeformState.setup_key`: ``(mesh version, methods, seeds, radius %, fixed
        region, fixed seeds, share, ARAP energy)``.
    """
    t0 = time.perf_counter()
    _, methods, seeds, radius, region, fixed_seeds, share, energy = key

    def report(fraction: float, message: str) -> None:
        if progress is not None:
            progress(fraction, message)

    report(0.0, "edge graph")
    if graph is None:
        graph = edge_graph(V, F)
    r = radius / 100.0 * diagonal(V)
    report(0.05, f"growing {len(seeds)} handle disc(s)")
    regions = grow_handles(V, F, list(seeds), r, graph=graph, cancel=cancel)
    if region == "farthest":
        report(0.15, "the farthest region")
        fixed = farthest_region(V, F, regions.vertices, share, graph=graph)
    elif region == "clicked" and fixed_seeds:
        held = grow_handles(V, F, list(fixed_seeds), r, graph=graph, cancel=cancel).vertices
        fixed = np.setdiff1d(held, regions.vertices).astype(np.int64)
    else:
        fixed = np.zeros(0, dtype=np.int64)
    deformers: dict[str, Deformer] = {}
    region_of: dict[str, IntArray] = {}
    share_each = 0.8 / max(len(methods), 1)
    for k, method in enumerate(methods):
        lo = 0.2 + k * share_each

        def sub(fraction: float, message: str = "", lo: float = lo, name: str = method) -> None:
            report(lo + share_each * float(fraction or 0.0), f"{name}: {message}")

        opts = {"energy": energy} if method == "arap" else {}
        d = make_deformer(
            method, V, F, regions.vertices, fixed, progress=sub, cancel=cancel, **opts
        )
        deformers[method] = d
        slot = np.searchsorted(regions.vertices, d.handles)
        region_of[method] = regions.region[slot]
    report(1.0, "ready")
    return Built(key, regions, fixed, deformers, region_of, graph, time.perf_counter() - t0)


def close_set(built: Any) -> None:
    """End a handle set's child process, if it has one."""
    close = getattr(built, "close", None)
    if close is not None:
        close()
