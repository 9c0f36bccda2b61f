"""Deform panel state: handles grown from clicked vertices, the region held fixed, each handle's
rigid move, and the deformers that follow (no polyscope import).

A *handle set* (seeds grown into geodesic discs, the region held, one deformer per shown
method: :mod:`.handle_sets`) is built once, by a job of the panel; every move of a handle is
then one cheap call (:meth:`DeformState.solve`: one back-substitution, or ARAP iterations).
A handle's *move* (:mod:`.moves`) is a rigid motion of its disc, as ``meshlap deform --rotate
--move`` says it. A session saves the seeds, the radius, the fixed region and the moves (it
reopens the same deformation); the undo history holds whole lists of moves.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.deform import (
    ArapDeformer,
    Deformer,
    rigid_targets,
    rotation_error,
)
from meshlap_core.errors import MeshError
from meshlap_core.options import ARAP_ENERGIES, DEFAULT_ARAP_ENERGY, DEFORM_METHODS
from meshlap_core.types import FloatArray

from ..panel_spec import PanelSpec
from .animation import Animation, Option
from .handle_sets import Built, close_set
from .moves import (
    IDENTITY,
    MAX_HANDLES,
    check_moves,
    check_seeds,
    diagonal,
    distinct,
    identity,
    move_matrix,
    move_problem,
    normal_moves,
)
from .settings import (
    Choice,
    Custom,
    Flag,
    Integer,
    Number,
    Settings,
    shown,
)

ARAP_TOLERANCE = 1e-9
"""ARAP stops iterating once an iteration lowers the energy by less than this fraction."""
INLINE_SOLVE_MAX = 120_000
"""Up to this many vertices a move is solved on the UI thread (at 43k vertices: a harmonic
update 3.5 ms, biharmonic 13 ms, triharmonic 20–50 ms, an ARAP iteration 32 ms); above, each
solve is a job and the window keeps drawing (about a second per update at 692k)."""
COMPARE: tuple[str, ...] = ("none", *DEFORM_METHODS)
"""The second method shown beside the first on the same handles (``none``: one copy)."""
COLOURS: tuple[str, ...] = ("displacement", "rotation error", "none")
"""The colour map on the deformed copies."""
FIXED_REGIONS: tuple[str, ...] = ("farthest", "clicked", "none")
"""What is held at rest: the vertices farthest from every handle, discs around ctrl-clicked
vertices, or nothing (components holding no handle stay at rest)."""
QUANTITY = {
    "displacement": "displacement |x - p| [length]",
    "rotation error": "rotation error, relative RMS of the one-ring [dimensionless]",
}
"""Each colour map's quantity as its colour bar names it (what, and its unit)."""
ENERGY_FORMULA = {
    "laplacian": "|L x - delta|^2_M (+ w^2 |x_c - t_c|^2): keep the Laplacian coordinates",
    "harmonic": "int |grad d|^2 of the displacement d = x - p (Delta d = 0)",
    "biharmonic": "int (Delta d)^2 of the displacement (Delta^2 d = 0)",
    "triharmonic": "int |grad Delta d|^2 of the displacement (Delta^3 d = 0)",
    "arap": "sum_i sum_j w_ij |(x_i - x_j) - R_i (p_i - p_j)|^2 (local rotations R_i)",
}
"""What each method minimizes, in one line (the core's ``energy_name`` is shown beside it)."""
# fmt: off
SETTINGS = Settings(
    Choice("method", "arap", choices=DEFORM_METHODS, label="method",
           tooltip="laplacian: keep Delta x (Sorkine et al. 2004); harmonic / biharmonic / "
           "triharmonic: Delta^k d = 0 for the displacement d = x - p; arap: local rotations "
           "and a global solve, iterated (Sorkine & Alexa 2007)",
           view=Flag("--deform-method", "the deformation method"),
           animate=Flag("--deform-method", "the deformation method")),
    Choice("compare", "none", choices=COMPARE, label="side by side",
           tooltip="a second method on the same handles, on a copy beside the first",
           view=Flag("--deform-compare", "a second method beside the first")),
    Number("radius", 5.0, lo=0.0, hi=50.0, slider=(0.0, 10.0), fmt="%.2f",
           label="handle radius %",
           tooltip="each clicked vertex grows into a geodesic disc of this radius, in % of "
           "the bounding-box diagonal (0: the vertex alone)",
           view=Flag("--handle-radius", "handle disc radius in percent of the box diagonal"),
           animate=Flag("--handle-radius", "handle disc radius in percent of the diagonal")),
    Choice("fixed_region", "farthest", choices=FIXED_REGIONS, label="fixed region",
           tooltip="farthest: the vertices farthest from every handle; clicked: discs around "
           "ctrl-clicked vertices; none: nothing held (a lone handle then moves its part "
           "rigidly)"),
    Number("fixed_fraction", 0.1, lo=0.0, lo_open=True, hi=0.9, fmt="%.2f",
           label="farthest share",
           tooltip="the fixed region: vertices at least (1 - share) of the largest distance "
           "from the handles"),
    Custom("handles", [], check=check_seeds, normalize=distinct, widget="none",
           example=[3, 40],
           refused=("3", [1.5], [-1], [True], [10**400], list(range(MAX_HANDLES + 1)))),
    Custom("fixed", [], check=check_seeds, normalize=distinct, widget="none", example=[100],
           refused=({"0": 1}, [-2], [None])),
    Custom("moves", [], check=check_moves, normalize=normal_moves, widget="none",
           example=[{"rotate": [0.0, 0.0, 1.0, 30.0], "move": [0.1, 0.0, 0.0]},
                    {"rotate": [0.0, 0.0, 1.0, 0.0], "move": [0.0, 0.0, 0.0]}],
           refused=([1], [{"rotate": [0, 0, 1], "move": [0, 0, 0]}],
                    [{"rotate": [0, 0, 0, 10], "move": [0, 0, 0]}],
                    [{"rotate": [0, 0, 1, 10], "move": [0, float("nan"), 0]}],
                    [{"rotate": [0, 0, 1, 720], "move": [0, 0, 0]}],
                    [{"rotate": [0, 0, 1, 0], "move": [0, 0, 10**400]}])),
    Choice("arap_energy", DEFAULT_ARAP_ENERGY, choices=ARAP_ENERGIES, label="ARAP energy",
           tooltip="the edges each rotation fits: the one-ring's spokes (Sorkine & Alexa) or "
           "spokes and rims (libigl's default)"),
    Integer("arap_per_frame", 1, lo=1, hi=100, label="ARAP iterations per frame",
            tooltip="local/global iterations done each frame while ARAP has not converged",
            animate=Flag("--arap-per-frame", "ARAP iterations per frame", default=10)),
    Integer("arap_max", 200, lo=1, hi=100_000, widget="input", label="ARAP iterations per move",
            tooltip="ARAP stops after this many iterations since the handles last moved (or "
            f"once an iteration lowers the energy by less than {ARAP_TOLERANCE:g} of it)"),
    Choice("colour", "displacement", choices=COLOURS, label="colour",
           tooltip="displacement: |x - p| per vertex (mesh units); rotation error: how far "
           "each vertex's one-ring is from a rotation of its rest shape (relative RMS)"),
)
# fmt: on
"""The Deform panel's section of a saved session: the handle seeds, radius, fixed region and
moves (one per seed) reopen the same deformation."""


