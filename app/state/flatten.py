"""Flatten panel state: the mesh opened into a disk (its cut, a seam the user clicks), each
map to the plane computed once per ``(method, boundary)`` and kept with what the panel draws
of it (the checkerboard's texture coordinates, the layout, the distortion maps, their
histograms and its row of the table), and ARAP stepped live. No polyscope import.

The heavy objects are the core's: one :class:`~meshlap_core.flatten.Flattener` per disk (its
factorizations shared by every map of that disk), one :class:`~meshlap_core.flatten.ARAP` per
boundary. A map is one job of the panel, :func:`compute` of a :class:`Request` (plain data),
adopted on the UI thread (:meth:`FlattenState.adopt`). The window runs the job in a child
process (CHOLMOD's factorizations hold the GIL, for seconds on a big scan: from a thread they
froze the window); the flattener then stays in the child and each job remakes the disk, an
ARAP run continuing from the last run's map. Elsewhere (headless renders, animations, tests,
a machine without child processes) the job runs in this process and the flattener and ARAP
objects are reused.
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import threading
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from meshlap_core.errors import MeshError, check_cancel
from meshlap_core.flatten import ARAP, Flattener, UVMap, unit_square_uv
from meshlap_core.options import (
    FLATTEN_BOUNDARIES,
    FLATTEN_METHOD_BOUNDARIES,
    FLATTEN_METHODS,
    MAX_FLATTEN_ITERS,
)
from meshlap_core.types import FloatArray, IntArray

from ..panel_spec import PanelSpec
from .animation import Animation, Option
from .settings import MAX_INT, Choice, Custom, Flag, Integer, Number, Settings, Toggle, shown

MAP_NAMES = {
    "tutte": "Tutte", "harmonic": "harmonic", "lscm": "LSCM", "scp": "spectral conformal",
    "arap": "ARAP",
}  # fmt: skip
"""How the panel names each map (the table, the captions)."""
DISTORTIONS = ("angle", "area")
"""What the layout and the copy of the mesh are coloured by."""
DISTORTION_LABELS = {
    "angle": "angle distortion sigma1/sigma2, 1 = conformal [dimensionless]",
    "area": "area distortion log(sigma1 sigma2), 0 = area kept [dimensionless]",
}
"""Each distortion's quantity and unit: its colour bar's title and its histogram's x axis."""
MAX_SEAM_CLICKS = 10_000
"""Most vertices a clicked seam holds (each joined to the next by a shortest edge path)."""
HISTOGRAM_BINS = 40
LIVE_EVERY_S = 0.1
"""ARAP hands the window its map at most this often."""
LIVE_SHARE = 0.2
"""At most this share of a live ARAP run goes to measuring and handing over its maps (the
distortion of every face, and from a child process the arrays sent): the next map is handed
over once four times the last hand-over's cost has passed."""


def check_seam(x: Any) -> str | None:
    """A list of at most :data:`MAX_SEAM_CLICKS` vertex indices (the session's mesh bounds
    them: :func:`check_mesh`)."""
    if not isinstance(x, list):
        return f"must be a list of vertices, got {shown(x)}"
    if len(x) > MAX_SEAM_CLICKS:
        return f"has {len(x)} vertices; a seam holds at most {MAX_SEAM_CLICKS}"
    for v in x:
        if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v < MAX_INT:
            return f"has {shown(v)}; a seam vertex is a vertex index (an integer >= 0)"
    return None


def without_repeats(clicks: list[int]) -> list[int]:
    """The clicked vertices without a vertex clicked twice in a row (no edge joins them)."""
    return [int(v) for i, v in enumerate(clicks) if i == 0 or v != clicks[i - 1]]


