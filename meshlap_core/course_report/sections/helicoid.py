"""Section 3: the helicoid at the origin (fundamental forms, normal curvature, principal
curvatures, in the project's sign: positive where the surface bends away from n, and in the
coursework's, do Carmo's ``e = p_uu · n``) and the convergence of the discrete H and K on meshed
helicoid, sphere and torus against their closed forms."""

from __future__ import annotations

import math

import numpy as np

from ... import surfaces
from ...curvature.convergence import ConvergenceStudy, convergence_study
from ..context import Context
from ..document import Fig, Section, num
from ..figures import new_figure

KEY = "helicoid"
TITLE = "The helicoid, and convergence of discrete H and K"
STEPS = (5, 6)  # progress steps (quick, full)


def run(ctx: Context, sec: Section) -> None:
    """Write section 3 into ``sec``."""
    _origin(ctx, sec)
    _convergence(ctx, sec)


def _origin(ctx: Context, sec: Section) -> None:
    """The helicoid at the origin: tables against the closed forms, κₙ(θ), the viewer."""
    geo = surfaces.point_geometry("helicoid", 0.0, 0.0)
    sec.p(
        "Helicoid p(u, v) = (u cos v, u sin v, v) (c = 1) at the origin (u, v) = (0, 0). "
        "Signs are the project's, the same in `meshlap_core.surfaces` and on meshes: "
        "n = p_u × p_v / |p_u × p_v| and e = −p_uu · n, f = −p_uv · n, g = −p_vv · n (do "
        "Carmo's II negated), so a sphere with its outward normal has H > 0, as the mesh "
        "code's Δx = −2Hn; K does not depend on the sign. "
        "The closed forms below for c = 1: E = 1, F = 0, G = 1 + u², "
        "e = g = 0, f = 1/√(1+u²), K = −1/(1+u²)², κ = ±1/(1+u²), κₙ(θ) = sin 2θ at u = 0. "
        "Angles θ are measured in the tangent plane from the unit p_u direction towards "
        "n × p_u (at the origin I is the identity, so they equal the (u, v) angles)."
    )
    exact = {
        "E": 1.0,
        "F": 0.0,
        "G": 1.0,
        "e": 0.0,
        "f": 1.0,
        "g": 0.0,
        "K": -1.0,
        "H": 0.0,
        "k1": 1.0,
        "k2": -1.0,
    }
    rows = [[k, getattr(geo, k), exact[k], abs(getattr(geo, k) - exact[k])] for k in exact]
    rows += [
        [
            "theta_max (deg)",
            math.degrees(geo.theta_max),
            45.0,
            abs(math.degrees(geo.theta_max) - 45.0),
        ],
        [
            "theta_min (deg)",
            math.degrees(geo.theta_min),
            135.0,
            abs(math.degrees(geo.theta_min) - 135.0),
        ],
    ]
    sec.add(
        ctx.table(
            "helicoid_origin",
            "First and second fundamental forms and curvatures of the helicoid at the "
            "origin (H > 0 on spheres), computed against the closed forms.",
            ["quantity", "computed", "closed_form", "abs_difference"],
            rows,
        )
    )
    dev = _principal(ctx, sec)
    sec.p(
        f"Measured: at the origin the point is {geo.classification} with κ₁ = {num(geo.k1)} "
        f"at θ = {math.degrees(geo.theta_max):.1f}° and κ₂ = {num(geo.k2)} at "
        f"θ = {math.degrees(geo.theta_min):.1f}°; the sampled κₙ(θ) differs from sin 2θ by at "
        f"most {num(dev)} over 721 angles."
    )
    _origin_figures(ctx, sec)
    _coursework(ctx, sec)


