"""Curvature lab state: an estimator's principal curvatures and directions on a parametric
surface's mesh (with its error against the exact surface, under resolution, noise and jitter)
or on the loaded mesh (with the estimators' disagreement). No polyscope import."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.curvature import vertex_normals
from meshlap_core.curvature.estimators import (
    PATCH_RINGS,
    TOPOLOGY_ESTIMATORS,
    disagreement,
    estimate_curvature,
)
from meshlap_core.curvature.principal import PrincipalCurvatures, tangent_frames
from meshlap_core.curvature.refinement import ExactPrincipal, exact_principal
from meshlap_core.curvature.study import (
    curvature_study,
    flip_edges,
    flipped_and_noisy,
    jittered_mesh,
)
from meshlap_core.curvature.topology import CurvatureTopology
from meshlap_core.errors import MeshError
from meshlap_core.options import (
    CURVATURE_ESTIMATOR_LABELS,
    CURVATURE_ESTIMATORS,
    LAB_SHOWS,
    LAB_SOURCES,
    PRINCIPAL_FIELD_UNITS,
    PRINCIPAL_FIELDS,
    titled,
)
from meshlap_core.surfaces import SURFACES, SurfaceMesh, mesh_surface
from meshlap_core.types import FloatArray, IntArray

from ..panel_spec import PanelSpec
from .isolines import isoline_fields
from .settings import MAX_INT, Choice, Integer, Number, Settings, Toggle

MAX_RES = 256
"""Largest lab resolution (cells per direction; the torus gets twice as many around)."""
MAX_NOISE = 0.02
"""Largest normal noise, a fraction of the bounding-box diagonal."""
MAX_JITTER = 0.45
"""Largest parameter jitter, a fraction of a cell."""
STUDY_LEVELS = (8, 16, 32, 64)
"""Resolutions of the lab's convergence study (fixed: a resolution move keeps the plot)."""
KEEP_BASES = 6
"""Exact surfaces kept (per surface, resolution and jitter): a slider moved back is instant."""
KEEP_ESTIMATES = 8
KEEP_FLIPS = 3
"""Flipped triangulations kept per exact surface (per ``flips`` value, with their normals and
topology): a noise or estimator move on a flipped mesh does not flip again."""
"""Estimates kept (per surface, resolution, jitter, noise, flips and estimator): a quantity or
*show* move, or a slider moved back, recolours without re-running the estimator."""
LIGHT_ESTIMATORS = tuple(e for e, rings in PATCH_RINGS.items() if rings is not None)
"""The tensor estimators (cotan, Rusinkiewicz, normal cycle: a fixed patch of rings, 0.05-0.07 s
of CPU at 32k vertices with the base's kept topology): the lab runs them in a thread, not a
child process, whose start, imports and 13 MB of pickles cost 0.3-1 s per move (the window's
``Jobs.processes``; measured in ``benchmarks/bench_curvature.py --only window``)."""
LIGHT_RES = 128
"""Largest resolution run in a thread (the torus: 32,768 vertices; numpy releases the GIL,
the window's longest gap measured 0.02-0.12 s under load)."""