# fmt: off
SETTINGS = Settings(
    Choice("method", "tutte", choices=FLATTEN_METHODS, label="map",
           tooltip="tutte: uniform weights, boundary fixed (bijective on a convex boundary); "
           "harmonic: cotangent weights, boundary fixed; lscm: least-squares conformal, two "
           "pinned vertices; scp: spectral conformal (Mullen et al. 2008); arap: as rigid as "
           "possible, local/global iterations (Liu et al. 2008)",
           view=Flag("--map", "the map to the plane")),
    Choice("boundary", "free", choices=FLATTEN_BOUNDARIES, label="boundary",
           tooltip="where the outer boundary goes, for the maps that take a shape: the unit "
           "circle or square by arc length, or free (the map's own; Tutte's and the harmonic "
           "map have none: they take the circle)",
           view=Flag("--map-boundary", "the boundary shape, where the map takes one"),
           animate=Flag("--map-boundary", "ARAP's boundary", default="free")),
    Integer("iters", 50, lo=1, hi=MAX_FLATTEN_ITERS, label="ARAP iterations", widget="input",
            tooltip="local/global iterations per run (run again to continue from there)"),
    Number("checker", 0.04, lo=0.002, hi=0.5, slider=(0.005, 0.2), fmt="%.3f",
           label="checker size", tooltip="side of a checker square, as a fraction of the "
           "layout's width", view=Flag("--checker", "checker size (fraction of the layout)"),
           animate=Flag("--checker", "checker size (fraction of the layout)")),
    Choice("distortion", "angle", choices=DISTORTIONS, label="distortion",
           tooltip="angle: sigma1/sigma2 of each face's Jacobian (1: conformal); area: "
           "log(sigma1 sigma2) (0: area kept), on the layout and on a copy of the mesh",
           view=Flag("--distortion", "what the layout is coloured by")),
    Toggle("copy", True, label="distortion on the surface",
           tooltip="a copy of the mesh coloured by the distortion, beside the layout"),
    Custom("seam", [], check=check_seam, normalize=without_repeats, widget="none",
           example=[0, 1], refused=("3", [1.5], [-1], [True], [10**400], {"0": 1},
                                     [0] * (MAX_SEAM_CLICKS + 1))),
)
# fmt: on
"""The Flatten panel's settings: the map, its boundary, ARAP's run, the checkerboard, what the
layout shows, and the clicked seam (vertices joined by shortest edge paths, cut first)."""


def check_mesh(values: dict[str, Any], mesh: Any, source: Any) -> None:
    """Saved seam vertices the session's mesh has.

    Raises
    ------
    MeshError
        A seam vertex beyond the mesh's vertices.
    """
    n = len(mesh.V)
    bad = next((v for v in values["seam"] if v >= n), None)
    if bad is not None:
        raise MeshError(f'"flatten.seam" has {bad}; vertices are 0..{n - 1}', source)


def boundary_for(method: str, boundary: str) -> str:
    """The boundary ``method`` uses: ``boundary`` where it takes it, else its own default
    (:data:`~meshlap_core.options.FLATTEN_METHOD_BOUNDARIES`)."""
    allowed = FLATTEN_METHOD_BOUNDARIES[method]
    return boundary if boundary in allowed else allowed[0]


def seam_path(V: FloatArray, F: IntArray, clicks: list[int]) -> IntArray:
    """The clicked vertices joined in order, each to the next by the shortest edge path
    (Dijkstra on edge lengths): a path along edges ``(k,)`` (empty for fewer than two
    clicks).

    Raises
    ------
    MeshError
        A clicked vertex the mesh does not have, or one no edge path reaches from the one
        before (another component).
    """
    clicks = without_repeats(list(clicks))
    bad = next((v for v in clicks if not 0 <= v < len(V)), None)
    if bad is not None:
        raise MeshError(f"vertex {bad} is out of range; the mesh has {len(V)} vertices", "seam")
    if len(clicks) < 2:
        return np.zeros(0, dtype=np.int64)
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    length = np.maximum(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1), np.finfo(float).tiny)
    G = sp.csr_matrix((length, (E[:, 0], E[:, 1])), shape=(len(V), len(V)))
    path = [clicks[0]]
    for a, b in itertools.pairwise(clicks):
        _, pred = dijkstra(G, directed=False, indices=a, return_predecessors=True)
        if pred[b] < 0:
            raise MeshError(f"no edge path joins vertices {a} and {b}", "seam")
        piece = [b]
        while piece[-1] != a:
            piece.append(int(pred[piece[-1]]))
        path.extend(reversed(piece[:-1]))
    return np.asarray(path, dtype=np.int64)