def check_section(values: dict[str, Any], source: Any) -> None:
    """One move per handle seed (an older list without moves: every handle at rest), and no
    vertex both a handle seed and a fixed seed.

    Raises
    ------
    MeshError
        More moves than seeds, or a seed in both lists.
    """
    h, m = values["handles"], values["moves"]
    if len(m) > len(h) or (m and len(m) != len(h)):
        raise MeshError(
            f'"deform.moves" holds {len(m)} moves for {len(h)} handle seeds (one each)', source
        )
    if not m:
        values["moves"] = [identity() for _ in h]
    both = sorted(set(h) & set(values["fixed"]))
    if both:
        raise MeshError(f'"deform.fixed" has {both[0]}, a handle seed too', source)


def check_mesh(values: dict[str, Any], mesh: Any, source: Any) -> None:
    """Seeds the session's mesh has, and moves within a thousand bounding-box diagonals.

    Raises
    ------
    MeshError
        A seed beyond the mesh's vertices or a move too far, naming the key.
    """
    n = len(mesh.V)
    for key in ("handles", "fixed"):
        bad = next((v for v in values[key] if v >= n), None)
        if bad is not None:
            raise MeshError(f'"deform.{key}" has {bad}; vertices are 0..{n - 1}', source)
    far = 1000.0 * diagonal(mesh.V)
    for m in values["moves"]:
        if max(abs(x) for x in m["move"]) > far:
            raise MeshError(
                f'"deform.moves" moves a handle by {shown(m["move"])}, farther than 1000 '
                "bounding-box diagonals",
                source,
            )