# fmt: off
SETTINGS = Settings(
    Choice("source", "surface", choices=LAB_SOURCES, label="source",
           tooltip="a parametric surface (exact values known) or the loaded mesh"),
    Choice("estimator", "cotan", choices=CURVATURE_ESTIMATORS, label="estimator",
           tooltip="; ".join(f"{k}: {v}" for k, v in CURVATURE_ESTIMATOR_LABELS.items())),
    Choice("quantity", "H", choices=PRINCIPAL_FIELDS, label="quantity",
           tooltip="k1 >= k2, H = (k1+k2)/2 > 0 on spheres, K = k1 k2, abs_max"),
    Choice("show", "error", choices=LAB_SHOWS, label="show",
           tooltip="the estimate, its error against the exact surface, or the largest "
           "difference between all the estimators"),
    Toggle("crosses", True, label="crosses",
           tooltip="principal directions: black k1 (max), green k2 (min), length by |k| "
           "(the exact k1 in magenta, off by default)"),
    Choice("surface", "torus", choices=tuple(SURFACES), label="lab surface",
           tooltip="the parametric surface"),
    Integer("res", 32, lo=3, hi=MAX_RES, label="resolution", widget="slider",
            tooltip="N: N x N cells of the (u, v) grid; the torus gets 2N x N (twice as many "
            "around, its cells near square). The line under the slider names the same mesh "
            "as meshlap surface --res NU,NV"),
    Number("noise", 0.0, lo=0.0, hi=MAX_NOISE, fmt="%.4f", label="noise",
           tooltip="normal noise, a fraction of the bounding-box diagonal"),
    Number("jitter", 0.0, lo=0.0, hi=MAX_JITTER, fmt="%.4f", label="jitter",
           tooltip="parameter jitter of interior vertices, a fraction of a cell"),
    Number("flips", 0.0, lo=0.0, hi=1.0, fmt="%.4f", label="edge flips",
           tooltip="fraction of the interior edges flipped"),
    Integer("vertex", -1, lo=-1, hi=MAX_INT - 1, label="vertex",
            tooltip="pick a vertex (or click the mesh): its shape operator"),
    isoline_fields(LAB_SHOWS),
)
# fmt: on
"""The Curvature lab's settings (its section of a saved session: its choices, sliders and
the picked vertex of the lab's mesh, the parametric surface's at ``res`` or the loaded mesh,
which bounds it: :func:`check_mesh`)."""
SHOWN_ONLY = ("crosses", "vertex", "isolines")
"""Settings the result does not depend on (the rest are :meth:`CurvatureLabState.params`;
the isolines are the panel's, not this state's)."""


def lab_grid(values: dict[str, Any]) -> tuple[int, int]:
    """The ``(nu, nv)`` cells of the lab's parametric surface at ``values["res"] = N``:
    ``(2N, N)`` on the torus (its u circle is three times its v circle: near-square cells),
    ``(N, N)`` elsewhere; :func:`meshlap_core.surfaces.mesh_surface`'s ``res``, and so
    ``meshlap surface --res NU,NV``'s."""
    n = int(values["res"])
    return (2 * n, n) if values["surface"] == "torus" else (n, n)


def grid_line(values: dict[str, Any]) -> str:
    """What the resolution means, said under its slider: ``"torus: 64 x 32 cells, 2,048
    vertices (meshlap surface torus --res 64,32)"`` (``--mesh out.obj`` writes that mesh)."""
    nu, nv = lab_grid(values)
    name = values["surface"]
    n = grid_vertices(name, nu, nv)
    return f"{name}: {nu} x {nv} cells, {n:,} vertices (meshlap surface {name} --res {nu},{nv})"


@functools.lru_cache(maxsize=64)
def grid_vertices(surface: str, nu: int, nv: int) -> int:
    """The vertex count of ``mesh_surface(surface, (nu, nv))`` (seams and poles welded)."""
    return len(mesh_surface(surface, (nu, nv)).V)


def lab_vertex_count(values: dict[str, Any], mesh: Any) -> int:
    """Vertices of the lab's mesh for the session ``values`` (the loaded ``mesh``'s, or the
    parametric surface's at ``res``: its grid, as :func:`make_base` meshes it)."""
    if values["source"] == "mesh":
        return len(mesh.V)
    return grid_vertices(values["surface"], *lab_grid(values))


def check_mesh(values: dict[str, Any], mesh: Any, source: Any) -> None:
    """A saved picked vertex that the lab's mesh has.

    Raises
    ------
    MeshError
        ``vertex`` beyond the lab's mesh (named with its size).
    """
    v = values["vertex"]
    if v >= 0:
        n = lab_vertex_count(values, mesh)
        if v >= n:
            raise MeshError(
                f'"curvature_lab.vertex" is {v}; the lab\'s mesh has vertices 0..{n - 1}', source
            )


@dataclass
class LabResult:
    """What the lab shows, computed off the UI thread.

    Attributes
    ----------
    V : (n,3) float
    F : (m,3) int
    values : (n,) float
        The coloured field (0 where an error is not measured: boundary and poles).
    label : str
    principal : PrincipalCurvatures
        The estimate (``k1 ≥ k2``, directions ``d1``, ``d2``).
    exact_d1 : (n,3) float or None
        The exact direction of ``k1`` (parametric surfaces).
    summary : str
        One line: the RMS error (surface) or the largest disagreement (mesh).
    exact : ((n,) float, (n,) float) or None
        The exact ``(k1, k2)`` on a parametric mesh.
    base : Base or None
        The jittered mesh and its exact values when they were computed for this result, for the
        state's cache (``None`` on the loaded mesh or when the cached one was used).
    """

    V: FloatArray
    F: IntArray
    values: FloatArray
    label: str
    principal: PrincipalCurvatures
    exact_d1: FloatArray | None
    summary: str
    exact: tuple[FloatArray, FloatArray] | None = None
    base: Base | None = None
    estimate_key: tuple[Any, ...] | None = None
    crosses: Crosses | None = None


