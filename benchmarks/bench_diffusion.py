"""Benchmark: heat-method geodesics, exact distance, isolines and the filter drag, beside the
peers a user would otherwise call, in one process.

    python benchmarks/bench_diffusion.py [--mesh armadillo_igl.obj] [--scan] [--exact]
                                         [--filter-k 300] [--repeat 3] [--clicks 6]

* precompute (factorizations) of :class:`meshlap_core.diffusion.HeatGeodesic` against
  ``igl.heat_geodesics_precompute`` and, when installed (not a dependency),
  ``potpourri3d.MeshHeatMethodDistanceSolver``; all with ``t = h²``; then a new source per
  click (``--clicks`` sources spread over the mesh, vertex 0 first; the solvers alternating
  on each) against ``igl.heat_geodesics_solve`` / ``compute_distance``: median and worst;
* ``--exact``: ``igl.exact_geodesic`` from one source (18–39 s at 43k) and the heat method's
  relative error against it;
* ``igl.isolines`` with 10 levels of the distance;
* ``--filter-k K``: one drag update of the filter editor, ``U h(Λ) Uᵀ M X`` with the
  coefficients projected once (the eigenbasis read from the cache, computed the first time);
* ``--scan``: the same on the 692k scan (``igl.upsample`` of ``armadillo_loop``, made once in
  memory).

The runs alternate (ours, peer, ...) and the best of ``--repeat`` is kept; the ratios are
peer / ours (above 1: ours faster). Each alternation's precompute pair is printed too, as
ours / peer (below 1: ours faster). Meshes missing from ``../shared/meshes`` are skipped.
"""

from __future__ import annotations

import argparse
import importlib.util
import time

import igl
import numpy as np
from _util import best_of, print_table, shared_mesh

from meshlap_core.diffusion import (
    HeatGeodesic,
    SpectralFilter,
    curve_gain,
    exact_distance,
    isoline_values,
    isolines,
    transfer,
)
from meshlap_core.io import load_mesh


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def _igl_precompute(V: np.ndarray, F: np.ndarray):
    data = igl.HeatGeodesicsData()
    igl.heat_geodesics_precompute(V, F, data)
    return data


def click_sources(n: int, clicks: int) -> np.ndarray:
    """``clicks`` vertices spread over the mesh (fixed seed), vertex 0 first."""
    rng = np.random.default_rng(24)
    return np.unique(np.concatenate([[0], rng.choice(n, clicks - 1, replace=False)]))[:clicks]


def heat_rows(
    V: np.ndarray, F: np.ndarray, repeat: int, clicks: int
) -> tuple[list, np.ndarray, list]:
    """Precompute times of ours and the peers, alternating (ours, libigl, potpourri3d, ours,
    ...), best of ``repeat``; then, on the precomputed solvers, a new source per click from
    ``clicks`` sources spread over the mesh, the solvers alternating on each source (median
    and worst per solver); our distance from vertex 0; the per-click table."""
    have_pp = importlib.util.find_spec("potpourri3d") is not None
    if not have_pp:
        print("potpourri3d not installed: its row is skipped (pip install potpourri3d)")
    names = ["meshlap HeatGeodesic", "igl heat_geodesics"] + (["potpourri3d"] if have_pp else [])
    pre: dict[str, list[float]] = {name: [] for name in names}
    solvers: dict[str, object] = {}
    for _ in range(repeat):
        for name in names:
            if name.startswith("meshlap"):
                tp, solvers[name] = _timed(lambda: HeatGeodesic(V, F))
            elif name.startswith("igl"):
                tp, solvers[name] = _timed(lambda: _igl_precompute(V, F))
            else:
                import potpourri3d as pp3d

                tp, solvers[name] = _timed(lambda: pp3d.MeshHeatMethodDistanceSolver(V, F))
            pre[name].append(tp)

    def click(name: str, src: int) -> np.ndarray:
        s = solvers[name]
        if name.startswith("meshlap"):
            return s.distance([src])  # type: ignore[attr-defined]
        if name.startswith("igl"):
            return np.asarray(igl.heat_geodesics_solve(s, np.array([src])))
        return np.asarray(s.compute_distance(src))  # type: ignore[attr-defined]

    per_click: dict[str, list[float]] = {n: [] for n in names}
    first: dict[str, np.ndarray] = {}
    sources = click_sources(len(V), clicks)
    for src in sources:
        for name in names:
            ts, d = _timed(lambda: click(name, int(src)))  # noqa: B023
            per_click[name].append(ts)
            if src == sources[0]:
                first[name] = d
    ours = first[names[0]]
    for name in names[1:]:  # each alternation's pair: how steady the ratio is
        pairs = ", ".join(f"{a / b:.2f}" for a, b in zip(pre[names[0]], pre[name], strict=True))
        print(f"precompute, ours / {name} per pair (ours first): {pairs}")
    pre = {name: min(times) for name, times in pre.items()}  # the best of each
    t0 = pre[names[0]]
    c0 = float(np.median(per_click[names[0]]))
    rows = [
        [n, pre[n], float(np.median(per_click[n])), float(np.max(per_click[n])), pre[n] / t0,
         float(np.median(per_click[n])) / c0, float(np.abs(ours - first[n]).max() / ours.max())]
        for n in names
    ]  # fmt: skip
    clicks_table = [[int(src), *(per_click[n][i] for n in names)] for i, src in enumerate(sources)]
    return rows, ours, [["source", *names], clicks_table]