def check_start(options: dict[str, Any], state: Any) -> None:
    """``meshlap view --deform-compare``: not the method itself (nothing to compare)."""
    method, compare = options.get("deform_method"), options.get("deform_compare")
    if compare is not None and compare != "none" and compare == method:
        raise MeshError(f"{compare} is the method itself; pick another", "--deform-compare")


@dataclass
class Shown:
    """One deformer's result on screen."""

    positions: FloatArray  # (n,3) deformed
    solve_seconds: float = 0.0  # the last update (or ARAP iteration batch)


@dataclass
class DeformState:
    """The settings (:data:`SETTINGS`), the handle set built, and what the panel shows."""

    method: str = SETTINGS.default("method")
    compare: str = SETTINGS.default("compare")
    radius: float = SETTINGS.default("radius")
    fixed_region: str = SETTINGS.default("fixed_region")
    fixed_fraction: float = SETTINGS.default("fixed_fraction")
    handles: list[int] = field(default_factory=list)
    fixed: list[int] = field(default_factory=list)
    moves: list[dict[str, Any]] = field(default_factory=list)
    arap_energy: str = SETTINGS.default("arap_energy")
    arap_per_frame: int = SETTINGS.default("arap_per_frame")
    arap_max: int = SETTINGS.default("arap_max")
    colour: str = SETTINGS.default("colour")
    active: int = -1  # the handle the gizmo and the turn slider move
    error: str = ""
    built: Built | None = None
    shown: dict[str, Shown] = field(default_factory=dict)  # method -> positions on screen
    moved: int = 0  # bumped on every change of the moves (the solve follows)
    solved: dict[str, int] = field(default_factory=dict)  # method -> `moved` it answers
    converged: dict[str, bool] = field(default_factory=dict)  # ARAP done for these moves
    version: int = 0  # bumped when shown positions change
    undo_stack: list[list[dict[str, Any]]] = field(default_factory=list)
    redo_stack: list[list[dict[str, Any]]] = field(default_factory=list)
    updates: list[float] = field(default_factory=list)  # perf_counter of recent updates
    _graph: Any = None  # (mesh version, edge graph)
    _terms: dict[str, Any] = field(default_factory=dict)  # rotation error's terms per method

    # ------------------------------------------------------------------ lifetime
    def clear(self) -> None:
        """Forget the mesh's handles, builds and moves (a new mesh); the settings stay."""
        self.handles, self.fixed, self.moves = [], [], []
        self.undo_stack, self.redo_stack = [], []
        self.active = -1
        self.drop()
        self._graph = None

    def drop(self) -> None:
        """Forget the built handle set (the settings, seeds and moves stay)."""
        close_set(self.built)
        self.built = None
        self.shown = {}
        self.solved, self.converged = {}, {}
        self._terms = {}
        self.error = ""
        self.version += 1

    @property
    def methods(self) -> tuple[str, ...]:
        """The methods shown: the method, then the compared one."""
        if self.compare in ("none", self.method):
            return (self.method,)
        return (self.method, self.compare)

    # ------------------------------------------------------------------ handles
    def select(self, n: int, vertex: int, add: bool = False) -> bool:
        """Make ``vertex`` the handle (``add``: one more, as a shift-click; a vertex already a
        seed becomes the active handle); False when out of range or too many."""
        v = int(vertex)
        if not 0 <= v < n:
            return False
        if v in self.handles:
            self.active = self.handles.index(v)
            return True
        if add and len(self.handles) >= MAX_HANDLES:
            self.error = f"at most {MAX_HANDLES} handles"
            return False
        self.checkpoint()
        if add:
            self.handles = [*self.handles, v]
            self.moves = [*self.moves, identity()]
        else:
            self.handles, self.moves = [v], [identity()]
        self.fixed = [f for f in self.fixed if f != v]
        self.active = len(self.handles) - 1
        self.moved += 1
        return True

    def add_fixed(self, n: int, vertex: int) -> bool:
        """Hold a disc around ``vertex`` (a ctrl-click; the fixed region becomes *clicked*);
        again on a fixed seed: it is let go."""
        v = int(vertex)
        if not 0 <= v < n or v in self.handles:
            return False
        if v in self.fixed:
            self.fixed = [f for f in self.fixed if f != v]
        elif len(self.fixed) >= MAX_HANDLES:
            self.error = f"at most {MAX_HANDLES} fixed discs"
            return False
        else:
            self.fixed = [*self.fixed, v]
        self.fixed_region = "clicked"
        return True

    def clear_handles(self) -> None:
        """No handle, nothing fixed by click; the moves go too (undo brings them back)."""
        self.checkpoint()
        self.handles, self.moves, self.fixed = [], [], []
        self.active = -1
        self.drop()

    def setup_key(self, mesh_version: int) -> tuple[Any, ...]:
        """What a handle set is built from (a change rebuilds)."""
        return (
            mesh_version,
            self.methods,
            tuple(self.handles),
            float(self.radius),
            self.fixed_region,
            tuple(self.fixed) if self.fixed_region == "clicked" else (),
            float(self.fixed_fraction),
            self.arap_energy,
        )

    def ready(self, mesh_version: int) -> bool:
        """The handle set on screen is the one the settings describe."""
        return self.built is not None and self.built.key == self.setup_key(mesh_version)

    def graph_for(self, mesh_version: int) -> Any:
        """The edge graph kept from the last build of this mesh (``None``: none yet)."""
        if self._graph is not None and self._graph[0] == mesh_version:
            return self._graph[1]
        return None

    def adopt(self, built: Built) -> None:
        """Show a handle set a build made (UI thread): each deformer at its rest pose, the
        moves solved next."""
        if self.built is not built:
            close_set(self.built)
        self.built = built
        if built.graph is not None:
            self._graph = (built.key[0], built.graph)
        self.shown = {m: Shown(d.V.copy()) for m, d in built.deformers.items()}
        self.solved = {m: -1 for m in built.deformers}
        self.converged = {m: False for m in built.deformers}
        self._terms = {}
        self.error = ""
        self.version += 1

    # ------------------------------------------------------------------ moves, undo
    def set_move(self, index: int, move: dict[str, Any]) -> None:
        """Handle ``index`` moved rigidly by ``move`` (checked: a bad one changes nothing).

        Raises
        ------
        MeshError
            Not a move (:func:`move_problem`).
        """
        problem = move_problem(move)
        if problem:
            raise MeshError(problem, "move")
        moves = list(self.moves)
        moves[index] = normal_moves([move])[0]
        if moves != self.moves:
            self.moves = moves
            self.moved += 1

    def checkpoint(self) -> None:
        """Remember the moves (and seeds) before a change: *undo* comes back here."""
        snap = [{"handles": list(self.handles), "moves": normal_moves(self.moves)}]
        self.undo_stack = [*self.undo_stack[-199:], *snap]  # type: ignore[list-item]
        self.redo_stack = []

    def _restore(self, snap: Any) -> None:
        if list(snap["handles"]) != self.handles:
            self.handles = list(snap["handles"])
            self.active = min(self.active, len(self.handles) - 1)
        self.moves = normal_moves(snap["moves"])
        self.moved += 1

    def undo(self) -> bool:
        """Back to the moves (and seeds) before the last change; False when there is none."""
        if not self.undo_stack:
            return False
        now = {"handles": list(self.handles), "moves": normal_moves(self.moves)}
        *self.undo_stack, snap = self.undo_stack
        self.redo_stack = [*self.redo_stack, now]  # type: ignore[list-item]
        self._restore(snap)
        return True

    def redo(self) -> bool:
        """Again the change *undo* took back; False when there is none."""
        if not self.redo_stack:
            return False
        now = {"handles": list(self.handles), "moves": normal_moves(self.moves)}
        *self.redo_stack, snap = self.redo_stack
        self.undo_stack = [*self.undo_stack, now]  # type: ignore[list-item]
        self._restore(snap)
        return True

    def reset_moves(self) -> None:
        """Every handle back at rest (an undo step)."""
        if any(m != IDENTITY for m in self.moves):
            self.checkpoint()
            self.moves = [identity() for _ in self.handles]
            self.moved += 1

    # ------------------------------------------------------------------ targets, solves
    def targets(self, method: str) -> FloatArray:
        """The handles' targets ``(h,3)`` of ``method``'s deformer (its handle order): each
        disc rotated about its centroid, then moved."""
        b = self.built
        assert b is not None
        d = b.deformers[method]
        out = np.empty((len(d.handles), 3))
        region = b.region_of[method]
        for i in range(len(b.regions.seeds)):
            mask = region == i
            if not mask.any():
                continue
            seed = int(b.regions.seeds[i])
            m = self.moves[self.handles.index(seed)] if seed in self.handles else IDENTITY
            R, t = move_matrix(m)
            out[mask] = rigid_targets(d.V, d.handles[mask], R, t)
        return out

    def due(self) -> list[str]:
        """The methods whose shown positions are behind the moves, or ARAP still iterating."""
        if self.built is None or len(self.moves) != len(self.handles):
            return []
        out = []
        for m in self.built.deformers:
            if self.solved.get(m) != self.moved:
                out.append(m)
            elif m == "arap" and not self.converged.get(m, True):
                out.append(m)
        return out

    @staticmethod
    def solve_work(
        deformer: Deformer,
        targets: FloatArray,
        iterations: int,
        tolerance: float,
        colour: str = "none",
    ) -> tuple[FloatArray, bool, float]:
        """One solve of ``deformer`` for ``targets`` (any thread, the deformer used by nobody
        else meanwhile): a back-substitution, or ``iterations`` ARAP iterations (stopping
        early once converged). Returns ``(positions copy, converged, seconds)``."""
        remote = getattr(deformer, "solve", None)
        if remote is not None:  # in a child process (:mod:`meshlap_app.deformer_process`)
            return remote(targets, iterations, tolerance, colour)
        t0 = time.perf_counter()
        if isinstance(deformer, ArapDeformer):
            rest = deformer.V[deformer.handles]
            scale = float(np.abs(deformer.V).max()) if len(deformer.V) else 1.0
            deformer.set_targets(targets)
            if np.allclose(targets, rest, rtol=0.0, atol=1e-12 * scale):
                deformer.reset()  # every handle at rest: the rest pose is the minimum, E = 0
                return np.array(deformer.positions), True, time.perf_counter() - t0
            done = False
            for _ in range(iterations):
                before = deformer.energies[-1] if deformer.energies else None
                e = deformer.step()
                if before is not None and before - e <= tolerance * max(abs(before), 1e-300):
                    done = True
                    break
            return np.array(deformer.positions), done, time.perf_counter() - t0
        U = np.array(deformer.update(targets))
        return U, True, time.perf_counter() - t0

    def iterations_for(self, method: str) -> int:
        """ARAP iterations to do now (this frame's share, within the cap per move)."""
        d = self.built.deformers[method] if self.built is not None else None
        if not getattr(d, "method", "") == "arap":
            return 1
        fresh = self.solved.get(method) != self.moved
        done = 0 if fresh else d.iteration
        return max(0, min(self.arap_per_frame, self.arap_max - done))

    def solve(self, method: str) -> bool:
        """Bring ``method``'s positions up to the moves on this thread; True when they changed."""
        b = self.built
        if b is None:
            return False
        moved = self.moved
        iters = self.iterations_for(method)
        if iters == 0:
            self.solved[method], self.converged[method] = moved, True
            return False
        U, done, seconds = self.solve_work(
            b.deformers[method], self.targets(method), iters, ARAP_TOLERANCE, self.colour
        )
        self.adopt_solve(method, moved, U, done, seconds)
        return True

    def adopt_solve(
        self, method: str, moved: int, U: FloatArray, done: bool, seconds: float
    ) -> None:
        """A solve for the moves numbered ``moved`` arrived (UI thread)."""
        if method not in self.shown:
            return
        d = self.built.deformers[method] if self.built is not None else None
        self.shown[method] = Shown(U, seconds)
        self.solved[method] = moved
        capped = getattr(d, "method", "") == "arap" and d.iteration >= self.arap_max
        self.converged[method] = done or capped
        now = time.perf_counter()
        self.updates = [t for t in self.updates[-59:] if now - t < 2.0] + [now]
        self.version += 1

    def update_rate(self) -> float:
        """Updates (solves shown) per second over the last two seconds (0: none)."""
        if len(self.updates) < 2:
            return 0.0
        span = self.updates[-1] - self.updates[0]
        return (len(self.updates) - 1) / span if span > 0 else 0.0

    # ------------------------------------------------------------------ numbers
    def figures(self, method: str) -> dict[str, Any]:
        """What a teacher shows of ``method``'s deformer: the energy (formula, value), the
        system's size and factorization time, the handle error (plain data)."""
        b = self.built
        if b is None or method not in b.deformers:
            return {}
        d = b.deformers[method]
        out = {
            "method": method,
            "minimizes": ENERGY_FORMULA[method],
            "energy_name": d.energy_name,
            "energy": float(d.energy()),
            "n_unknowns": int(d.stats.n_unknowns),
            "nnz": int(d.stats.nnz),
            "factor_seconds": float(d.stats.factor_seconds),
            "setup_seconds": float(d.setup_seconds),
            "backend": d.stats.backend,
            "handle_error": float(d.handle_error()),
            "n_handles": len(d.handles),
            "n_fixed": len(d.fixed),
            "solve_seconds": float(self.shown[method].solve_seconds)
            if method in self.shown
            else 0.0,
        }
        if getattr(d, "method", "") == "arap":
            out["iteration"] = int(d.iteration)
            out["energies"] = list(d.energies)
        return out

    def field(self, method: str) -> FloatArray | None:
        """The colour map's values on ``method``'s copy ``(n,)`` (``None``: no colour)."""
        b = self.built
        if b is None or self.colour == "none" or method not in self.shown:
            return None
        d = b.deformers[method]
        U = self.shown[method].positions
        if self.colour == "displacement":
            return np.linalg.norm(U - d.V, axis=1)
        if hasattr(d, "remote_field"):  # computed in the child with the positions
            return d.remote_field[1] if d.remote_field is not None else None
        err, self._terms[method] = rotation_error(d.V, d.F, U, terms=self._terms.get(method))
        return err