@dataclass(frozen=True)
class Crosses:
    """The principal directions as 2-symmetric tangent line fields for polyscope, made once
    per estimate off the UI thread (:func:`crosses_of`).

    Attributes
    ----------
    basis_x, basis_y : (n,3) float
        The tangent basis of the estimate's normals.
    k1, k2 : (n,2) float
        ``d1``, ``d2`` in that basis, scaled by ``|k| / max|k|`` (at least 0.2).
    exact : (n,2) float or None
        The exact ``d1`` in that basis (parametric surfaces), scaled as ``k1``.
    """

    basis_x: FloatArray
    basis_y: FloatArray
    k1: FloatArray
    k2: FloatArray
    exact: FloatArray | None


@dataclass(frozen=True)
class Estimate:
    """An estimator's output on a lab surface after flips and noise (what a quantity or *show*
    move reuses: only the coloured field changes)."""

    key: tuple[Any, ...]  # (surface, res, jitter, noise, flips, estimator)
    V: FloatArray  # (n,3) the noisy positions
    F: IntArray  # (m,3) the flipped faces
    principal: PrincipalCurvatures
    crosses: Crosses | None = None


@dataclass(frozen=True)
class Base:
    """A lab surface before flips and noise: the jittered mesh and its exact curvature (what
    a move of the noise or flips slider reuses; the exact values do not depend on them), and
    per ``flips`` value the flipped mesh, its normals and its
    :class:`~meshlap_core.curvature.topology.CurvatureTopology` (the faces do not change with
    the noise: the estimators' edge tables are built once per resolution, jitter and flips;
    :meth:`triangulation`). The topologies are not pickled to or from a child process."""

    key: tuple[Any, ...]  # (surface, res, jitter)
    mesh: Any  # SurfaceMesh
    exact: ExactPrincipal
    normals: FloatArray  # (n,3) unit vertex normals of the mesh (the noise's direction)
    kept: dict[float, tuple[Any, FloatArray, CurvatureTopology]] = field(
        default_factory=dict, repr=False, compare=False
    )

    def triangulation(self, flips: float) -> tuple[SurfaceMesh, FloatArray, CurvatureTopology]:
        """The mesh with a fraction ``flips`` of its edges flipped (seed 0, as
        :func:`~meshlap_core.curvature.study.flipped_and_noisy`), its unit vertex normals and
        its topology, made on first use and kept (the last :data:`KEEP_FLIPS` values; any
        thread: the same values whoever makes them)."""
        got = self.kept.get(float(flips))
        if got is None:
            m, normals = self.mesh, self.normals
            if flips > 0:
                F = flip_edges(m.V, m.F, flips, 0)
                m = SurfaceMesh(m.V, F, m.uv, m.pole, m.boundary, m.surface, m.res)
                normals = vertex_normals(m.V, F)
            got = (m, normals, CurvatureTopology.of(m.F, len(m.V)))
            self.kept[float(flips)] = got
            while len(self.kept) > KEEP_FLIPS:
                self.kept.pop(next(iter(self.kept)), None)
        return got

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state["kept"] = {}  # rebuilt where it is used: megabytes of indices otherwise
        return state


def base_key(params: dict[str, Any]) -> tuple[Any, ...]:
    """What the exact values depend on: ``(surface, res, jitter)``."""
    return (params["surface"], int(params["res"]), float(params["jitter"]))


def estimate_key(params: dict[str, Any]) -> tuple[Any, ...]:
    """What an estimate on a lab surface depends on: the base's key, noise, flips and the
    estimator."""
    return (
        *base_key(params),
        float(params["noise"]),
        float(params["flips"]),
        params["estimator"],
    )


def make_base(params: dict[str, Any]) -> Base:
    """The jittered mesh of ``params`` and its exact curvature."""
    m = jittered_mesh(params["surface"], lab_grid(params), params["jitter"])
    return Base(base_key(params), m, exact_principal(m, m.surface), vertex_normals(m.V, m.F))


