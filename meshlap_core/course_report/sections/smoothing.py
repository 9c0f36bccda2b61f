"""Section 6: explicit and implicit smoothing of ``plane_ns`` and ``fandisk_ns`` with the
uniform and cotangent Laplacians: stability numbers (μ_min, the explicit limit, the gain of the
highest frequency) against what the runs did, histories, gain curves and pictures."""

from __future__ import annotations

import math
import re
import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ... import metrics, smoothing
from ...errors import MeshWarning
from ...options import EULER_METHODS, LAPLACIAN_KINDS
from ...types import FloatArray
from ..context import Context, StudyMesh
from ..document import Section, num
from ..figures import new_figure

KEY = "smoothing"
TITLE = "Explicit and implicit smoothing"
STEPS = (11, 17)  # progress steps (quick, full)

# (mesh, laplacian, method, label, lam / limit, predicted stable, smoothed V)
_Shot = tuple[str, str, str, str, float, bool, FloatArray]


@dataclass
class _Runs:
    """Every smoothing run: table rows, histories by (mesh, laplacian, method, λ), the explicit
    limit and μ_min by (mesh, laplacian), and the results worth a picture."""

    rows: list[list] = field(default_factory=list)
    hist: dict[tuple[str, str, str, float], list[dict]] = field(default_factory=dict)
    limits: dict[tuple[str, str], float] = field(default_factory=dict)
    mus: dict[tuple[str, str], float] = field(default_factory=dict)
    shots: list[_Shot] = field(default_factory=list)


def _lam_grid(ctx: Context, lap: str, method: str, limit: float) -> list[float]:
    """Step sizes: the uniform λ is dimensionless; the cotan λ (units of length²) is given as a
    multiple of the explicit stability limit 2/|μ_min| measured on the mesh. The explicit grid
    ends above the limit (1.1× and 2×) on purpose."""
    if method == "explicit":
        if lap == "uniform":
            return (
                [0.5, 1.0, round(1.1 * limit, 3), round(2.0 * limit, 3)]
                if ctx.quick
                else [0.25, 0.5, 1.0, round(1.1 * limit, 3), round(2.0 * limit, 3)]
            )
        fr = (0.5, 0.9, 1.1, 2.0) if ctx.quick else (0.25, 0.5, 0.9, 1.1, 2.0)
        return [f * limit for f in fr]
    if lap == "uniform":
        return [1.0, 10.0] if ctx.quick else [0.5, 1.0, 5.0, 20.0]
    return [f * limit for f in ((1.0, 10.0) if ctx.quick else (1.0, 5.0, 20.0, 100.0))]


def run(ctx: Context, sec: Section) -> None:
    """Write section 6 into ``sec``."""
    iters = 20 if ctx.quick else 50
    sec.p(
        "One iteration is x′ = x + λLx (explicit, forward Euler) or (I − λL)x′ = x (implicit, "
        "backward Euler, solved as (W − λK)x′ = Wx with a sparse Cholesky factorization reused "
        "for every step), with L = W⁻¹K negative semidefinite: uniform L = D⁻¹A − I or "
        "cotangent L = M⁻¹C (Voronoi areas, frozen). A mode of L with eigenvalue μ ≤ 0 is "
        "multiplied by g = 1 + λμ (explicit) or 1/(1 − λμ) (implicit) per step, so explicit "
        "smoothing is stable iff λ ≤ 2/|μ_min|; μ_min is computed on each mesh (Lanczos). The "
        "uniform λ is dimensionless; the cotangent λ has units of length², so it is given here "
        f"as a multiple of the explicit limit. Boundary vertices are free. {iters} iterations "
        "each."
    )
    runs = _run_all(ctx, sec, iters)
    _stability_table(ctx, sec, runs.rows)
    _stability_text(sec, runs, iters)
    _history_figs(ctx, sec, runs)
    _gain_fig(ctx, sec, runs.mus)
    ctx.progress.step("plots")
    _pictures(ctx, sec, runs.shots, iters)


