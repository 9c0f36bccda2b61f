"""Section 2: uniform mean curvature and angle-deficit Gaussian curvature on ``lilium_s`` and
``plane``: value ranges, the Gauss–Bonnet check, histograms and colour maps."""

from __future__ import annotations

import math

import numpy as np

from ... import curvature, topology
from ...types import FloatArray, IntArray
from ..context import Context
from ..document import Section, num
from ..figures import new_figure
from .common import STAT_COLUMNS, stats_row

KEY = "uniform"
TITLE = "Uniform mean curvature and Gaussian curvature"
STEPS = (5, 6)  # progress steps (quick, full)


def _gauss_bonnet(V: FloatArray, F: IntArray) -> tuple[float, float]:
    """``(Σ K_i A_i, 2πχ)`` with the π boundary rule (the deficit already includes it)."""
    d = curvature.angle_deficit(V, F, "pi")
    return float(d.sum()), 2.0 * math.pi * topology.euler_characteristic(F, len(V))


def run(ctx: Context, sec: Section) -> None:
    """Write section 2 into ``sec``."""
    names = ["lilium_s", "plane"]
    sec.p(
        "Uniform mean curvature H = −½ (L_u x) · n with L_u = D⁻¹A − I (the course formula; "
        "negative semidefinite, Δx = −2Hn, so H > 0 where the surface bends away from its "
        "normal like a sphere), and angle-deficit Gaussian curvature K = (2π − Σθ)/A_i with "
        "the barycentric area (⅓ of the incident triangles). At a boundary vertex the deficit "
        "is π − Σθ (the `pi` rule), so that Σ K_i A_i = 2πχ (Gauss–Bonnet) holds exactly."
    )
    rows, gb_rows, fields = [], [], {}
    for name in names:
        m = ctx.mesh(name)
        f = curvature.all_curvature_fields(m.V, m.F)
        fields[name] = f
        bnd = topology.boundary_vertex_mask(m.F, len(m.V))
        for key, label in (("uniform", "H uniform"), ("gaussian", "K angle deficit")):
            rows.append([name, label, "all", len(m.V), *stats_row(f[key])])
            rows.append([name, label, "interior", int((~bnd).sum()), *stats_row(f[key][~bnd])])
        s, target = _gauss_bonnet(m.V, m.F)
        gb_rows.append(
            [name, topology.euler_characteristic(m.F, len(m.V)), s, target, abs(s - target)]
        )
        sec.p(f"Mesh `{name}`: {m.label}.")
    ctx.progress.step("curvature computed")
    sec.add(
        ctx.table(
            "uniform_ranges",
            "Value ranges (all vertices, then interior only).",
            ["mesh", "field", "vertices", "n", *STAT_COLUMNS],
            [[r[0], r[1], r[2], r[3], *r[4:]] for r in rows],
        )
    )
    sec.add(
        ctx.table(
            "gauss_bonnet",
            "Gauss–Bonnet check: Σ K_i A_i against 2πχ.",
            ["mesh", "euler_characteristic", "sum_K_A", "two_pi_chi", "abs_difference"],
            gb_rows,
        )
    )
    pl = ctx.mesh("plane")
    fpl = fields["plane"]
    bnd = topology.boundary_vertex_mask(pl.F, len(pl.V))
    flat = float(np.ptp(pl.V[:, 2])) == 0.0
    sec.p(
        f"Measured on `plane`{' (exactly flat: z is constant)' if flat else ''}: "
        f"max |H uniform| = {num(np.abs(fpl['uniform']).max())}; max |K| over interior "
        f"vertices = {num(np.abs(fpl['gaussian'][~bnd]).max() if (~bnd).any() else 0.0)}, "
        f"over boundary vertices = {num(np.abs(fpl['gaussian'][bnd]).max() if bnd.any() else 0)}"
        " (a flat boundary vertex has Σθ = π except at the corners of the patch, where the "
        "π rule leaves the turning angle of the boundary as K·A). Gauss–Bonnet: "
        + "; ".join(f"{r[0]}: Σ K_i A_i = {num(r[2], 6)} vs 2πχ = {num(r[3], 6)}" for r in gb_rows)
        + "."
    )
    _pictures(ctx, sec, names, fields)


def _pictures(ctx: Context, sec: Section, names: list[str], fields: dict[str, dict]) -> None:
    """Histograms of both fields on both meshes, then their colour maps."""
    fig = new_figure(10.0, 6.4)
    for i, name in enumerate(names):
        for j, (key, label) in enumerate((("uniform", "H uniform"), ("gaussian", "K deficit"))):
            ax = fig.add_subplot(2, 2, 2 * i + j + 1)
            v = fields[name][key]
            lo, hi = np.percentile(v, [1, 99])
            if hi <= lo:
                lo, hi = float(v.min()) - 0.5, float(v.max()) + 0.5
            ax.hist(np.clip(v, lo, hi), bins=60, color="tab:blue" if j == 0 else "tab:orange")
            ax.set_title(f"{name}: {label} (clipped to p01..p99)", fontsize=9)
            ax.set_ylabel("vertices")
            ax.tick_params(labelsize=8)
    fig.tight_layout()
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "uniform_histograms",
                "Histograms of uniform H and angle-deficit K (values clipped to the "
                "1st–99th percentile so that a few boundary values do not hide the "
                "rest; the table has the full ranges).",
            )
        ]
    )
    ctx.progress.step("histograms")
    shots = [("lilium_s", "uniform"), ("lilium_s", "gaussian"), ("plane", "gaussian")]
    if not ctx.quick:  # H uniform is exactly 0 on the flat plane: a one-colour map
        shots.insert(2, ("plane", "uniform"))
    figs = []
    for name, fld in shots:
        m = ctx.mesh(name)
        figs.append(
            ctx.shot_or_render(
                f"uniform_{name}_{fld}",
                f"{name}: {'H uniform' if fld == 'uniform' else 'K angle deficit'} (viewer colour "
                "map, range clipped at 2 % each end; the panel shows min/max and a histogram)",
                m,
                field=fld,
            )
        )
        ctx.progress.step(f"map {name} {fld}")
    sec.figs(figs)