@dataclass
class CurvatureLabState:
    """The lab's choices and its last result (``inputs()`` names what the result is for)."""

    source: str = SETTINGS.default("source")
    estimator: str = SETTINGS.default("estimator")
    quantity: str = SETTINGS.default("quantity")
    show: str = SETTINGS.default("show")
    crosses: bool = SETTINGS.default("crosses")
    surface: str = SETTINGS.default("surface")
    res: int = SETTINGS.default("res")
    noise: float = SETTINGS.default("noise")
    jitter: float = SETTINGS.default("jitter")
    flips: float = SETTINGS.default("flips")
    result: LabResult | None = None
    computed_for: tuple[Any, ...] = field(default=())
    vertex: int = SETTINGS.default("vertex")  # the picked vertex of the result's mesh
    bases: dict[tuple[Any, ...], Base] = field(default_factory=dict)  # newest last
    studies: dict[tuple[Any, ...], list[dict[str, Any]]] = field(default_factory=dict)
    estimates: dict[tuple[Any, ...], Estimate] = field(default_factory=dict)  # newest last

    def inputs(self, mesh_version: int) -> tuple[Any, ...]:
        """Everything the result depends on (the mesh version only for the loaded mesh)."""
        base = (self.source, self.estimator, self.quantity, self.show)
        if self.source == "mesh":
            return (*base, mesh_version)
        return (*base, self.surface, self.res, self.noise, self.jitter, self.flips)

    def set_choice(self, what: str, value: str) -> None:
        """Set ``source``, ``estimator``, ``quantity``, ``show`` or ``surface`` (checked).

        Raises
        ------
        MeshError
            An unknown value (the previous one stays).
        """
        setattr(self, what, SETTINGS[what].checked(value, what))

    def set_number(self, what: str, value: Any) -> None:
        """Set ``res`` (3..MAX_RES), ``noise`` (0..MAX_NOISE), ``jitter`` (0..MAX_JITTER) or
        ``flips`` (0..1, the fraction of edges flipped).

        Raises
        ------
        MeshError
            Not a finite number in range (the previous value stays).
        """
        lo, hi = SETTINGS[what].lo, SETTINGS[what].hi
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise MeshError(f"must be a number, got {value!r}", what) from None
        if not math.isfinite(x) or not lo <= x <= hi:
            raise MeshError(f"must be between {lo} and {hi}, got {value!r}", what)
        setattr(self, what, int(x) if isinstance(SETTINGS[what], Integer) else x)

    def params(self) -> dict[str, Any]:
        """The inputs as a plain dict for :meth:`compute` (picklable, for a child process):
        every setting but what is only shown (:data:`SHOWN_ONLY`)."""
        return {k: getattr(self, k) for k in SETTINGS.keys() if k not in SHOWN_ONLY}

    def settings(self) -> dict[str, Any]:
        """Its part of the panel's section of a saved session (:data:`SETTINGS`' keys but the
        panel's isolines)."""
        out = self.params()
        out["crosses"] = bool(self.crosses)
        out["vertex"] = int(self.vertex)
        return {k: out[k] for k in SETTINGS.keys() if k in out}

    def configure(self, values: dict[str, Any]) -> None:
        """Take a session's section (checked against :data:`SETTINGS` and by
        :func:`check_mesh`); the result is recomputed for it, the picked vertex kept."""
        for s in SETTINGS:
            if s.key not in SHOWN_ONLY:
                setter = self.set_choice if isinstance(s, Choice) else self.set_number
                setter(s.key, values[s.key])
        self.crosses = bool(values["crosses"])
        self.result, self.computed_for = None, ()
        self.vertex = int(values["vertex"])

    def base(self) -> Base | None:
        """The cached exact surface for the current settings (``None``: not computed yet)."""
        return self.bases.get(base_key(self.params()))

    def estimate(self) -> Estimate | None:
        """The cached estimate for the current settings (``None``: not computed yet, its exact
        surface no longer cached, or the loaded mesh)."""
        if self.source != "surface" or self.base() is None:  # its exact values are needed
            return None
        return self.estimates.get(estimate_key(self.params()))

    def light(self) -> bool:
        """The next result is cheap enough for a thread of the window (see
        :data:`LIGHT_ESTIMATORS`): a lab surface up to :data:`LIGHT_RES`, one tensor estimator
        (or an estimate already cached), not the disagreement of all the estimators."""
        if self.source != "surface" or self.show == "disagreement":
            return False
        return self.estimate() is not None or (
            self.estimator in LIGHT_ESTIMATORS and self.res <= LIGHT_RES
        )

    @staticmethod
    def compute(
        params: dict[str, Any],
        V: Any,
        F: Any,
        base: Base | None = None,
        progress: Any = None,
        estimate: Estimate | None = None,
    ) -> LabResult:
        """The lab's result for ``params`` (any thread or a child process: touches no state);
        ``V, F`` are the loaded mesh's (used when ``source`` is ``mesh``); ``base`` the cached
        exact surface for ``params`` (computed when ``None`` or for other settings);
        ``estimate`` the cached estimate for ``params`` (the estimator is not run again: a
        quantity or *show* move only recolours). The convergence study is separate
        (:meth:`study`)."""
        if params["source"] == "surface":
            if estimate is not None and estimate.key != estimate_key(params):
                estimate = None
            if base is not None and base.key == base_key(params):
                result = _surface_result(params, base, estimate)
                result.base = None  # the state has it: not sent back from a child process
                return result
            return _surface_result(params, make_base(params), estimate)
        V = np.asarray(V, dtype=np.float64)
        F = np.asarray(F, dtype=np.int64)
        q, est = params["quantity"], params["estimator"]
        r = estimate_curvature(V, F, est)
        crosses = crosses_of(r, None, cross_length(V, F))
        if params["show"] == "disagreement":
            values = _disagreement(V, F, q)
            label = titled(f"{q} disagreement (max - min)", PRINCIPAL_FIELD_UNITS[q])
            return LabResult(V, F, values, label, r, None, _dis_summary(values), crosses=crosses)
        note = (
            "no exact surface for a loaded mesh: the estimate is shown"
            if params["show"] == "error"
            else ""
        )
        values = r.field(q)
        summary = note or f"{q} in [{values.min():.4g}, {values.max():.4g}]"
        label = titled(f"{q} ({est})", PRINCIPAL_FIELD_UNITS[q])
        return LabResult(V, F, values, label, r, None, summary, crosses=crosses)

    def study_key(self) -> tuple[Any, ...] | None:
        """What the convergence study depends on, ``(surface, estimator, noise, jitter,
        flips)``; ``None`` when no study is shown (the loaded mesh, or not the error map)."""
        if self.source != "surface" or self.show != "error":
            return None
        return (self.surface, self.estimator, self.noise, self.jitter, self.flips)

    @staticmethod
    def study(params: dict[str, Any], progress: Any = None) -> list[dict[str, Any]]:
        """The estimator's :func:`~meshlap_core.curvature.study.curvature_study` rows at
        :data:`STUDY_LEVELS` (``h``, ``H_rel``, ``K_rel``, ``H_order``, ...): the log-log plot
        of the error against h (any thread or a child process)."""
        return curvature_study(
            [params["surface"]],
            [params["estimator"]],
            STUDY_LEVELS,
            params["noise"],
            params["jitter"],
            flips=params["flips"],
            progress=progress,
        )

    def convergence(self) -> list[dict[str, Any]]:
        """The study rows for the current settings (empty until computed or when not shown)."""
        key = self.study_key()
        return self.studies.get(key, []) if key is not None else []

    def adopt_study(self, key: tuple[Any, ...], rows: list[dict[str, Any]]) -> None:
        """Keep the study ``rows`` computed for ``key`` (a failed study keeps ``[]``)."""
        self.studies[key] = rows

    def adopt(self, inputs: tuple[Any, ...], result: LabResult) -> None:
        """Take ``result``, computed for ``inputs`` (a picked vertex stays if it exists)."""
        self.result, self.computed_for = result, inputs
        if result.base is not None:
            self.bases.pop(result.base.key, None)
            self.bases[result.base.key] = result.base
            while len(self.bases) > KEEP_BASES:
                self.bases.pop(next(iter(self.bases)))
        key = result.estimate_key
        if key is not None:
            self.estimates.pop(key, None)
            self.estimates[key] = Estimate(
                key, result.V, result.F, result.principal, result.crosses
            )
            while len(self.estimates) > KEEP_ESTIMATES:
                self.estimates.pop(next(iter(self.estimates)))
        if self.vertex >= len(result.V):
            self.vertex = -1

    def pick(self, vertex: int) -> None:
        """Pick a vertex of the shown mesh for the shape-operator readout.

        Raises
        ------
        MeshError
            No result yet, or ``vertex`` outside it.
        """
        if self.result is None or not 0 <= int(vertex) < len(self.result.V):
            raise MeshError(f"no vertex {vertex} in the lab's mesh", "vertex")
        self.vertex = int(vertex)

    def shape_operator(self) -> dict[str, Any] | None:
        """The picked vertex's discrete shape operator (see :func:`shape_operator_at`)."""
        if self.result is None or self.vertex < 0:
            return None
        return shape_operator_at(self.result, self.vertex)