def _run_all(ctx: Context, sec: Section, iters: int) -> _Runs:
    """Every (mesh, Laplacian, method, λ) of the grid, ``iters`` steps each."""
    runs = _Runs()
    for name in ("plane_ns", "fandisk_ns"):
        m = ctx.mesh(name)
        sec.p(f"Mesh `{name}`: {m.label}.")
        for lap in LAPLACIAN_KINDS:
            # μ_min once per mesh and Laplacian; the gains of every λ follow from it
            W, K = smoothing.operator_parts(m.V, m.F, lap)
            mu_min, _exact = smoothing.most_negative_eigenvalue(W, K)
            runs.mus[(name, lap)] = mu_min
            limit = 2.0 / abs(mu_min) if mu_min < 0 else math.inf
            runs.limits[(name, lap)] = limit
            mu_grid = np.linspace(mu_min, 0.0, 257)
            for method in EULER_METHODS:
                for lam in _lam_grid(ctx, lap, method, limit):
                    row, history, shot = _one_run(
                        m, lap, method, lam, mu_min, mu_grid, limit, iters
                    )
                    runs.rows.append(row)
                    runs.hist[(name, lap, method, lam)] = history
                    if shot is not None:
                        runs.shots.append(shot)
                ctx.progress.step(f"{name} {lap} {method}")
    return runs


def _one_run(
    m: StudyMesh,
    lap: str,
    method: str,
    lam: float,
    mu_min: float,
    mu_grid: FloatArray,
    limit: float,
    iters: int,
) -> tuple[list, list[dict], _Shot | None]:
    """One run: its table row, its history, and the picture data unless it diverged
    (``mu_grid`` samples [μ_min, 0])."""
    name = m.name
    gain = float(smoothing.amplification_curve(method, lam, [mu_min])[0])
    radius = float(np.abs(smoothing.amplification_curve(method, lam, mu_grid)).max())
    stable = abs(gain) <= 1.0 + 1e-12
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshWarning)
        s = smoothing.Smoother(m.V, m.F, method, lap, lam, warn=False)
    t0 = time.perf_counter()
    s.run(iters)
    dt = time.perf_counter() - t0
    last = s.history[-1]
    row = [
        name,
        lap,
        method,
        lam,
        lam / limit,
        mu_min,
        limit,
        gain,
        radius,
        stable,
        s.iteration,
        s.diverged,
        last["drift_rms"],
        last["volume_change_pct"],
        1e3 * dt / max(s.iteration, 1),
    ]
    if s.diverged:
        return row, s.history, None
    label = f"{method} {lap} λ = {num(lam)}"
    return row, s.history, (name, lap, method, label, lam / limit, stable, s.V.copy())


def _stability_table(ctx: Context, sec: Section, rows: list[list]) -> None:
    """The table of every run's stability numbers and end state."""
    sec.add(
        ctx.table(
            "smoothing_stability",
            "Stability numbers and the state after the iterations. μ_min is the most negative "
            "eigenvalue of L (`smoothing.most_negative_eigenvalue`); high_freq_gain = g(μ_min) "
            "(`smoothing.amplification_curve`), the factor applied to the highest frequency each "
            "step; spectral_radius = max |g| over [μ_min, 0]; stable = |g(μ_min)| ≤ 1; "
            "lam_over_limit = λ / (2/|μ_min|); volume change is undefined (—) on an open mesh.",
            [
                "mesh",
                "laplacian",
                "method",
                "lam",
                "lam_over_limit",
                "mu_min",
                "explicit_lam_limit",
                "high_freq_gain",
                "spectral_radius",
                "stable",
                "iterations",
                "diverged",
                "drift_rms",
                "volume_change_pct",
                "ms_per_step",
            ],
            rows,
        )
    )