# ---------------------------------------------------------------- what the panel draws
@dataclass(eq=False)
class MapView:
    """One computed map and what the panel draws of it (made in the job's thread).

    Attributes
    ----------
    uvmap : UVMap
        The core's map (``uv`` per disk vertex, its distortion).
    uv01 : (n',2) float
        The map moved and scaled uniformly into ``[0, 1]²`` (the checkerboard's and the
        layout's coordinates).
    corners : (3m,2) float32
        ``uv01`` at every face corner (polyscope's corner parameterization of the input; it
        keeps single precision).
    values : dict
        Per face ``(m,)``: ``"angle"`` σ₁/σ₂ and ``"area"`` log σ₁σ₂, infinite (collapsed
        faces) replaced by the colour range's end.
    ranges : dict
        Each distortion's colour range.
    histograms : dict
        Each distortion's ``(centers, counts, width)`` over its colour range (values clipped
        into it).
    flipped : (k,) int
        The flipped faces.
    row : dict
        The map's row of the table (:meth:`UVMap.summary`).
    seconds : float
        The panel's own time to make this (after the map).
    """

    uvmap: UVMap
    uv01: FloatArray
    corners: FloatArray
    values: dict[str, FloatArray]
    ranges: dict[str, tuple[float, float]]
    histograms: dict[str, tuple[FloatArray, FloatArray, float]]
    flipped: IntArray
    row: dict[str, Any]
    seconds: float = 0.0

    @property
    def key(self) -> tuple[str, str]:
        return self.uvmap.method, self.uvmap.boundary


RANGE_QUANTILE = 0.95
"""A distortion's colour range ends at this quantile of its faces: a few folded faces (ARAP's
can reach σ₁/σ₂ of thousands) would leave the rest of the map one colour."""


def color_range(kind: str, values: FloatArray) -> tuple[float, float]:
    """The colour range of a distortion: ``[1, q]`` for the angle (``q`` its
    :data:`RANGE_QUANTILE`), ``[−r, r]`` for the area (``r`` that quantile of
    ``|log σ₁σ₂|``); never empty."""
    v = values[np.isfinite(values)]
    if kind == "angle":
        hi = float(np.quantile(v, RANGE_QUANTILE)) if v.size else 1.0
        return 1.0, max(hi, 1.0 + 1e-3)
    r = float(np.quantile(np.abs(v), RANGE_QUANTILE)) if v.size else 0.0
    return -max(r, 1e-3), max(r, 1e-3)


def describe(uvmap: UVMap) -> MapView:
    """Everything the panel draws of ``uvmap`` (vectorized; any thread)."""
    t0 = time.perf_counter()
    d = uvmap.distortion()
    uv01 = unit_square_uv(uvmap.uv)
    values, ranges, histograms = {}, {}, {}
    for kind, raw in (("angle", d.angle), ("area", d.area)):
        lo, hi = ranges[kind] = color_range(kind, raw)
        v = np.where(np.isfinite(raw), raw, hi if kind == "angle" else lo)
        values[kind] = v
        counts, edges = np.histogram(np.clip(v, lo, hi), bins=HISTOGRAM_BINS, range=(lo, hi))
        centers = 0.5 * (edges[:-1] + edges[1:])
        histograms[kind] = (centers, counts.astype(np.float64), float(edges[1] - edges[0]))
    return MapView(
        uvmap=uvmap,
        uv01=uv01,
        corners=uv01[uvmap.disk.F].reshape(-1, 2).astype(np.float32),
        values=values,
        ranges=ranges,
        histograms=histograms,
        flipped=np.flatnonzero(d.flipped),
        row=uvmap.summary(),
        seconds=time.perf_counter() - t0,
    )


def screen_axes(toward_eye: tuple[float, float, float]) -> tuple[FloatArray, FloatArray]:
    """The screen's right and up directions ``(3,)`` for a camera looking from
    ``toward_eye`` (y up), as :func:`meshlap_app.scene.side_offset` and the framing take
    them: the layout lies in the plane they span, facing the camera."""
    back = np.asarray(toward_eye, dtype=np.float64)
    back = back / np.linalg.norm(back)
    right = np.cross(np.array([0.0, 1.0, 0.0]), back)
    right /= max(float(np.linalg.norm(right)), 1e-12)
    return right, np.cross(back, right)