def run_mesh(name: str, V: np.ndarray, F: np.ndarray, args: argparse.Namespace) -> None:
    print(f"\n## {name}: {len(V)} vertices, {len(F)} faces")
    src = 0
    rows, d, (head, per_click) = heat_rows(V, F, args.repeat, args.clicks)
    print_table(
        ["solver", "precompute s", "click s (median)", "click s (worst)", "precompute ratio",
         "click ratio", "max |Δd|/max d (source 0)"],
        rows,
    )  # fmt: skip
    print(f"\na new source per click, {len(per_click)} sources, seconds (solvers alternating):")
    print_table(head, per_click)
    t_iso, (_, E, _) = best_of(lambda: isolines(V, F, d, isoline_values(d, 10)), args.repeat)
    t_iso_raw, _ = best_of(lambda: igl.isolines(V, F, d, isoline_values(d, 10)), args.repeat)
    print(
        f"isolines, 10 levels: ours {t_iso:.3f} s, igl.isolines {t_iso_raw:.3f} s "
        f"({len(E)} segments)"
    )
    if args.exact:
        t0 = time.perf_counter()
        ex = exact_distance(V, F, [src])
        t_ex = time.perf_counter() - t0
        ok = np.isfinite(ex) & (ex > 0)
        rel = np.abs(d[ok] - ex[ok]) / ex[ok]
        print(
            f"igl.exact_geodesic (one source): {t_ex:.1f} s; heat method relative error "
            f"mean {100 * rel.mean():.2f} %, median {100 * np.median(rel):.2f} %, "
            f"max {100 * rel.max():.1f} %"
        )
    if args.filter_k:
        from meshlap_core.spectral import SpectralBasis

        t0 = time.perf_counter()
        basis = SpectralBasis.compute(V, F, args.filter_k)
        print(
            f"eigenbasis k={args.filter_k}: {time.perf_counter() - t0:.1f} s ({basis.info.method})"
        )
        f = SpectralFilter(basis)
        k = args.filter_k
        h = transfer("low-pass", basis.eigenvalues, keep=k // 2)
        X = basis.V

        def full():  # what a user writes: every gain, one product
            return basis.vectors[:, :k] @ (
                h[:, None] * (basis.vectors[:, :k].T @ (basis.mass[:, None] * X))
            )

        t_full, _ = best_of(full, max(args.repeat, 5))
        f.apply(h)
        state = {"keep": k // 2}

        def drag():  # the low-pass edge moved by one mode
            state["keep"] = k // 2 + (1 if state["keep"] == k // 2 else 0)
            return f.apply(transfer("low-pass", basis.eigenvalues, keep=state["keep"]))

        t_drag, _ = best_of(drag, max(args.repeat, 5))
        print(
            f"filter at k={k}: projection + product {1000 * t_full:.1f} ms; "
            f"drag update (one mode changed) {1000 * t_drag:.2f} ms (goal < 16 ms); "
            f"ratio {t_full / t_drag:.0f}"
        )
        top = float(basis.eigenvalues[-1])
        xs = np.array([0.0, 0.05, 0.1, 0.2, 0.35, 0.6, 1.0]) * top  # the panel's drawn curve
        y = np.array([1.0, 1.0, 1.0, 0.5, 0.0, 0.0, 0.0])
        t_pieces, G = best_of(lambda: f.pieces(xs), args.repeat)

        def curve_drag():  # a gain of the drawn curve moved: the panel's Σ_j y_j G_j
            y[3] = 0.6 if y[3] == 0.5 else 0.5
            return np.tensordot(y, G, axes=1)

        def curve_full():  # the same move through U h(Λ) Uᵀ M X (most gains change)
            y[3] = 0.6 if y[3] == 0.5 else 0.5
            return f.apply(curve_gain(basis.eigenvalues, np.column_stack([xs, y])))

        t_curve, _ = best_of(curve_drag, max(args.repeat, 5))
        t_curve_full, _ = best_of(curve_full, max(args.repeat, 5))
        print(
            f"drawn curve at k={k} (7 points): its pieces {1000 * t_pieces:.1f} ms once per "
            f"basis; a drag {1000 * t_curve:.2f} ms (goal < 16 ms) against "
            f"{1000 * t_curve_full:.1f} ms through the product over U"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="armadillo_igl.obj", help="a mesh of ../shared/meshes")
    ap.add_argument("--scan", action="store_true", help="also the 692k scan")
    ap.add_argument("--exact", action="store_true", help="igl.exact_geodesic too (slow)")
    ap.add_argument("--filter-k", type=int, default=0, help="time the filter drag at this k")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--clicks", type=int, default=6, help="new sources timed per solver")
    args = ap.parse_args()
    path = shared_mesh(args.mesh)
    if path is not None:
        mesh = load_mesh(path)
        run_mesh(args.mesh, mesh.V, mesh.F, args)
    if args.scan:
        src = shared_mesh("armadillo_loop.obj")
        if src is not None:
            mesh = load_mesh(src)
            V, F = igl.upsample(mesh.V, mesh.F)  # = /tmp/scans/armadillo_692k.obj
            scan = argparse.Namespace(**{**vars(args), "exact": False, "filter_k": 0})
            run_mesh("armadillo 692k (upsampled armadillo_loop)", V, F, scan)


if __name__ == "__main__":
    main()