def _stability_text(sec: Section, runs: _Runs, iters: int) -> None:
    """What the runs did against what the gains predicted, in one paragraph."""
    rows, limits = runs.rows, runs.limits
    unstable = [r for r in rows if not r[9]]
    div = [r for r in unstable if r[11]]
    div_stable = [r for r in rows if r[9] and r[11]]
    impl_ok = not any(r[11] for r in rows if r[2] == "implicit")
    impl_max = max((r[4] for r in rows if r[2] == "implicit"), default=float("nan"))
    sec.p(
        f"Measured: {len(unstable)} of {len(rows)} runs are predicted unstable "
        f"(|g(μ_min)| > 1), all explicit with λ above 2/|μ_min|; {len(div)} of them blew up "
        f"within {iters} iterations (the stepper stops at the first runaway step: "
        + (
            ", ".join(f"{r[0]} {r[1]} λ = {num(r[3])} after {r[10]} steps" for r in div[:4])
            or "none"
        )
        + ("" if len(div) <= 4 else ", …")
        + "); "
        + (
            f"{len(div_stable)} predicted-stable runs diverged. "
            if div_stable
            else "no predicted-stable run diverged. "
        )
        + (
            f"No implicit run diverged, up to λ = {impl_max:.3g}× the explicit limit "
            "(g = 1/(1 − λμ) lies in (0, 1] for every λ). "
            if impl_ok
            else "Some implicit run diverged (unexpected); see the table. "
        )
        + "Explicit limits 2/|μ_min|: "
        + "; ".join(f"{nm} {lap}: {num(lim)}" for (nm, lap), lim in limits.items())
        + ". The uniform limit is at least 1 on any mesh (μ_min ≥ −2); the cotangent one has "
        "units of length² and shrinks with the square of the shortest edges."
    )


def _history_figs(ctx: Context, sec: Section, runs: _Runs) -> None:
    """Per mesh: displacement (and volume, if closed) against iteration for every run."""
    hist_figs = []
    for name in ("plane_ns", "fandisk_ns"):
        closed = ctx.mesh(name).F is not None and metrics.is_closed(ctx.mesh(name).F)
        panels = [
            ("drift_rms", "RMS displacement from the input", True),
            ("step_rms", "RMS displacement of each step", True),
        ]
        if closed:
            panels.append(("volume_change_pct", "volume change %", False))
        fig = new_figure(4.3 * len(panels), 6.4)
        for i, lap in enumerate(LAPLACIAN_KINDS):
            hist = {k: h for k, h in runs.hist.items() if k[0] == name and k[1] == lap}
            for j, (key, label, logy) in enumerate(panels):
                ax = fig.add_subplot(2, len(panels), i * len(panels) + j + 1)
                _history_axis(ax, hist, key, logy, runs.limits[(name, lap)])
                ax.set_title(f"{name}, {lap}: {label}", fontsize=9)
                ax.set_xlabel("iteration", fontsize=8)
                ax.grid(alpha=0.3)
                ax.tick_params(labelsize=7)
                if j == 0:
                    ax.legend(fontsize=5.5, ncol=1)
        fig.tight_layout()
        hist_figs.append(
            ctx.save_fig(
                fig,
                f"smoothing_history_{name}",
                f"{name}: per iteration, displacement from the input and of each step (it grows "
                "where a run is unstable)"
                + (
                    ", and volume change (y range set by the stable runs)"
                    if closed
                    else "; volume is undefined on an open mesh"
                )
                + ". Dashed reds: explicit, solid blues: implicit, darker = larger λ.",
            )
        )
    sec.figs(hist_figs)