# ---------------------------------------------------------------- meshlap animate
def parse_triple(text: Any, flag: str, count: int) -> list[float]:
    """``"a,b,c"`` (``count`` finite numbers) as floats."""
    parts = str(text).split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise MeshError(
            f"expected {count} numbers separated by commas, got {text!r}", flag
        ) from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise MeshError(f"expected {count} finite numbers, got {text!r}", flag)
    return values


def _animation_check(opts: dict[str, Any]) -> None:
    if not 2 <= int(opts["drag_frames"]) <= 2000:
        raise MeshError(f"must be 2 to 2000, got {opts['drag_frames']}", "--drag-frames")
    if int(opts["drag_vertex"]) < -1:
        raise MeshError(f"must be a vertex index, got {opts['drag_vertex']}", "--drag-vertex")
    if isinstance(opts.get("drag_move"), str):
        opts["drag_move"] = parse_triple(opts["drag_move"], "--drag-move", 3)
    if isinstance(opts.get("drag_rotate"), str):
        rot = parse_triple(opts["drag_rotate"], "--drag-rotate", 4)
        if rot[3] != 0 and not any(rot[:3]):
            raise MeshError("the rotation axis is the zero vector", "--drag-rotate")
        if not -360 <= rot[3] <= 360:
            raise MeshError(f"degrees are -360 to 360, got {rot[3]:g}", "--drag-rotate")
        opts["drag_rotate"] = rot
    if max(abs(x) for x in opts["drag_move"]) > 100:
        raise MeshError("at most 100 diagonals", "--drag-move")