def place_row(
    P: FloatArray, toward_eye: tuple[float, float, float], gap: float = 0.15
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Where the layout and the copy go beside the mesh shown at ``P (n,3)`` (display
    coordinates): the layout is ``origin + uv01 @ axes`` (``origin (3,)``, ``axes (2,3)``),
    the unit square in the screen plane as large as the mesh's larger side, right of the
    mesh; the copy's ``offset (3,)`` puts it right of the layout, ``gap`` of that size
    apart."""
    right, up = screen_axes(toward_eye)
    x, y = P @ right, P @ up
    size = max(float(np.ptp(x)), float(np.ptp(y)), 1e-12)
    space = gap * size
    centre = 0.5 * (P.min(axis=0) + P.max(axis=0))
    start = float(x.max()) + space  # the layout's left edge
    origin = centre + (start - centre @ right) * right - 0.5 * size * up
    offset = (start + size + space - float(x.min())) * right
    return origin, size * np.stack([right, up]), offset


def face_of(kind: str, index: int, position: FloatArray, P: FloatArray, F: IntArray) -> int:
    """The face a pick hit: the face itself, else the face around the picked vertex (any
    other element: of the whole mesh) whose centroid is nearest the hit ``position``
    (``P (n,3)``, ``F (m,3)`` the picked structure's positions and faces)."""
    if kind == "face":
        return int(index)
    faces = np.flatnonzero((F == int(index)).any(axis=1)) if kind == "vertex" else np.arange(len(F))
    if len(faces) == 0:
        faces = np.arange(len(F))
    centres = P[F[faces]].mean(axis=1)
    return int(faces[np.argmin(np.linalg.norm(centres - np.asarray(position), axis=1))])


# ---------------------------------------------------------------- the state
@dataclass
class FlattenState:
    """Settings, the disk and its maps, the live ARAP run and the clicked face.

    ``maps`` holds every map computed on the current disk by ``(method, boundary)``;
    ``shown`` is the one on screen (the last good one stays while another is computed);
    ``arap`` keeps an ARAP object per boundary, so a run continues where the last one
    stopped (``None`` when it ran in a child process: the next run starts from its map).
    ``flattener`` is the disk's when the maps are computed in this process. ``lock``
    serializes the jobs' use of the flattener and the ARAP objects (a cancelled job may
    still be finishing its step when the next one starts).
    """

    method: str = SETTINGS.default("method")
    boundary: str = SETTINGS.default("boundary")
    iters: int = SETTINGS.default("iters")
    checker: float = SETTINGS.default("checker")
    distortion: str = SETTINGS.default("distortion")
    copy: bool = SETTINGS.default("copy")
    seam: list[int] = field(default_factory=list)
    face: int = -1  # the clicked face (-1: none)
    flattener: Flattener | None = None
    disk_key: tuple[Any, ...] | None = None  # (mesh version, seam clicks) of the maps
    failed: tuple[Any, ...] | None = None  # the (disk, map) whose job failed
    maps: dict[tuple[str, str], MapView] = field(default_factory=dict)
    shown: MapView | None = None
    arap: dict[str, ARAP | None] = field(default_factory=dict)
    live_rate: float = 0.0  # ARAP iterations per second of the current (or last) run
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    version: int = 0  # bumped whenever what is shown changes

    # ------------------------------------------------------------------ lifetime
    def clear(self) -> None:
        """Forget the mesh's disk, maps, ARAP runs and seam (a new mesh: its vertices are not
        the seam's); the other settings stay."""
        self.new_disk(None)
        self.shown, self.face, self.seam = None, -1, []

    # ------------------------------------------------------------------ settings
    @property
    def key(self) -> tuple[str, str]:
        """The map the settings ask for: ``(method, boundary it uses)``."""
        return self.method, boundary_for(self.method, self.boundary)

    def set_choice(self, name: str, value: str) -> None:
        """Set the choice ``name`` (one of its setting's; ``MeshError`` otherwise)."""
        setattr(self, name, SETTINGS[name].checked(value, SETTINGS[name].label))
        self.version += 1

    def set_checker(self, value: float) -> None:
        """The checker size, clamped into its range (``MeshError`` for a non-number)."""
        s = SETTINGS["checker"]
        if not isinstance(value, int | float) or not np.isfinite(value):
            raise MeshError(f"must be a number between {s.lo:g} and {s.hi:g}", s.label)
        self.checker = s.clamp(value)
        self.version += 1

    def set_iters(self, value: int) -> None:
        """ARAP's iterations per run, in its setting's range (the previous stays when not)."""
        self.iters = SETTINGS["iters"].checked(value, SETTINGS["iters"].label)

    def disk_wanted(self, version: int) -> tuple[Any, ...]:
        """The disk key for the mesh ``version`` and the seam (fewer than two clicks: none)."""
        clicks = tuple(self.seam) if len(self.seam) >= 2 else ()
        return (version, clicks)

    # ------------------------------------------------------------------ the seam
    def add_seam_vertex(self, n: int, vertex: int) -> bool:
        """Append a clicked vertex to the seam (False: out of range, or the last one again,
        or the seam is full: nothing changes)."""
        v = int(vertex)
        if not 0 <= v < n or (self.seam and self.seam[-1] == v):
            return False
        if len(self.seam) >= MAX_SEAM_CLICKS:
            return False
        self.seam = [*self.seam, v]
        return True

    def undo_seam(self) -> bool:
        """Drop the last clicked seam vertex; False when there is none."""
        if not self.seam:
            return False
        self.seam = self.seam[:-1]
        return True

    # ------------------------------------------------------------------ jobs
    def request(self, V: FloatArray, F: IntArray, version: int) -> Request:
        """What a job computes for the settings now (the disk of the mesh ``version``; an
        ARAP run continues the map of the last run on its boundary)."""
        method, boundary = self.key
        last = self.maps.get(self.key) if method == "arap" else None
        return Request(
            V, F, self.disk_wanted(version), method, boundary, int(self.iters),
            None if last is None else last.uvmap.uv,
            [] if last is None else list(last.uvmap.energies),
            0.0 if last is None else last.uvmap.seconds,
        )  # fmt: skip

    def adopt(self, result: Computed, disk: tuple[Any, ...]) -> None:
        """A job's map (or an ARAP run's latest), computed on the disk ``disk``: kept, and
        shown when it is the one asked for; its flattener and ARAP object (a job in this
        process) kept for the next maps."""
        flat, arap, view, rate = result
        if disk != self.disk_key:  # (a job of another seam or mesh: not this disk's)
            return
        if flat is not None:
            self.flattener = flat
        if view.uvmap.method == "arap":
            self.arap[view.uvmap.boundary] = arap  # (None: the next run starts from the map)
            self.live_rate = rate
        self.maps[view.key] = view
        if view.key == self.key:
            self.shown = view
            if not 0 <= self.face < len(view.uvmap.disk.F):
                self.face = -1
        self.version += 1

    def new_disk(self, disk: tuple[Any, ...] | None) -> None:
        """The mesh or the seam changed: the maps of the old disk go (the one on screen
        stays until the new disk's arrives)."""
        self.flattener, self.disk_key, self.failed = None, disk, None
        self.maps, self.arap, self.live_rate = {}, {}, 0.0
        self.version += 1

    # ------------------------------------------------------------------ what is shown
    def rows(self) -> list[dict[str, Any]]:
        """The table: one row per computed map, in the order of the methods and boundaries."""
        order = [(m, b) for m in FLATTEN_METHODS for b in FLATTEN_BOUNDARIES]
        return [self.maps[k].row for k in order if k in self.maps]

    def ellipse(self, radius_factor: float = 2.0) -> tuple[Any, FloatArray, FloatArray] | None:
        """The clicked face's :class:`~meshlap_core.flatten.FaceEllipse` and its circle on
        the surface ``(c,3)`` (input coordinates) and image in the layout ``(c,2)``
        (``uv01`` coordinates); ``None`` without a face or a map."""
        view = self.shown
        if view is None or self.face < 0:
            return None
        d = view.uvmap.distortion()
        e = d.ellipse(self.face)
        V = view.uvmap.disk.V
        diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
        radius = max(radius_factor * float(np.sqrt(d.face_area[self.face])), 0.02 * diag)
        circle, image = e.polylines(radius)
        return e, circle, to_unit(view.uvmap.uv, image)


Computed = tuple[Any, Any, "MapView", float]
"""What a job returns: ``(flattener, ARAP object, map drawn, ARAP's iterations per second)``,
the first two ``None`` from a child process (they stay there)."""


@dataclass(frozen=True)
class Request:
    """One map asked of a job, as plain data (it may cross to a child process).

    Attributes
    ----------
    V : (n,3) float
    F : (m,3) int
    disk : tuple
        ``(mesh version, seam clicks)``: the disk the map is of.
    method, boundary : str
    iters : int
        ARAP's iterations.
    start : (n',2) float or None
        ARAP's map to continue from (``None``: its start map).
    energies : list of float
        ARAP's energies so far (continued).
    spent : float
        ARAP's seconds so far.
    """

    V: FloatArray
    F: IntArray
    disk: tuple[Any, ...]
    method: str
    boundary: str
    iters: int = 1
    start: FloatArray | None = None
    energies: list[float] = field(default_factory=list)
    spent: float = 0.0


def compute(
    req: Request,
    flat: Flattener | None = None,
    arap: ARAP | None = None,
    lock: Any = None,
    *,
    progress: Any = None,
) -> Computed:
    """The map ``req`` asks for and what the panel draws of it (any thread, or a child
    process: :func:`meshlap_app.jobs.in_child`). ``flat`` (the disk's flattener) and
    ``arap`` (the last run's object) are reused when given, else made; ``lock`` serializes
    their use (a cancelled job may still be finishing a step). ARAP hands its maps to the
    window as it goes (``progress.partial``; at most every :data:`LIVE_EVERY_S`, and within
    :data:`LIVE_SHARE` of its time)."""
    cancel = getattr(progress, "cancel", None)
    remote = bool(getattr(progress, "remote", False))
    report = progress if progress is not None else (lambda *a: None)
    with lock if lock is not None else contextlib.nullcontext():
        if flat is None:
            clicks = req.disk[1]
            report(0.0, "joining the seam" if clicks else "cutting to a disk")
            path = seam_path(req.V, req.F, list(clicks)) if clicks else None
            flat = Flattener(req.V, req.F, path, progress=progress, cancel=cancel)
        if req.method != "arap":
            view = describe(flat.map(req.method, req.boundary, progress=progress, cancel=cancel))
            return (None, None, portable(view), 0.0) if remote else (flat, None, view, 0.0)
    return _arap_run(req, flat, arap, lock, progress, remote)


def _arap_run(
    req: Request, flat: Flattener, arap: ARAP | None, lock: Any, progress: Any, remote: bool
) -> Computed:
    """``req.iters`` iterations of ARAP, continuing ``arap`` or ``req.start`` (see
    :func:`compute`)."""
    cancel = getattr(progress, "cancel", None)
    report = progress if progress is not None else (lambda *a: None)
    partial = getattr(progress, "partial", None)
    guard = lock if lock is not None else contextlib.nullcontext()
    t0 = time.perf_counter()
    with guard:
        if arap is None:
            report(0.0, "ARAP: its start map and factorization")
            arap = flat.arap(req.boundary, cancel=cancel)
            if req.start is not None:  # continue the last run (its map and energies)
                arap = continued(flat, arap, req)
    spent, begun, last = req.spent + time.perf_counter() - t0, time.perf_counter(), -np.inf
    start, rate, cost = arap.iterations, 0.0, 0.0

    def drawn() -> Computed:
        now = time.perf_counter()
        view = describe(arap_map(flat, arap, req.boundary, spent + now - begun))
        return (None, None, portable(view), rate) if remote else (flat, arap, view, rate)

    for i in range(req.iters):
        with guard:
            check_cancel(cancel, "ARAP")  # Cancel: between iterations
            energy = arap.step()
        now = time.perf_counter()
        rate = (arap.iterations - start) / max(now - begun, 1e-9)
        report((i + 1) / req.iters, f"iteration {arap.iterations}: E = {energy:.6g}")
        wait = max(LIVE_EVERY_S, cost * (1.0 - LIVE_SHARE) / LIVE_SHARE)
        if partial is not None and now - last >= wait and i + 1 < req.iters:
            partial(drawn())
            last = time.perf_counter()
            cost = last - now
    return drawn()


def continued(flat: Flattener, fresh: ARAP, req: Request) -> ARAP:
    """An ARAP object at the map ``req.start`` of a run made elsewhere (a child process
    that ended), with that run's energies and iteration count: the next iteration is the
    one that run would have made (the local step depends on the map alone; the pinned
    vertices are where the start map put them)."""
    arap = ARAP(
        flat.disk.V, flat.disk.F, req.start, pinned=fresh.pinned, frames=flat.frames,
        cot=flat.cotangents, K=flat.stiffness("cotan"),
    )  # fmt: skip
    if req.energies:
        arap.energies = [*req.energies[:-1], arap.energy]
        arap.iterations = len(req.energies) - 1
    return arap


def portable(view: MapView) -> MapView:
    """``view`` without what stays in the process that made it (the flattener and its
    factorizations, the disk's edge table): what a child process sends back."""
    view.uvmap.distortion()  # (measured here, with the flattener's frames)
    view.uvmap.flattener = None
    view.uvmap.disk = dataclasses.replace(view.uvmap.disk, table=None)
    return view


def to_unit(uv: FloatArray, points: FloatArray) -> FloatArray:
    """``points (k,2)`` in the coordinates of the map ``uv (n,2)`` moved and scaled as
    :func:`~meshlap_core.flatten.unit_square_uv` moves ``uv``."""
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    size = float((hi - lo).max())
    return (points - 0.5 * (lo + hi)) * (1.0 / size if size > 0 else 1.0) + 0.5


def arap_map(flat: Flattener, arap: ARAP, boundary: str, seconds: float) -> UVMap:
    """ARAP's current map as a :class:`UVMap` (a copy of its coordinates)."""
    return UVMap(
        "arap", boundary, arap.uv.copy(), flat.disk, seconds, iterations=arap.iterations,
        energies=list(arap.energies), flattener=flat,
    )  # fmt: skip


# ---------------------------------------------------------------- meshlap animate
def _animation_check(opts: dict[str, Any]) -> None:
    if not 1 <= int(opts["arap_iters"]) <= 2000:
        raise MeshError(f"must be 1 to 2000, got {opts['arap_iters']}", "--arap-iters")


ANIMATION = Animation(
    summary="ARAP's local/global iterations from its start map (--arap-iters), the "
    "checkerboard on the mesh and the layout beside it",
    options=(
        Option("--arap-iters", "flatten: ARAP iterations, one frame each (default 30)", 30, int),
    ),
    session_help="flatten  the session's seam, checker size and ARAP boundary",
    check=_animation_check,
    kind=lambda opts: "arap",
    fps={"arap": 8.0},
    frame_count=lambda opts: int(opts["arap_iters"]) + 1,
)
"""``meshlap animate --panel flatten``: ARAP's iterations."""


SPEC = PanelSpec(
    name="flatten",
    title="Flatten",
    summary="maps to the plane (Tutte, harmonic, LSCM, spectral conformal, ARAP): the "
    "checkerboard through the map, the layout, flipped triangles and the angle and area "
    "distortion",
    panel="FlattenPanel",
    state=FlattenState,
    settings=SETTINGS,
    check_mesh=check_mesh,
    animation=ANIMATION,
    unsaved={
        "clear face": "an action: no clicked face (the face is the setting)",
        "clear seam": "an action: no seam (the seam is the setting)",
        "undo seam vertex": "an action: the seam without its last vertex (the seam is kept)",
        "run ARAP": "an action: ARAP iterates from the map shown (the result is recomputed)",
        "restart ARAP": "an action: ARAP again from its initial map",
    },
)
"""The Flatten panel."""