def _surface_result(
    params: dict[str, Any], base: Base, estimate: Estimate | None = None
) -> LabResult:
    """The estimate on ``base``'s mesh after flips and noise (``estimate`` when cached), and
    the field shown."""
    q, est = params["quantity"], params["estimator"]
    crosses = None
    if estimate is not None:
        Vs, Fs, r, crosses = estimate.V, estimate.F, estimate.principal, estimate.crosses
    else:
        m, normals, topology = base.triangulation(params["flips"])
        _, Vs = flipped_and_noisy(m, params["noise"], normals=normals)
        Fs = m.F
        options = {"topology": topology} if est in TOPOLOGY_ESTIMATORS else {}
        r = estimate_curvature(Vs, Fs, est, **options)
    if crosses is None:
        crosses = crosses_of(r, base.exact.d1, cross_length(Vs, Fs))
    ex = base.exact
    exact = PrincipalCurvatures(ex.k1, ex.k2, ex.d1, ex.d2, np.zeros_like(ex.d1), "exact")
    compared = ex.compared
    if params["show"] == "error":
        err = np.where(compared, r.field(q) - exact.field(q), np.nan)
        values = np.nan_to_num(err)
        label = titled(f"{q} error ({est} - exact)", PRINCIPAL_FIELD_UNITS[q])
        rms = float(np.sqrt(np.nanmean(err**2)))
        scale = float(np.sqrt(np.nanmean(np.where(compared, exact.field(q), np.nan) ** 2)))
        rel = f" ({100 * rms / scale:.3g} % of RMS |{q}|)" if scale > 0 else ""
        summary = f"RMS error {rms:.4g}{rel} over {int(compared.sum())} vertices"
    elif params["show"] == "disagreement":
        values = _disagreement(Vs, Fs, q)
        label = titled(f"{q} disagreement (max - min)", PRINCIPAL_FIELD_UNITS[q])
        summary = _dis_summary(values)
    else:
        values, label = r.field(q), titled(f"{q} ({est})", PRINCIPAL_FIELD_UNITS[q])
        exq = exact.field(q)
        summary = f"exact {q} in [{np.nanmin(exq):.4g}, {np.nanmax(exq):.4g}]"
    return LabResult(
        Vs,
        Fs,
        values,
        label,
        r,
        exact.d1,
        summary,
        (exact.k1, exact.k2),
        base,
        estimate_key(params),
        crosses,
    )