def _animation_check_mesh(opts: dict[str, Any], mesh: Any) -> None:
    n = len(mesh.V)
    if not -1 <= int(opts["drag_vertex"]) < n:
        raise MeshError(
            f"vertex {opts['drag_vertex']} is out of range (the mesh has {n} vertices)",
            "--drag-vertex",
        )


def _animation_from_session(opts: dict[str, Any], values: dict[str, Any], source: Any) -> None:
    """A saved deformation: its handles move from rest to their saved moves (unless a drag is
    typed)."""
    typed = any(opts.get(k) is not None for k in ("drag_vertex", "drag_move", "drag_rotate"))
    opts["drag_session"] = bool(values.get("handles")) and not typed


ANIMATION = Animation(
    summary="a handle dragged: each frame a step of its move (ARAP iterating), the rest "
    "following by the chosen method",
    options=(
        Option("--drag-vertex", "deform: the handle's vertex (default -1: the top one)", -1, int),
        Option(
            "--drag-move",
            "deform: the handle's move, in bounding-box diagonals (default 0,0.2,0)",
            "0,0.2,0",
            metavar="DX,DY,DZ",
        ),
        Option(
            "--drag-rotate",
            "deform: the handle's turn about its centroid (default 0,0,1,0)",
            "0,0,1,0",
            metavar="AX,AY,AZ,DEG",
        ),
        Option("--drag-frames", "deform: number of frames (default 30)", 30, int),
    ),
    session_help="deform  the session's handles move from rest to their saved moves (unless "
    "--drag-vertex, --drag-move or --drag-rotate is typed)",
    check=_animation_check,
    kind=lambda opts: "drag",
    fps={"drag": 10.0},
    frame_count=lambda opts: int(opts["drag_frames"]),
    from_session=_animation_from_session,
    check_mesh=_animation_check_mesh,
)
"""``meshlap animate --panel deform``."""


SPEC = PanelSpec(
    name="deform",
    title="Deform",
    summary="drag handles and let the mesh follow: Laplacian coordinates, (bi/tri)harmonic "
    "displacement and as-rigid-as-possible, side by side",
    panel="DeformPanel",
    state=DeformState,
    settings=SETTINGS,
    check_section=check_section,
    check_mesh=check_mesh,
    check_start=check_start,
    animation=ANIMATION,
    unsaved={
        "undo": "an action: the move before the last (the moves reached are the setting)",
        "redo": "an action: the move undone last (the moves reached are the setting)",
        "reset": "an action: every handle back at rest (the moves are the setting)",
        "clear handles": "an action: no handles (the handles are the setting)",
        "turn (deg)": "the active handle's turn: kept in the session with its moves",
        "scene drag": "a drag of a handle in the screen plane: kept as the handle's move",
    },
)
"""The Deform panel."""
