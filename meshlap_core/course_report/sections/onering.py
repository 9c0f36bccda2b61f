"""Section 1: the ordered one-ring of every vertex of the cube, checked face by face, with a
drawing of one ring and the viewer's one-ring panel."""

from __future__ import annotations

import itertools

import numpy as np

from ... import curvature, topology
from ...types import IntArray
from ..context import Context, StudyMesh
from ..document import Fig, Section
from ..figures import camera, draw_mesh, new_figure, view_dir

KEY = "onering"
TITLE = "Ordered one-ring on the cube"
STEPS = (3, 3)  # progress steps (quick, full)


def _ring_rows(ring: topology.OneRing, F: IntArray, n: int) -> tuple[list[list], bool]:
    """One table row per vertex, and whether every consecutive ccw pair (a, b) of every vertex
    v makes a face (v, a, b)."""
    faces = {tuple(np.roll(f, s)) for f in F.tolist() for s in range(3)}
    rows = []
    all_ok = True
    for v in range(n):
        nb = ring[v].tolist()
        pairs = list(zip(nb, nb[1:] + ([nb[0]] if not ring.boundary[v] else []), strict=False))
        ok = all((v, a, b) in faces for a, b in pairs)
        all_ok &= ok
        rows.append(
            [
                v,
                int(ring.valence[v]),
                "boundary" if ring.boundary[v] else "interior",
                " → ".join(map(str, nb)),
                " → ".join(map(str, ring.reversed()[v].tolist())),
                ok,
            ]
        )
    return rows, all_ok


def run(ctx: Context, sec: Section) -> None:
    """Write section 1 into ``sec``."""
    mesh = ctx.mesh("cube")
    V, F = mesh.V, mesh.F
    n = len(V)
    ring = topology.one_ring(F, n)
    rows, all_ok = _ring_rows(ring, F, n)
    ctx.progress.step("one-rings ordered")
    sec.p(
        f"Mesh: {mesh.label}. `topology.one_ring` orders the neighbours of every vertex at once. "
        "Counter-clockwise means: for consecutive neighbours (a, b) of v, (v, a, b) is a face of "
        "the mesh, so the order turns counter-clockwise seen from outside (the side the face "
        "normals point to). The last column checks exactly that, for every consecutive pair "
        "(including last → first on a closed cycle)."
    )
    sec.p(
        f"Measured: {'every' if all_ok else 'NOT every'} consecutive pair of all {n} one-rings "
        f"is a face (v, a, b) of the mesh; valences range from {int(ring.valence.min())} to "
        f"{int(ring.valence.max())} (a triangulated cube has corners of different valence)."
    )
    sec.add(
        ctx.table(
            "onering_cube",
            f"Ordered one-rings of every vertex of {mesh.name} (0-based indices).",
            ["vertex", "valence", "kind", "neighbours_ccw", "neighbours_cw", "ccw_pairs_are_faces"],
            rows,
        )
    )
    v0 = 0
    f1 = _ring_figure(ctx, mesh, ring, v0)
    ctx.progress.step("figure drawn")
    f2 = ctx.shot(
        "onering_cube_viewer",
        f"The viewer's one-ring panel on vertex {v0} (numbers are the order).",
        mesh=mesh,
        panel="onering",
        vertex=v0,
        use_file=True,
    )
    ctx.progress.step("screenshot")
    sec.figs([f1, f2])
    if f2 is None:
        sec.note(f"No viewer screenshot: {ctx.screenshot_reason}.")


def _ring_figure(ctx: Context, mesh: StudyMesh, ring: topology.OneRing, v0: int) -> Fig:
    """The one-ring of ``v0`` seen from outside along its normal, numbered in ccw order."""
    V, F = mesh.V, mesh.F
    nb = ring[v0]
    N = curvature.vertex_normals(V, F)
    fig = new_figure(6.4, 5.6)
    ax = fig.add_axes((0.02, 0.02, 0.96, 0.88))
    cam = camera(N[v0] + 0.25 * view_dir(25.0, -35.0))
    draw_mesh(ax, V, F, None, cam=cam, edges=True)
    P = V @ cam.T
    ax.plot(*P[v0, :2], "o", color="crimson", ms=12, zorder=5)
    ax.annotate(
        f"v{v0}",
        P[v0, :2],
        xytext=(9, -16),
        textcoords="offset points",
        color="crimson",
        fontsize=12,
        weight="bold",
    )
    ring_pts = P[nb, :2]
    cyc = np.vstack([ring_pts, ring_pts[:1]]) if not ring.boundary[v0] else ring_pts
    for a, b in itertools.pairwise(cyc):
        ax.annotate(
            "",
            b,
            a,
            arrowprops={"arrowstyle": "-|>", "color": "tab:blue", "lw": 2.2, "mutation_scale": 18},
            zorder=6,
        )
    for i, (w, pt) in enumerate(zip(nb.tolist(), ring_pts, strict=True)):
        ax.plot(*pt, "o", color="tab:blue", ms=9, zorder=7)
        ax.annotate(
            f"{i}: v{w}",
            pt,
            xytext=(7, 7),
            textcoords="offset points",
            fontsize=12,
            color="navy",
            weight="bold",
            zorder=8,
        )
    fig.suptitle(
        f"{mesh.name}: one-ring of vertex {v0}, seen from outside along its normal\n"
        "neighbours numbered 0, 1, 2, … in counter-clockwise order",
        fontsize=11,
    )
    return ctx.save_fig(
        fig,
        "onering_cube",
        f"The one-ring of vertex {v0} seen from outside: position i in the "
        "order is labelled 'i: v<index>' (0-based, as in the viewer) and the "
        "arrows follow the order, counter-clockwise.",
    )
