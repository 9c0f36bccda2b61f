"""Diffusion panel state: heat from clicked vertices two ways, geodesic distance (heat method,
exact on demand), spectral filters and the heat kernel signature. No polyscope import.

The heavy objects are built once and reused: the backward Euler factorization
(:class:`~meshlap_core.diffusion.HeatDiffusion`, per mesh), the heat method's two
factorizations (:class:`~meshlap_core.diffusion.HeatGeodesic`, per mesh, ``m`` and boundary
rule) and the filter's projected coefficients (per eigenbasis). The eigenbasis is the one the
Spectral view computed (:func:`find_basis` finds it among the panels' states without naming a
panel).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.diffusion import (
    HeatDiffusion,
    HeatGeodesic,
    SpectralFilter,
    curve_gain,
    heat_kernel_signature,
    heat_spectral,
    hks_distance,
    hks_times,
    transfer,
    truncation_bound,
    unit_heat,
)
from meshlap_core.errors import MeshError
from meshlap_core.options import (
    DEFAULT_HEAT_BOUNDARY,
    FILTER_KINDS,
    HEAT_BOUNDARIES,
    HEAT_METHODS,
    titled,
)
from meshlap_core.spectral import SpectralBasis
from meshlap_core.types import FloatArray

from ..panel_spec import PanelSpec
from .animation import Animation, Option
from .isolines import COUNT_RANGE, DEFAULT_COUNT
from .settings import (
    MAX_INT,
    Choice,
    Custom,
    Integer,
    Number,
    Settings,
    Toggle,
    integer_problem,
    shown,
)

SHOWS: tuple[str, ...] = ("heat", "distance", "filter", "hks")
"""What the Diffusion view shows on the mesh."""
HEAT_FIELDS: tuple[str, ...] = (*HEAT_METHODS, "difference")
"""The heat field on the mesh: backward Euler, the eigen-expansion, or spectral − Euler."""
LOG_T_RANGE = (-3.0, 4.0)
"""The t slider's range, as log10 of t relative to the mesh's h² (t = 10^x · h²)."""
PLAY_STEP = 0.05
"""How far the play button moves t per heat field shown (log10 of t/h²: a decade in 20)."""
PANEL_FILTERS: tuple[str, ...] = (*FILTER_KINDS, "drawn")
"""The filter editor's kinds: the core's, and a curve the user drags (:func:`curve_gain`)."""
DEFAULT_KNOTS: tuple[tuple[float, float], ...] = (
    (0.0, 1.0), (0.05, 1.0), (0.1, 1.0), (0.2, 0.5), (0.35, 0.0), (0.6, 0.0), (1.0, 0.0),
)  # fmt: skip
"""The drawn curve's control points ``(λ / λ_max, h)``: a soft low-pass. Their λ are fixed
(an equalizer's bands, denser at low frequencies); a drag moves a gain, so the filtered shape
is a sum of precomputed pieces (:meth:`SpectralFilter.pieces`)."""
GAIN_RANGE = (-2.0, 5.0)
"""The gains a drawn point may take (as the band gain's slider)."""
HKS_SCALES = 16
"""Times of the heat kernel signature (log-spaced, Sun et al. 2009)."""

HEAT_TITLES: dict[str, str] = dict(
    zip(
        HEAT_FIELDS,  # backward Euler, the eigen-expansion, their difference
        (
            titled("heat u, backward Euler", "1/length^2"),
            titled("heat u, eigen-expansion", "1/length^2"),
            titled("heat u: eigen-expansion - backward Euler", "1/length^2"),
        ),
        strict=True,
    )
)
"""The colour bar's title of each heat field (a unit of heat at each source: ``∫ u dA = 1``,
heat per area)."""
DISTANCE_TITLE = titled("geodesic distance, heat method", "length")
DISTANCE_ERROR_TITLE = titled("distance error |d - d_exact| / d_exact", "dimensionless")
HKS_TITLE = titled("heat kernel signature HKS(x, t) / heat trace", "1/length^2")
HKS_DISTANCE_TITLE = titled("HKS distance from the source's signature", "dimensionless")

ISO_FIELDS: tuple[str, ...] = ("heat", "heat error", "distance error", "hks")
"""The fields whose isoline settings a session keeps in ``isoline_fields`` (the distance's
are ``isolines`` / ``isoline_count``): the heat (its two copies too), the heat difference, the
distance's error map, the heat kernel signature."""


def check_isoline_fields(x: Any) -> str | None:
    """``{field: {"on": bool, "count": int}}`` over :data:`ISO_FIELDS`."""
    if not isinstance(x, dict):
        return "must be an object of fields"
    for name, v in x.items():
        if name not in ISO_FIELDS:
            return f"has {name!r}; fields are {', '.join(ISO_FIELDS)}"
        if not (isinstance(v, dict) and set(v) == {"on", "count"}):
            return f'{name!r} must be {{"on": true/false, "count": N}}'
        if not isinstance(v["on"], bool) or integer_problem(v["count"], *COUNT_RANGE):
            return f"{name!r}: on must be true/false, count 1..200"
    return None


def check_sources(x: Any) -> str | None:
    """A list of vertex indices (each an integer ``0 .. MAX_INT - 1``; the session's mesh
    bounds them further, :func:`check_mesh`)."""
    if not isinstance(x, list):
        return f"must be a list of vertices, got {shown(x)}"
    for v in x:
        if integer_problem(v, 0, MAX_INT - 1):
            return f"has {shown(v)}; a source is a vertex index (an integer >= 0)"
    return None


CURVE_POINTS = tuple(f"curve point {i}" for i in range(len(DEFAULT_KNOTS)))
"""The drawn curve's control points as dragged in the plot (its widgets)."""
MAX_SMOOTHER_STEPS = 10_000
"""Most steps of the smoothers' transfer functions (the filter editor's *smoother steps*)."""


def check_curve(x: Any) -> str | None:
    """The drawn curve's gains: one finite number in :data:`GAIN_RANGE` per control point
    of :data:`DEFAULT_KNOTS` (their λ are fixed)."""
    n = len(DEFAULT_KNOTS)
    if not isinstance(x, list) or len(x) != n:
        return f"must be a list of {n} gains, got {shown(x)}"
    lo, hi = GAIN_RANGE
    for y in x:
        if not isinstance(y, int | float) or isinstance(y, bool) or not lo <= y <= hi:
            return f"has {shown(y)}; a gain is a number {lo:g} to {hi:g}"
    return None


def distinct(sources: list[int]) -> list[int]:
    """The sources without repeats, in their order (``[0, 0, 0]`` is one source: a unit of
    heat each, three would triple the heat; and a list of a million repeats costs nothing)."""
    return list(dict.fromkeys(sources))


# fmt: off
SETTINGS = Settings(
    Choice("show", "distance", choices=SHOWS, label="show",
           tooltip="heat: u_t = Lap u from the clicked vertices; distance: heat method (Crane et "
           "al. 2013); filter: U h(Lambda) U^T M X; hks: heat kernel signature"),
    Custom("sources", [], check=check_sources, normalize=distinct, widget="none",
           example=[3, 5], refused=("3", [1.5], [-1], [True], [10**400], {"0": 1})),
    Number("log_t", 0.0, lo=LOG_T_RANGE[0], hi=LOG_T_RANGE[1], fmt="%.2f",
           label="log10 t/h^2", tooltip="heat time t = 10^x h^2 (h: mean edge)"),
    Integer("steps", 1, lo=1, hi=1000, label="Euler steps",
            tooltip="(M + tau K) u' = M u, tau = t/steps"),
    Choice("heat_field", "euler", choices=HEAT_FIELDS, label="heat field",
           tooltip="euler, spectral (sum exp(-lambda_i t) phi_i phi_i^T M u0) or spectral - "
           "euler; all three on one colour range"),
    Number("m", 1.0, lo=1e-3, hi=1e4, widget="input", fmt="%.4g", label="m (t = m h^2)",
           tooltip="heat time factor (default 1)"),
    Choice("boundary", DEFAULT_HEAT_BOUNDARY, choices=HEAT_BOUNDARIES,
           label="boundary condition",
           tooltip="heat step on open meshes: Neumann, Dirichlet or their average (the "
           "paper's)"),
    Toggle("isolines", True, label="isolines",
           tooltip="level curves of the distance field on the mesh"),
    Integer("isoline_count", DEFAULT_COUNT, lo=COUNT_RANGE[0], hi=COUNT_RANGE[1],
            label="isoline count", tooltip="curves over the field's range"),
    Custom("isoline_fields", {}, check=check_isoline_fields, widget="none",
           example={"heat": {"on": True, "count": 5}},
           refused=([], {"nope": {"on": True, "count": 5}}, {"heat": {"on": 1, "count": 5}},
                    {"heat": {"on": True, "count": 10**400}})),
    Choice("filter", "low-pass", choices=PANEL_FILTERS, label="filter",
           tooltip="low-pass: first modes; band: gain on modes; explicit/implicit/taubin: the "
           "smoothers' transfer functions (1 - s lam)^n, (1 + s lam)^-n, ...; drawn: drag "
           "the curve's points in the plot"),
    Integer("keep", 10, lo=0, hi=MAX_INT, label="modes kept", widget="slider",
            tooltip="low-pass / band end"),
    Number("gain", 2.0, lo=-100.0, hi=100.0, slider=GAIN_RANGE, fmt="%.2f", label="band gain",
           tooltip="gain of the band"),
    Integer("hks_scale", 8, lo=0, hi=HKS_SCALES - 1, label="HKS time", widget="slider",
            tooltip="log-spaced t"),
    Integer("iters", 10, lo=0, hi=MAX_SMOOTHER_STEPS, label="smoother steps", widget="input",
            added=True, tooltip="n of the smoothers' filters"),
    Toggle("residual", False, label="keep residual", added=True,
           tooltip="add X - U U^T M X back"),
    Custom("curve", [y for _, y in DEFAULT_KNOTS], check=check_curve, widget="drag",
           label="curve point 0", also=CURVE_POINTS[1:],
           added=True, example=[1.0, 1.0, 0.5, 0.0, 0.25, 0.0, 0.0],
           tooltip="the drawn filter's gains h at its control points (their lambda fixed)",
           refused=([], [1.0] * (len(DEFAULT_KNOTS) - 1), ["1"] * len(DEFAULT_KNOTS),
                    [float("nan")] * len(DEFAULT_KNOTS), [99.0] * len(DEFAULT_KNOTS))),
)
# fmt: on
"""The Diffusion panel's section of a saved session (:mod:`.session`): the sources are
kept without repeats and the session's mesh bounds them (:func:`check_mesh`)."""


def check_mesh(values: dict[str, Any], mesh: Any, source: Any) -> None:
    """Saved sources the session's mesh has (so at most its vertex count of them, once the
    repeats are dropped when the file was read).

    Raises
    ------
    MeshError
        A source that is not a vertex index of the mesh.
    """
    n = len(mesh.V)
    bad = next((v for v in values["sources"] if v >= n), None)
    if bad is not None:
        raise MeshError(f'"diffusion.sources" has {bad}; vertices are 0..{n - 1}', source)


def find_basis(slices: Any, V: FloatArray) -> SpectralBasis | None:
    """The eigenbasis some panel's state holds for the mesh ``V`` (``None``: none computed)."""
    for st in slices:
        basis = getattr(st, "basis", None)
        if isinstance(basis, SpectralBasis) and basis.V.shape == V.shape:
            if np.array_equal(basis.V, V):
                return basis
    return None


def symmetric_range(*fields: FloatArray) -> tuple[float, float]:
    """One colour range ``[-r, r]`` over several fields (finite values)."""
    r = 0.0
    for f in fields:
        f = np.asarray(f)
        f = f[np.isfinite(f)]
        if f.size:
            r = max(r, float(np.abs(f).max()))
    r = r or 1.0
    return -r, r


@dataclass
class DiffusionState:
    """Settings, the reusable solvers, and the fields the panel shows."""

    show: str = SETTINGS.default("show")
    sources: list[int] = field(default_factory=list)
    log_t: float = SETTINGS.default("log_t")  # t = 10^log_t · h²
    playing: bool = False  # t sweeps up its log scale (the play button)
    steps: int = SETTINGS.default("steps")
    heat_field: str = SETTINGS.default("heat_field")
    m: float = SETTINGS.default("m")
    boundary: str = SETTINGS.default("boundary")
    filter: str = SETTINGS.default("filter")
    keep: int = SETTINGS.default("keep")
    gain: float = SETTINGS.default("gain")
    band: tuple[int, int] = (1, 10)
    knots: list[tuple[float, float]] = field(default_factory=lambda: list(DEFAULT_KNOTS))
    step: float = 0.0  # smoother step; 0: 0.5 / λ_max of the basis
    iters: int = 10
    residual: bool = False
    hks_scale: int = SETTINGS.default("hks_scale")
    error: str = ""
    message: str = ""
    # results
    heat: dict[str, FloatArray] = field(default_factory=dict)
    bound: float = float("nan")
    k_used: int = 0
    distance: FloatArray | None = None
    exact: FloatArray | None = None
    exact_error: FloatArray | None = None
    exact_stats: dict[str, float] = field(default_factory=dict)
    filtered: FloatArray | None = None
    gains: FloatArray | None = None
    measured: FloatArray | None = None  # per-mode amplification of the smoother, projected
    hks: FloatArray | None = None
    hks_dist: FloatArray | None = None
    version: int = 0  # bumped whenever a shown field changes
    _heat_solver: Any = None
    _geodesic: Any = None
    _geodesic_key: Any = None
    _filter: Any = None
    _pieces: Any = None  # (the drawn curve's λ (p,), its pieces G (p,n,c))
    _hks: Any = None  # (basis id, H (n,s), times (s,))

    # ------------------------------------------------------------------ lifetime
    def clear(self) -> None:
        """Forget the mesh's solvers and fields (a new mesh); the settings stay."""
        self.sources = []
        self.heat, self.bound, self.k_used = {}, float("nan"), 0
        self.distance = self.exact = self.exact_error = None
        self.exact_stats = {}
        self.filtered = self.gains = self.hks = self.hks_dist = self.measured = None
        self._heat_solver = self._geodesic = self._geodesic_key = None
        self._filter = self._hks = self._pieces = None
        self.error = self.message = ""
        self.playing = False
        self.version += 1

    def t(self, h: float) -> float:
        """The heat time ``10^log_t · h²``."""
        return float(10.0**self.log_t * h * h)

    # ------------------------------------------------------------------ sources
    def select(self, n: int, vertex: int, add: bool = False) -> bool:
        """Make ``vertex`` the source (``add``: one more source, as a shift-click does); False
        when out of range (nothing changes)."""
        if not 0 <= int(vertex) < n:
            return False
        v = int(vertex)
        if add:
            if v not in self.sources:
                self.sources = [*self.sources, v]
        else:
            self.sources = [v]
        self.exact = self.exact_error = None  # for the previous sources
        self.exact_stats = {}
        return True

    # ------------------------------------------------------------------ settings
    def set_log_t(self, value: float) -> None:
        log_t = SETTINGS["log_t"]
        if not math.isfinite(value):
            raise MeshError(f"must be a number between {log_t.lo:g} and {log_t.hi:g}", log_t.label)
        self.log_t = log_t.clamp(value)

    def toggle_play(self) -> None:
        """Play or pause the sweep of t; played from the top of the range, it starts over."""
        self.playing = not self.playing
        if self.playing and self.log_t >= LOG_T_RANGE[1]:
            self.log_t = LOG_T_RANGE[0]

    def play_step(self) -> bool:
        """Move ``log_t`` up by :data:`PLAY_STEP` while playing (stopping at the top of
        :data:`LOG_T_RANGE`); True when t moved."""
        if not self.playing:
            return False
        hi = LOG_T_RANGE[1]
        x = min(self.log_t + PLAY_STEP, hi)
        self.playing = x < hi
        moved = x != self.log_t
        self.log_t = float(x)
        return moved

    def set_m(self, value: float) -> None:
        """The heat time factor, in its setting's range (the previous one stays when not)."""
        m = SETTINGS["m"]
        self.m = m.checked(value, m.label)

    def set_choice(self, name: str, value: str) -> None:
        """Set the choice ``name`` (one of its setting's choices; ``MeshError`` otherwise)."""
        setattr(self, name, SETTINGS[name].checked(value, name))

    # ------------------------------------------------------------------ heat
    def heat_solver(self, V: FloatArray, F: Any) -> HeatDiffusion:
        if self._heat_solver is None:
            self._heat_solver = HeatDiffusion(V, F)
        return self._heat_solver

    def heat_work(
        self, V: FloatArray, F: Any, h: float, basis: SpectralBasis | None
    ) -> tuple[dict[str, FloatArray], float, int]:
        """The heat fields for the current settings, computed without changing what is shown
        (a job's work: a new τ refactorizes ``M + τK``): ``(fields, bound, k)``."""
        hd = self.heat_solver(V, F)
        t = self.t(h)
        u0 = unit_heat(np.asarray(self.sources), hd.mass)
        euler, spectral = HEAT_METHODS  # the two ways
        fields = {euler: hd.euler(u0, t, self.steps)}
        if basis is None:
            return fields, float("nan"), 0
        fields[spectral] = heat_spectral(basis, u0, t)
        fields["difference"] = fields[spectral] - fields[euler]
        return fields, truncation_bound(basis.eigenvalues, t, basis.k_max), basis.k_max

    def adopt_heat(self, result: tuple[dict[str, FloatArray], float, int]) -> None:
        self.heat, self.bound, self.k_used = result
        self.version += 1

    def compute_heat(self, V: FloatArray, F: Any, h: float, basis: SpectralBasis | None) -> None:
        """Heat at ``t`` from a unit at each source: backward Euler (``steps`` steps) and, with
        a basis, the eigen-expansion over all its modes and their difference."""
        if self.sources:
            self.adopt_heat(self.heat_work(V, F, h, basis))

    def heat_shown(self) -> tuple[FloatArray | None, tuple[float, float]]:
        """The heat field on the mesh and the one colour range of all three."""
        f = self.heat.get(self.heat_field, self.heat.get("euler"))
        return f, symmetric_range(*self.heat.values())

    # ------------------------------------------------------------------ distance
    def geodesic_key(self, mesh_version: int) -> tuple[Any, ...]:
        return (mesh_version, self.m, self.boundary)

    def geodesic_ready(self, mesh_version: int) -> bool:
        return self._geodesic is not None and self._geodesic_key == self.geodesic_key(mesh_version)

    def adopt_geodesic(self, solver: HeatGeodesic, key: tuple[Any, ...]) -> None:
        self._geodesic, self._geodesic_key = solver, key

    def adopt_distance(self, d: FloatArray) -> None:
        self.distance = d
        self.version += 1

    def compute_distance(self) -> None:
        """The heat method's distance from the sources (its solver precomputed)."""
        if self._geodesic is None or not self.sources:
            return
        self.distance = self._geodesic.distance(self.sources)
        self.version += 1

    def adopt_exact(self, exact: FloatArray) -> None:
        """The exact distance arrived: the relative error map of the heat method and its
        max/mean (vertices at distance 0 or unreachable left out)."""
        self.exact = np.asarray(exact)
        err = np.full(len(self.exact), np.nan)
        if self.distance is not None and len(self.distance) == len(self.exact):
            ok = np.isfinite(self.exact) & (self.exact > 0)
            err[ok] = np.abs(self.distance[ok] - self.exact[ok]) / self.exact[ok]
            good = err[ok]
            self.exact_stats = {
                "max": float(good.max()) if good.size else 0.0,
                "mean": float(good.mean()) if good.size else 0.0,
            }
        self.exact_error = err
        self.version += 1

    # ------------------------------------------------------------------ filters
    def smoother_step(self, basis: SpectralBasis) -> tuple[float, float]:
        """The smoothers' step ``s`` (default ``0.5 / λ_max`` of the basis) and Taubin's
        ``ν = −1.02 s`` (a pass band near 0)."""
        step = self.step or 0.5 / float(basis.eigenvalues[-1] or 1.0)
        return step, -1.02 * step

    def measure(self, basis: SpectralBasis) -> FloatArray:
        """Run the current smoother on the mesh (cotangent, frozen operator, the basis's mass)
        and project: the per-mode amplification (any thread; nothing stored)."""
        from meshlap_core.diffusion import smoother_transfer

        step, nu = self.smoother_step(basis)
        extra = {"taubin_nu": nu} if self.filter == "taubin" else {}
        return smoother_transfer(basis, self.filter, step, self.iters, **extra)[1]

    def curve_points(self, basis: SpectralBasis) -> FloatArray:
        """The drawn curve's control points ``(p,2)`` in ``λ`` of the basis (its knots are
        kept relative to the largest eigenvalue, so they survive a new basis)."""
        P = np.array(self.knots, dtype=np.float64)
        P[:, 0] *= float(basis.eigenvalues[-1]) or 1.0
        return P

    def move_knot(self, index: int, gain: float) -> None:
        """Drag control point ``index`` to the gain ``h`` (kept in :data:`GAIN_RANGE`; its λ
        stays).

        Raises
        ------
        MeshError
            A non-finite gain (the point stays).
        """
        if not math.isfinite(gain):
            raise MeshError(f"a gain must be finite, got {gain!r}", "drawn curve")
        knots = list(self.knots)
        h = float(min(max(gain, GAIN_RANGE[0]), GAIN_RANGE[1]))
        knots[index] = (float(knots[index][0]), h)
        self.knots = knots

    def filter_gains(self, basis: SpectralBasis) -> FloatArray:
        lam = basis.eigenvalues
        if self.filter == "drawn":
            return curve_gain(lam, self.curve_points(basis))
        step, nu = self.smoother_step(basis)
        return transfer(
            self.filter,  # type: ignore[arg-type]
            lam,
            step=step,
            iters=self.iters,
            nu=nu,
            keep=self.keep,
            band=self.band,
            gain=self.gain,
        )

    def compute_filter(self, basis: SpectralBasis) -> None:
        """``U h(Λ) Uᵀ M X`` for the current transfer function (coefficients projected once
        per basis)."""
        if self._filter is None or self._filter.basis is not basis:
            self._filter = SpectralFilter(basis)
            self._pieces = None
        self.gains = self.filter_gains(basis)
        if self.filter == "drawn":  # Σ_j y_j G_j: a drag costs a few axpys
            P = self.curve_points(basis)
            if self._pieces is None or not np.array_equal(self._pieces[0], P[:, 0]):
                self._pieces = (P[:, 0].copy(), self._filter.pieces(P[:, 0]))
            out = np.tensordot(P[:, 1], self._pieces[1], axes=1)
            self.filtered = out + self._filter.residual if self.residual else out
        else:
            self.filtered = self._filter.apply(self.gains, residual=self.residual)
        self.version += 1

    # ------------------------------------------------------------------ HKS
    def compute_hks(self, basis: SpectralBasis) -> None:
        """The scaled signature at the chosen time and, with a source, the signature distance
        from it."""
        if self._hks is None or self._hks[0] is not basis:
            times = hks_times(basis.eigenvalues, HKS_SCALES)
            self._hks = (basis, heat_kernel_signature(basis, times, scaled=True), times)
        H = self._hks[1]
        self.hks = H[:, min(self.hks_scale, H.shape[1] - 1)]
        self.hks_dist = hks_distance(H, self.sources[0]) if self.sources else None
        self.version += 1

    def hks_time(self) -> float:
        return float(self._hks[2][self.hks_scale]) if self._hks is not None else float("nan")


# ---------------------------------------------------------------- meshlap animate
def parse_log_range(text: str, flag: str) -> tuple[float, float]:
    """``"A:B"`` (log10 of t/h², ``A < B`` inside :data:`LOG_T_RANGE`) as two floats."""
    parts = str(text).split(":")
    try:
        a, b = (float(x) for x in parts)
    except ValueError:
        raise MeshError(f"expected A:B (log10 of t/h^2), got {text!r}", flag) from None
    lo, hi = LOG_T_RANGE
    if not (lo <= a < b <= hi):
        raise MeshError(f"needs {lo:g} <= A < B <= {hi:g}, got {text!r}", flag)
    return a, b


def _animation_check(opts: dict[str, Any]) -> None:
    if not opts.get("heat"):
        raise MeshError("the diffusion animation is the heat flow: add --heat", "--panel")
    if isinstance(opts.get("heat_t"), str):
        opts["heat_t"] = parse_log_range(opts["heat_t"], "--heat-t")
    if not 2 <= int(opts["heat_frames"]) <= 2000:
        raise MeshError(f"must be 2 to 2000, got {opts['heat_frames']}", "--heat-frames")
    if int(opts["heat_vertex"]) < -1:
        raise MeshError(f"must be a vertex index, got {opts['heat_vertex']}", "--heat-vertex")


def _animation_check_mesh(opts: dict[str, Any], mesh: Any) -> None:
    n = len(mesh.V)
    if not -1 <= int(opts["heat_vertex"]) < n:
        raise MeshError(
            f"vertex {opts['heat_vertex']} is out of range (the mesh has {n} vertices)",
            "--heat-vertex",
        )


def _animation_from_session(opts: dict[str, Any], values: dict[str, Any], source: Any) -> None:
    """A saved view: its first source heats (``--heat`` implied)."""
    opts["heat"] = True
    if opts.get("heat_vertex") is None and values.get("sources"):
        opts["heat_vertex"] = int(values["sources"][0])


ANIMATION = Animation(
    summary="heat flowing from a vertex (--heat): backward Euler, t swept on a log scale",
    options=(
        Option("--heat", "diffusion: heat flowing from --heat-vertex", store_true=True),
        Option(
            "--heat-vertex",
            "diffusion: the source vertex (default -1: the one facing the camera)",
            -1,
            int,
        ),
        Option(
            "--heat-t",
            "diffusion: log10 of t/h^2 from A to B (default -1:3)",
            "-1:3",
            metavar="A:B",
        ),
        Option("--heat-frames", "diffusion: number of frames (default 30)", 30, int),
    ),
    session_help="diffusion  the session's first source heats; --heat is implied",
    check=_animation_check,
    kind=lambda opts: "heat",
    fps={"heat": 10.0},
    frame_count=lambda opts: int(opts["heat_frames"]),
    from_session=_animation_from_session,
    check_mesh=_animation_check_mesh,
)
"""``meshlap animate --panel diffusion --heat``."""


SPEC = PanelSpec(
    name="diffusion",
    title="Diffusion",
    summary="heat from clicked vertices two ways, geodesic distance by the heat method, "
    "spectral filters and the heat kernel signature",
    panel="DiffusionPanel",
    state=DiffusionState,
    settings=SETTINGS,
    check_mesh=check_mesh,
    animation=ANIMATION,
    unsaved={
        "clear sources": "an action on the sources (declared): empties them",
        "show error map": "sets the heat field (declared) to difference in the distance view",
        "exact distance": "an action: a job (minutes on a scan), its error map shown when done",
        "measure by smoothing": "an action: runs the smoother and projects it (a job)",
        "play t": "an action: sweeps t up its log scale (log_t is declared)",
        "pause t": "an action: stops at the t shown (declared)",
    },
)
"""The Diffusion panel."""
