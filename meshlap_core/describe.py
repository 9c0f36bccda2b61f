"""The figures ``meshlap info`` prints and the viewer's Mesh panel shows."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import topology
from .errors import MeshError
from .laplacian import face_areas
from .types import FloatArray, IntArray, as_mesh


def mesh_info(
    V: FloatArray, F: IntArray, report: Any = None, source: str | None = None
) -> dict[str, Any]:
    """Counts, bounding box, boundary, components, χ, genus, manifoldness and repairs.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    report : MeshReport, optional
        The validator's report (repairs, warnings, manifoldness, orientation).
    source : str, optional
        File name to include.

    Returns
    -------
    info : dict
        JSON-ready values; ``genus`` is ``None`` (with ``genus_note``) when the mesh is not a
        manifold surface.
    """
    V, F = as_mesh(V, F)
    n, m = len(V), len(F)
    lo, hi = V.min(axis=0), V.max(axis=0)
    n_comp, _ = topology.connected_components(F, n)
    E, count = topology.edge_face_counts(F)
    info: dict[str, Any] = {
        "file": source,
        "n_vertices": n,
        "n_faces": m,
        "n_edges": len(E),
        "bbox_min": lo.tolist(),
        "bbox_max": hi.tolist(),
        "bbox_diagonal": float(np.linalg.norm(hi - lo)),
        "surface_area": float(face_areas(V, F).sum()),
        "n_components": n_comp,
        "n_boundary_edges": int(np.sum(count == 1)),
        "n_nonmanifold_edges": int(np.sum(count > 2)),
        "euler_characteristic": topology.euler_characteristic(F),
    }
    try:
        loops = topology.boundary_loops(F)
        info["n_boundary_loops"] = len(loops)
        info["boundary_loop_lengths"] = [len(lp) for lp in loops]
    except MeshError as exc:
        info["n_boundary_loops"] = None
        info["boundary_loop_lengths"] = None
        info["boundary_note"] = exc.problem
    try:
        info["genus"] = topology.genus(F)
    except MeshError as exc:
        info["genus"] = None
        info["genus_note"] = exc.problem
    info["closed"] = info["n_boundary_edges"] == 0
    if report is not None:
        info["n_nonmanifold_vertices"] = int(report.n_nonmanifold_vertices)
        info["manifold"] = bool(report.is_manifold)
        info["consistently_oriented"] = bool(report.consistently_oriented)
        info["repairs"] = list(report.repairs)
        info["warnings"] = list(report.warnings)
    else:
        ring = topology.one_ring(F, n)
        info["manifold"] = bool(ring.regular.all() and info["n_nonmanifold_edges"] == 0)
        info["repairs"] = []
        info["warnings"] = []
    return info


def format_info(info: dict[str, Any]) -> str:
    """Human-readable lines for :func:`mesh_info`."""
    lines = []
    if info.get("file"):
        lines.append(f"file              {info['file']}")
    lines += [
        f"vertices          {info['n_vertices']}",
        f"faces             {info['n_faces']}",
        f"edges             {info['n_edges']}",
        "bounding box      "
        + " .. ".join(
            "(" + ", ".join(f"{x:.4g}" for x in b) + ")"
            for b in (info["bbox_min"], info["bbox_max"])
        ),
        f"bbox diagonal     {info['bbox_diagonal']:.6g}",
        f"surface area      {info['surface_area']:.6g}",
        f"components        {info['n_components']}",
        f"boundary loops    {info['n_boundary_loops']}"
        + (
            f" (lengths {info['boundary_loop_lengths']})"
            if info.get("boundary_loop_lengths")
            else ""
        ),
        f"Euler char. χ     {info['euler_characteristic']}",
        "genus             "
        + (
            str(info["genus"])
            if info["genus"] is not None
            else f"undefined ({info.get('genus_note')})"
        ),
        f"manifold          {'yes' if info.get('manifold') else 'no'}"
        + (
            f" ({info['n_nonmanifold_edges']} non-manifold edges)"
            if info["n_nonmanifold_edges"]
            else ""
        ),
    ]
    if "consistently_oriented" in info:
        how = "consistently" if info["consistently_oriented"] else "INCONSISTENTLY"
        lines.append(f"oriented          {how}")
    for r in info.get("repairs", []):
        lines.append(f"repaired          {r}")
    for w in info.get("warnings", []):
        lines.append(f"warning           {w}")
    return "\n".join(lines)