def shape_operator_at(r: LabResult, i: int, n: int = 73) -> dict[str, Any]:
    """The 2×2 shape operator of the estimate at vertex ``i`` in the tangent basis ``(t1, t2)``
    of its normal, ``S = Σ k_j d_j d_jᵀ``, and Euler's formula
    ``κn(θ) = k1 cos²θ + k2 sin²θ`` (θ from ``d1``) on ``n`` angles in ``[0°, 360°]``, beside the
    exact one at the same vertex when the surface is known (the exact ``d1`` sits at the angle
    ``φ`` from the estimate's, so the exact curve is ``k1* cos²(θ − φ) + k2* sin²(θ − φ)``).

    Returns
    -------
    dict
        ``S`` (2×2 list), ``t1``, ``t2`` (3-vectors), ``k1``, ``k2``, ``theta_deg`` and
        ``kn`` ((n,) arrays), and ``exact_kn`` ((n,) or None).
    """
    p = r.principal
    S, t1, t2 = p.shape_operator(i)
    th = np.radians(np.linspace(0.0, 360.0, n))
    kn = p.k1[i] * np.cos(th) ** 2 + p.k2[i] * np.sin(th) ** 2
    exact_kn = None
    if r.exact_d1 is not None and r.exact is not None:
        ek1, ek2 = float(r.exact[0][i]), float(r.exact[1][i])
        if np.isfinite(ek1) and np.isfinite(ek2):
            d = r.exact_d1[i]
            phi = np.arctan2(d @ p.d2[i], d @ p.d1[i])
            exact_kn = ek1 * np.cos(th - phi) ** 2 + ek2 * np.sin(th - phi) ** 2
    return {
        "S": S.tolist(),
        "t1": t1,
        "t2": t2,
        "k1": float(p.k1[i]),
        "k2": float(p.k2[i]),
        "theta_deg": np.degrees(th),
        "kn": kn,
        "exact_kn": exact_kn,
    }