def _history_axis(
    ax: Any,
    hist: dict[tuple[str, str, str, float], list[dict]],
    key: str,
    logy: bool,
    limit: float,
) -> None:
    """One history panel of one mesh and Laplacian: ``key`` against iteration, explicit runs in
    reds, implicit in blues, darker for larger λ (a linear y range is set by the stable runs)."""
    import matplotlib as mpl

    finite_stable = []
    for method, cmap, style in (("explicit", "Reds", "--"), ("implicit", "Blues", "-")):
        by_lam = {k[3]: h for k, h in hist.items() if k[2] == method}
        lams = sorted(by_lam)
        for q, lam in enumerate(lams):
            h = by_lam[lam]
            pts = [
                (e["iteration"], e[key])
                for e in h
                if e[key] is not None and (not logy or e[key] > 0)
            ]
            if not pts:
                continue
            it, y = zip(*pts, strict=True)
            colour = mpl.colormaps[cmap](0.35 + 0.6 * q / max(len(lams) - 1, 1))
            rel = lam / limit
            ax.plot(
                it,
                y,
                style,
                color=colour,
                lw=1.3,
                label=f"{method[:4]} λ={num(lam, 2)} ({rel:.2g}× limit)",
            )
            if rel <= 1.0 or method == "implicit":
                finite_stable.extend(y)
    if not logy and finite_stable:
        lo, hi = min(finite_stable), max(finite_stable)
        pad = 0.08 * (hi - lo or 1.0)
        ax.set_ylim(lo - pad, hi + pad)
    if logy:
        ax.set_yscale("log")


def _gain_fig(ctx: Context, sec: Section, mus: dict[tuple[str, str], float]) -> None:
    """The gain per step against frequency for a few λ (uniform Laplacian of fandisk_ns)."""
    mu_min = mus[("fandisk_ns", "uniform")]
    mu = np.linspace(mu_min, 0.0, 400)
    fig = new_figure(6.5, 3.8)
    ax = fig.add_subplot(1, 1, 1)
    for method, lam, style in (
        ("explicit", 0.5, "--"),
        ("explicit", 1.0, "--"),
        ("explicit", round(1.1 * 2 / abs(mu_min), 3), "--"),
        ("implicit", 1.0, "-"),
        ("implicit", 10.0, "-"),
    ):
        ax.plot(
            -mu,
            smoothing.amplification_curve(method, lam, mu),
            style,
            label=f"{method} λ = {lam:g}",
        )
    ax.axhline(1, color="0.5", lw=0.7)
    ax.axhline(-1, color="0.5", lw=0.7)
    ax.set_xlabel("frequency −μ of the uniform Laplacian")
    ax.set_ylabel("gain g per step")
    ax.set_title(f"fandisk_ns: amplification (μ_min = {mu_min:.4g})", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "smoothing_gain",
                "Gain per step against frequency: outside "
                "the band [−1, 1] a mode grows; explicit λ above 2/|μ_min| leaves it "
                "at the highest frequencies.",
            )
        ]
    )


def _pictures(ctx: Context, sec: Section, shots: list[_Shot], iters: int) -> None:
    """Per mesh and Laplacian, the largest stable explicit run and a middle implicit one
    (quick: fandisk_ns with the uniform Laplacian only)."""
    figs = []
    for name in ("plane_ns", "fandisk_ns") if not ctx.quick else ("fandisk_ns",):
        mesh = ctx.mesh(name)
        if not ctx.quick:
            figs.append(ctx.shot_or_render(f"smoothing_{name}_input", f"{name}: input", mesh))
        for lap in LAPLACIAN_KINDS if not ctx.quick else ("uniform",):
            for meth in EULER_METHODS:
                c = sorted(
                    (s for s in shots if s[0] == name and s[1] == lap and s[2] == meth and s[5]),
                    key=lambda s: s[4],
                )
                if not c:
                    continue
                # explicit: the largest stable λ; implicit: the middle of the grid (the largest
                # flattens and shrinks the mesh beyond recognition)
                _n, _l, _m, label, ratio, _st, Vs = c[-1] if meth == "explicit" else c[len(c) // 2]
                key = re.sub(r"[^a-z0-9]+", "_", f"{name}_{meth}_{lap}").strip("_")
                figs.append(
                    ctx.shot_or_render(
                        f"smoothing_{key}",
                        f"{name} after {iters} iterations: {label} "
                        f"({ratio:.3g}× the explicit limit; coloured by cotangent H)",
                        V=Vs,
                        F=mesh.F,
                        label=f"{name}_{meth}_{lap}_{iters}",
                    )
                )
                ctx.progress.step(f"picture {name} {lap} {meth}")
    sec.figs(figs)