def _coursework(ctx: Context, sec: Section) -> None:
    """The coursework's numbers: do Carmo's sign ``e = p_uu · n`` (meshlap's ``signs=
    "do-carmo"``) at the origin and at (0.8, 0.3), against their closed forms, and its κₙ
    figure at the origin."""
    sign = "do-carmo"
    rows = []
    for u, v in ((0.0, 0.0), (0.8, 0.3)):
        w = 1.0 + u * u
        dc = surfaces.point_geometry("helicoid", u, v, signs=sign)
        out = surfaces.point_geometry("helicoid", u, v)
        theta_uv = math.degrees(math.atan(1.0 / math.sqrt(w)))  # tan θ_uv = tan 45° / √G
        closed = {
            "e": 0.0,
            "f": -1.0 / math.sqrt(w),
            "g": 0.0,
            "K": -1.0 / w**2,
            "H": 0.0,
            "k1": 1.0 / w,
            "k2": -1.0 / w,
            "theta_max (deg, tangent plane)": 135.0,
            "theta_min (deg, tangent plane)": 45.0,
            "theta_uv_max (deg, (u, v) plane)": 180.0 - theta_uv,
            "theta_uv_min (deg, (u, v) plane)": theta_uv,
        }
        for q, exact in closed.items():
            key = q.split(" ")[0]
            got, ours = getattr(dc, key), getattr(out, key)
            if q.startswith("theta"):
                got, ours = math.degrees(got), math.degrees(ours)
            rows.append([u, v, q, sign, got, exact, abs(got - exact), ours])
    theta, kn = surfaces.normal_curvature_curve("helicoid", 0.0, 0.0, 721, signs=sign)
    dev = float(np.abs(kn + np.sin(2 * theta)).max())
    sec.p(
        "The coursework's sign. The coursework this lab grew from follows do Carmo: "
        "e = p_uu · n, f = p_uv · n, g = p_vv · n with the same n = p_u × p_v / |p_u × p_v|, "
        "i.e. II with the opposite sign. Then the helicoid has f = −1/√(1+u²) and, at the "
        "origin, κₙ(θ) = −sin 2θ, largest (κ₁ = 1) at θ = 3π/4 (135°) and smallest at π/4. "
        "meshlap gives these numbers with `meshlap surface helicoid --signs do-carmo` "
        '(`point_geometry(..., signs="do-carmo")`); the table below is computed so '
        "(signs = do-carmo) beside meshlap's own sign (the last column). II, the shape "
        "operator, H, κₙ change sign between the two, κ₁ and κ₂ become −κ₂ and −κ₁ (so their "
        "directions swap), K, n and the classification do not."
    )
    sec.add(
        ctx.table(
            "helicoid_coursework",
            "The helicoid in the coursework's sign (do Carmo's e = p_uu · n), against the "
            "closed forms, with meshlap's outward sign beside it.",
            ["u", "v", "quantity", "signs", "computed", "closed_form", "abs_difference", "outward"],
            rows,
        )
    )
    path = ctx.fig_dir / "helicoid_kn_do_carmo.png"
    surfaces.plot_normal_curvature("helicoid", 0.0, 0.0, path, signs=sign)
    ctx.figures.append(path)
    sec.p(
        f"Measured in the coursework's sign: the sampled κₙ(θ) at the origin differs from "
        f"−sin 2θ by at most {num(dev)} over 721 angles."
    )
    sec.figs(
        [
            Fig(
                ctx.rel(path),
                "κₙ(θ) of the helicoid at the origin in the coursework's sign (do Carmo's, "
                "signs: do-carmo): −sin 2θ, maximum κ₁ = 1 at θ = 3π/4.",
            )
        ]
    )


def _principal(ctx: Context, sec: Section) -> float:
    """The principal-curvature table at three points; returns max |κₙ(θ) − sin 2θ| at 0."""
    theta, kn = surfaces.normal_curvature_curve("helicoid", 0.0, 0.0, 721)
    dev = float(np.abs(kn - np.sin(2 * theta)).max())
    pts = []
    for u, v in ((0.0, 0.0), (0.5, 1.0), (1.0, 2.0)):
        g = surfaces.point_geometry("helicoid", u, v)
        k_exact = 1.0 / (1.0 + u * u)
        pts.append(
            [
                u,
                v,
                g.k1,
                g.k2,
                k_exact,
                -k_exact,
                g.K,
                -1.0 / (1 + u * u) ** 2,
                g.H,
                g.H,  # one convention: the mesh code's H is the surface's
                g.classification,
            ]
        )
    sec.add(
        ctx.table(
            "helicoid_principal",
            "Principal curvatures along the helicoid (κ₁ ≥ κ₂; H_core = H_surfaces).",
            [
                "u",
                "v",
                "k1",
                "k2",
                "k1_exact",
                "k2_exact",
                "K",
                "K_exact",
                "H_surfaces",
                "H_core_sign",
                "classification",
            ],
            pts,
        )
    )
    return dev


def _origin_figures(ctx: Context, sec: Section) -> None:
    """κₙ(θ) at the origin (matplotlib) and the viewer's surfaces panel."""
    path = ctx.fig_dir / "helicoid_kn.png"
    surfaces.plot_normal_curvature("helicoid", 0.0, 0.0, path)
    ctx.figures.append(path)
    f1 = Fig(
        ctx.rel(path),
        "Normal curvature κₙ(θ) of the helicoid at the origin, with κ₁, "
        "κ₂ and their directions (positive where it bends away from n).",
    )
    ctx.progress.step("helicoid at the origin")
    f2 = ctx.shot(
        "helicoid_viewer",
        "The viewer's surfaces panel: the helicoid and the point "
        "(u, v) = (0, 0) with I, II, K, H (H > 0 on spheres) and κₙ(θ).",
        panel="surfaces",
    )
    ctx.progress.step("screenshot")
    sec.figs([f1, f2])
    if f2 is None:
        sec.note(f"No viewer screenshot of the surfaces panel: {ctx.screenshot_reason}.")


