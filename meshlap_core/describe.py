"""The figures ``meshlap info`` prints and the viewer's Mesh panel shows."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import topology
from .errors import MeshError
from .laplacian import face_areas
from .types import FloatArray, IntArray, as_mesh


def mesh_info(
    V: FloatArray,
    F: IntArray,
    report: Any = None,
    source: str | None = None,
    table: Any = None,
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
    table : EdgeTable, optional
        The edge table of ``F`` (``Mesh.edge_table``), reused instead of rebuilt.

    Returns
    -------
    info : dict
        JSON-ready values; ``genus`` is ``None`` (with ``genus_note``) when the mesh is not a
        manifold surface.

    Examples
    --------
    >>> from meshlap_core import icosphere, mesh_info
    >>> info = mesh_info(*icosphere(2))
    >>> info["n_vertices"], info["n_faces"], info["n_edges"]
    (162, 320, 480)
    >>> info["euler_characteristic"], info["genus"], info["closed"]  # V − E + F = 2 − 2g
    (2, 0, True)
    """
    V, F = as_mesh(V, F)
    n, m = len(V), len(F)
    if n == 0:
        raise MeshError("the mesh has no vertices", source or "V")
    lo, hi = V.min(axis=0), V.max(axis=0)
    summary = topology.surface_summary(F, n, table=table)
    info: dict[str, Any] = {
        "file": source,
        "n_vertices": n,
        "n_faces": m,
        "n_edges": summary["n_edges"],
        "bbox_min": lo.tolist(),
        "bbox_max": hi.tolist(),
        "bbox_diagonal": float(np.linalg.norm(hi - lo)),
        "surface_area": float(face_areas(V, F).sum()),
        "n_components": summary["n_components"],
        "n_boundary_edges": summary["n_boundary_edges"],
        "n_nonmanifold_edges": summary["n_nonmanifold_edges"],
        "euler_characteristic": summary["euler_characteristic"],
        "n_boundary_loops": summary["n_boundary_loops"],
        "boundary_loop_lengths": summary["boundary_loop_lengths"],
    }
    if "boundary_note" in summary:
        info["boundary_note"] = summary["boundary_note"]
    info["genus"] = summary["genus"]
    if "genus_note" in summary:
        info["genus_note"] = summary["genus_note"]
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
            f" (lengths {_short_list(info['boundary_loop_lengths'])})"
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


def _short_list(values: list[Any], shown: int = 10) -> str:
    """``[3, 4, 5]``, or the first ``shown`` values and how many more (``--json`` has all)."""
    if len(values) <= shown:
        return str(list(values))
    head = ", ".join(str(v) for v in values[:shown])
    return f"[{head}, ... {len(values) - shown:,} more]"
