"""Denoising sweeps: noise levels × Laplacians × methods × λ × iteration counts, scored against
the clean mesh (RMSE, volume change, dihedral-angle and normal errors).

Sign convention: ``L = W⁻¹K`` negative semidefinite (see :mod:`meshlap_core.smoothing`).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..errors import MeshError, MeshWarning
from ..metrics import Reference
from ..noise import add_noise, bbox_diagonal
from ..options import (
    EULER_METHODS,
    LAPLACIAN_KINDS,
    MASS_AREA,
    NOISE_MODES,
    SMOOTHING_METHODS,
    AreaKind,
    check_choice,
)
from ..types import FloatArray, IntArray, as_mesh, as_vertices
from .params import check_iters, check_lam
from .stepper import Smoother


def denoise_sweep(
    V_clean: FloatArray,
    F: IntArray,
    *,
    V_noisy: FloatArray | None = None,
    noise_levels: Sequence[float] = (0.005, 0.02, 0.05),
    methods: Sequence[str] = EULER_METHODS,
    laplacians: Sequence[str] = ("uniform",),
    lams: Sequence[float] = (0.1, 0.5, 1.0),
    iters: Sequence[int] = (10,),
    seed: int = 0,
    noise_mode: str = "isotropic",
    area: AreaKind = MASS_AREA,
    progress: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """Denoising table: noise levels × Laplacians × methods × λ × iteration counts.

    Parameters
    ----------
    V_clean : (n,3) float
        Clean reference.
    F : (m,3) int
        Shared connectivity.
    V_noisy : (n,3) float, optional
        A given noisy version (same vertex order); then ``noise_levels`` is ignored and the
        row's ``noise`` is the measured level ``RMS(offset per coordinate) / bbox diagonal``.
    noise_levels : sequence of float
        ``α`` values; noise is :func:`meshlap_core.noise.add_noise` with ``seed`` (the same seed
        for every level, so levels differ only in amplitude).
    methods : sequence of {"explicit", "implicit", "taubin"}
    laplacians : sequence of {"uniform", "cotan"}
        Negative semidefinite ``L = W⁻¹K`` (see :class:`Smoother`); built on the noisy mesh.
    lams : sequence of float
    iters : sequence of int
        Checkpoints; each (noise, Laplacian, method, λ) runs once to ``max(iters)``.
    seed : int
    noise_mode : {"isotropic", "normal"}
    area : {"voronoi", "barycentric"}
    progress : callable, optional
        Called with a short progress line per run.

    Returns
    -------
    rows : list of dict
        ``noise``, ``method``, ``laplacian``, ``lam``, ``iters``, ``rmse``, ``rmse_noisy``,
        ``max_error``, ``volume_change_pct`` (vs the clean volume; ``None`` on open meshes),
        ``volume_change_noisy_pct``, ``dihedral_mae_deg``, ``dihedral_mae_noisy_deg``,
        ``normal_dev_deg``, ``normal_dev_noisy_deg``, ``stable``, ``diverged``, ``failed``
        (``None``, or why this combination could not run, e.g. a Taubin pass band above
        ``1/λ`` or an implicit system beyond double precision), ``seconds`` (smoothing time up
        to this checkpoint). Metrics of a diverged or failed run are NaN.
    """
    V_clean, F = as_mesh(V_clean, F)
    for m in methods:
        check_choice(m, SMOOTHING_METHODS, "method")
    for lap in laplacians:
        check_choice(lap, LAPLACIAN_KINDS, "laplacian")
    check_choice(noise_mode, NOISE_MODES, "noise_mode")
    lam_list = [check_lam(v) for v in lams]
    iter_list = sorted({check_iters(v) for v in iters})
    if not lam_list or not iter_list or not methods or not laplacians:
        raise MeshError("methods, laplacians, lams and iters must not be empty", "sweep")
    ref = Reference(V_clean, F)
    cases = _noisy_cases(V_clean, F, V_noisy, noise_levels, noise_mode, seed)
    rows: list[dict[str, Any]] = []
    for level, Vn in cases:
        base = ref.compare(Vn)
        for lap in laplacians:
            for method in methods:
                for lam in lam_list:
                    rows += _run_combination(
                        ref, base, level, Vn, F, method, lap, lam, iter_list, area, progress
                    )
    return rows


def _noisy_cases(
    V_clean: FloatArray,
    F: IntArray,
    V_noisy: FloatArray | None,
    noise_levels: Sequence[float],
    noise_mode: str,
    seed: int,
) -> list[tuple[float, FloatArray]]:
    """``(level, noisy positions)`` per noise level, or the one given noisy mesh and its level."""
    if V_noisy is not None:
        Vn = as_vertices(V_noisy, "V_noisy")
        if Vn.shape != V_clean.shape:
            raise MeshError(
                f"has {len(Vn)} vertices but the clean mesh has {len(V_clean)}", "V_noisy"
            )
        diag = bbox_diagonal(V_clean)
        level = float(np.sqrt(np.mean((Vn - V_clean) ** 2)) / diag) if diag > 0 else float("nan")
        return [(level, Vn)]
    cases = []
    for a in noise_levels:
        cases.append((float(a), add_noise(V_clean, F, a, mode=noise_mode, seed=seed)))  # type: ignore[arg-type]
    return cases


_NAN_METRICS = ("rmse", "max_error", "volume_change_pct", "dihedral_mae_deg", "normal_dev_deg")


def _run_combination(
    ref: Reference,
    base: dict[str, Any],
    level: float,
    Vn: FloatArray,
    F: IntArray,
    method: str,
    lap: str,
    lam: float,
    iter_list: list[int],
    area: AreaKind,
    progress: Callable[[str], None] | None,
) -> list[dict[str, Any]]:
    """The rows of one (noise, Laplacian, method, λ): one run to ``max(iter_list)``, one row per
    checkpoint; a combination that cannot run (or diverges) gives NaN metrics and says why."""
    failed: str | None = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshWarning)
            s = Smoother(
                Vn,
                F,
                method,  # type: ignore[arg-type]
                lap,  # type: ignore[arg-type]
                lam,
                area=area,
                track_history=False,
                warn=False,
            )
        stable = s.is_stable()
    except MeshError as exc:
        failed, stable = exc.problem, False
    rows: list[dict[str, Any]] = []
    elapsed = 0.0
    for k in iter_list:
        if failed is None:
            t0 = time.perf_counter()
            try:
                s.run(k - s.iteration)
            except MeshError as exc:
                failed = exc.problem
            elapsed += time.perf_counter() - t0
        if failed is not None or s.diverged:
            got: dict[str, Any] = {key: float("nan") for key in _NAN_METRICS}
        else:
            got = ref.compare(s.V)
        rows.append(
            {
                "noise": level,
                "method": method,
                "laplacian": lap,
                "lam": lam,
                "iters": k,
                "rmse": got["rmse"],
                "rmse_noisy": base["rmse"],
                "max_error": got["max_error"],
                "volume_change_pct": got["volume_change_pct"],
                "volume_change_noisy_pct": base["volume_change_pct"],
                "dihedral_mae_deg": got["dihedral_mae_deg"],
                "dihedral_mae_noisy_deg": base["dihedral_mae_deg"],
                "normal_dev_deg": got["normal_dev_deg"],
                "normal_dev_noisy_deg": base["normal_dev_deg"],
                "stable": stable,
                "diverged": failed is None and bool(s.diverged),
                "failed": failed,
                "seconds": elapsed,
            }
        )
    if progress is not None:
        progress(
            f"noise {level:g} {lap} {method} lam={lam:g}: "
            + (
                f"failed: {failed}"
                if failed is not None
                else f"{s.iteration} iterations in {elapsed:.3f} s"
            )
        )
    return rows


def best_rows(rows: Sequence[dict[str, Any]], key: str = "rmse") -> list[dict[str, Any]]:
    """The row with the smallest finite ``key`` for each noise level, in noise order.

    Parameters
    ----------
    rows : sequence of dict
        From :func:`denoise_sweep`.
    key : str
        A numeric column, e.g. ``"rmse"`` or ``"dihedral_mae_deg"``.

    Returns
    -------
    list of dict
    """
    best: dict[float, dict[str, Any]] = {}
    for r in rows:
        v = r.get(key)
        if v is None or not math.isfinite(v):
            continue
        cur = best.get(r["noise"])
        if cur is None or v < cur[key]:
            best[r["noise"]] = r
    return [best[k] for k in sorted(best)]