def _disagreement(V: FloatArray, F: IntArray, q: str) -> FloatArray:
    return disagreement([estimate_curvature(V, F, e) for e in CURVATURE_ESTIMATORS], q)


def _dis_summary(values: FloatArray) -> str:
    return (
        f"estimators disagree by up to {values.max():.4g} (median {np.median(values):.4g}): "
        "large where no estimator can be trusted"
    )


def _in_basis(d: FloatArray, k: FloatArray, t1: FloatArray, t2: FloatArray) -> FloatArray:
    """``d`` (n,3) in the basis ``(t1, t2)``, scaled by ``|k| / max|k|`` (at least 0.2, so a
    flat direction still shows), ``(n,2)``."""
    a = np.abs(k)
    top = float(np.percentile(a, 98)) if a.size else 1.0
    s = np.clip(a / (top or 1.0), 0.2, 1.0)
    return np.stack([np.einsum("ij,ij->i", d, t1), np.einsum("ij,ij->i", d, t2)], 1) * s[:, None]


def cross_field(
    p: PrincipalCurvatures, which: int = 1
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """A principal direction as a 2-symmetric tangent line field for polyscope: the 2-D values
    in the tangent basis ``(t1, t2)`` of ``p.normal``, scaled by ``|k| / max|k|``
    (at least 0.2, so a flat direction still shows).

    Returns
    -------
    values : (n,2) float
    basis_x, basis_y : (n,3) float
    """
    d, k = (p.d1, p.k1) if which == 1 else (p.d2, p.k2)
    t1, t2 = tangent_frames(p.normal)
    return _in_basis(d, k, t1, t2), t1, t2


def crosses_of(
    p: PrincipalCurvatures, exact_d1: FloatArray | None = None, length: float = 1.0
) -> Crosses:
    """Both principal directions (and the exact ``d1`` when given) as :func:`cross_field`
    gives them, sharing one tangent basis, times ``length`` (the world length of a cross arm
    at the largest ``|k|``: drawn as ambient vectors, a cross stays inside its vertex's cell
    on a coarse or a fine mesh alike)."""
    t1, t2 = tangent_frames(p.normal)
    exact = None if exact_d1 is None else length * _in_basis(exact_d1, p.k1, t1, t2)
    k1, k2 = _in_basis(p.d1, p.k1, t1, t2), _in_basis(p.d2, p.k2, t1, t2)
    return Crosses(t1, t2, length * k1, length * k2, exact)


def cross_length(V: FloatArray, F: IntArray) -> float:
    """A cross arm's world length: 0.4 of the mean edge length (one cross per vertex, no
    overlap with the neighbours'; the three edges of every face, on coordinate columns)."""
    if len(F) == 0:
        return 1.0
    X = [np.ascontiguousarray(V[:, d]) for d in range(3)]
    P = [[x[np.ascontiguousarray(F[:, k])] for x in X] for k in range(3)]
    total = 0.0
    for i, j in ((0, 1), (1, 2), (2, 0)):
        d = [P[j][c] - P[i][c] for c in range(3)]
        total += float(np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sum())
    return 0.4 * total / (3 * len(F))


SPEC = PanelSpec(
    name="curvature_lab",
    title="Curvature lab",
    summary="one estimator's principal curvatures and directions, its error against an exact "
    "parametric surface under resolution, noise, jitter and flips, or the estimators' "
    "disagreement on the loaded mesh",
    panel="CurvatureLabPanel",
    state=CurvatureLabState,
    settings=SETTINGS,
    check_mesh=check_mesh,
)
"""The Curvature lab panel."""