def _convergence(ctx: Context, sec: Section) -> None:
    """Convergence studies of H and K under refinement: tables, a summary sentence, a plot."""
    if ctx.quick:
        plan = [
            ("helicoid", "grid", (8, 16, 32)),
            ("sphere", "icosphere", (1, 2, 3, 4)),
            ("torus", "grid", (8, 16, 32)),
        ]
    else:
        plan = [
            ("helicoid", "grid", (8, 16, 32, 64, 128)),
            ("sphere", "icosphere", (1, 2, 3, 4, 5)),
            ("sphere", "grid", (8, 16, 32, 64, 128)),
            ("torus", "grid", (8, 16, 32, 64, 128)),
        ]
    studies = []
    for surf, mesher, res in plan:
        studies.append(convergence_study(surf, res, mesher))
        ctx.progress.step(f"convergence {surf} {mesher}")
    sec.p(
        "Convergence: meshes of the parameter rectangle (`grid`) or subdivided icospheres, "
        "errors |discrete − exact| over interior vertices (one sign convention: H > 0 on "
        "spheres for both). order = log-log slope of the error against the mean edge "
        "length h between consecutive levels (2: the error shrinks 4× when h halves; 0: it "
        "stalls)."
    )
    _convergence_tables(ctx, sec, studies)
    _convergence_summary(sec, studies)
    _convergence_plot(ctx, sec, studies)


def _level_rows(studies: list[ConvergenceStudy]) -> list[list]:
    """One row per study, estimator and level, with the observed orders."""
    rows = []
    for st in studies:
        for est, d in st.errors.items():
            for i, r in enumerate(st.resolutions):
                rows.append(
                    [
                        st.surface,
                        st.mesher,
                        r,
                        st.n_vertices[i],
                        st.h[i],
                        est,
                        d["max"][i],
                        d["order_max"][i - 1] if i else None,
                        d["mean"][i],
                        d["order_mean"][i - 1] if i else None,
                    ]
                )
    return rows


def _convergence_tables(ctx: Context, sec: Section, studies: list[ConvergenceStudy]) -> None:
    """The summary table (coarsest and finest level) and the table of every level."""
    summary = []
    for st in studies:
        for est, d in st.errors.items():
            summary.append(
                [
                    st.surface,
                    st.mesher,
                    est,
                    f"{st.resolutions[0]}…{st.resolutions[-1]}",
                    d["max"][0],
                    d["max"][-1],
                    d["order_max"][-1],
                    d["mean"][-1],
                    d["order_mean"][-1],
                ]
            )
    sec.add(
        ctx.table(
            "convergence_summary",
            "Coarsest and finest level of each study, with "
            "the observed order between the two finest levels.",
            [
                "surface",
                "mesher",
                "estimator",
                "levels",
                "max_error_coarsest",
                "max_error_finest",
                "order_max_finest",
                "mean_error_finest",
                "order_mean_finest",
            ],
            summary,
        )
    )
    sec.add(
        ctx.table(
            "convergence",
            "Every level of every study.",
            [
                "surface",
                "mesher",
                "res",
                "vertices",
                "h",
                "estimator",
                "max_error",
                "order_max",
                "mean_error",
                "order_mean",
            ],
            _level_rows(studies),
            max_rows=0,
        )
    )


def _convergence_summary(sec: Section, studies: list[ConvergenceStudy]) -> None:
    """Which estimators converge (order > 1.5) and which stall, read off the finest levels."""
    finals = []
    for st in studies:
        for est, d in st.errors.items():
            o = [x for x in d["order_max"] if x is not None]
            finals.append((st.surface, st.mesher, est, d["max"][-1], o[-1] if o else None))
    conv = [f for f in finals if f[4] is not None and f[4] > 1.5]
    stall = [f for f in finals if f[4] is not None and abs(f[4]) < 0.3]
    sec.p(
        "Read off the table (finest pair of levels): converging with order > 1.5: "
        + (", ".join(f"{s} {m}: {e} (order {o:.2f})" for s, m, e, _, o in conv) or "none")
        + ". Stalling (|order| < 0.3): "
        + (", ".join(f"{s} {m}: {e} (max error {num(x)})" for s, m, e, x, _ in stall) or "none")
        + "."
    )


def _convergence_plot(ctx: Context, sec: Section, studies: list[ConvergenceStudy]) -> None:
    """Max error against h, one log-log panel per study."""
    from matplotlib.ticker import NullFormatter

    fig = new_figure(4.2 * len(studies), 3.8)
    for i, st in enumerate(studies):
        ax = fig.add_subplot(1, len(studies), i + 1)
        for est, d in st.errors.items():
            y = np.maximum(np.asarray(d["max"], dtype=float), 1e-16)
            ax.loglog(st.h, y, "o-", label=est, ms=4)
        ax.set_title(f"{st.surface} ({st.mesher})", fontsize=10)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("mean edge length h")
        ax.grid(alpha=0.3, which="both")
        if i == 0:
            ax.set_ylabel("max |discrete − exact|")
            ax.legend(fontsize=7)
    fig.tight_layout()
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "convergence",
                "Max error of each estimator against h "
                "(log-log). A slope of 2 is second-order convergence.",
            )
        ]
    )
