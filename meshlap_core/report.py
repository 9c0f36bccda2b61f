"""``meshlap report``: the whole curvature / spectral / smoothing study, reproduced and checked.

:func:`build_report` runs seven sections on the course meshes (``../shared/meshes`` beside the
checkout, or ``--meshes DIR``; the bundled ``assets/`` stand in for missing ones and the report
says so at the top) and writes ``report.md``, ``report.html``, PNG figures in ``figures/`` and
one CSV per table in ``tables/``:

1. the ordered one-ring on the cube;
2. uniform-Laplacian mean curvature and angle-deficit Gaussian curvature on ``lilium_s`` and
   ``plane`` (colour maps, histograms, value ranges, the Gauss–Bonnet check);
3. the helicoid (first and second fundamental forms at the origin, ``κₙ(θ)``, principal
   curvatures) and the convergence of discrete ``H``, ``K`` on meshed helicoid / sphere / torus;
4. cotangent versus uniform mean curvature (maps, histograms, ranges, difference, scaling);
5. spectral reconstruction of ``armadillo`` from ``k`` Laplace–Beltrami eigenvectors (error
   against ``k`` with the correct ``M`` inner product and with the classic Euclidean one,
   eigen-solve times beside the course report's);
6. explicit and implicit smoothing of ``plane_ns`` and ``fandisk_ns`` (stability numbers);
7. denoising of ``fandisk`` (RMSE against noise level, volume change, dihedral angles, error
   maps, and a recommendation table computed from the measured numbers).

Sign conventions. Every Laplacian is negative semidefinite (``Δx = −2Hn``, so the core's mean
curvature ``H = −½ Δx · n`` is positive on a sphere with outward normals); eigenvalues shown are
the non-negative frequencies of ``−Δ``. :mod:`meshlap_core.surfaces` measures the second
fundamental form against ``n = p_u × p_v`` with do Carmo's sign (``e = p_uu · n``), so its ``H``
is the **negative** of the core's for the same normal; section 3 says so where both appear.

This module is headless: it never imports polyscope. Mesh pictures come from the viewer run in a
subprocess (``python -m meshlap_core.cli view MESH --screenshot OUT.png``, EGL); when that fails
(no EGL, no display libraries) the report still builds, says why, and draws the mesh with
matplotlib instead. Plots use matplotlib's Agg canvas (imported lazily). Every file is written
atomically (:func:`meshlap_core.io.atomic_write`).
"""

from __future__ import annotations

import csv
import html
import io
import itertools
import math
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np

from . import curvature, metrics, noise, smoothing, spectral, surfaces, topology
from ._version import __version__
from .errors import MeshError, MeshWarning
from .io import atomic_write, load_mesh, save_mesh
from .types import FloatArray, IntArray

SECTIONS: tuple[str, ...] = (
    "onering",
    "uniform",
    "helicoid",
    "cotan",
    "spectral",
    "smoothing",
    "denoising",
)
"""Section keys, in report order (``--sections`` accepts these names or the numbers 1–7)."""

SECTION_TITLES: dict[str, str] = {
    "onering": "Ordered one-ring on the cube",
    "uniform": "Uniform mean curvature and Gaussian curvature",
    "helicoid": "The helicoid, and convergence of discrete H and K",
    "cotan": "Cotangent versus uniform mean curvature",
    "spectral": "Spectral reconstruction",
    "smoothing": "Explicit and implicit smoothing",
    "denoising": "Denoising evaluation",
}

COURSE_EIGEN_SECONDS: tuple[float, float] = (388.0, 5771.0)
"""The two eigen-solve times quoted from the course report (issue 7), in seconds."""

PACKAGE_ROOT = Path(__file__).resolve().parents[1]
ASSETS_DIR = PACKAGE_ROOT / "assets"


def default_meshes_dir() -> Path:
    """``../shared/meshes`` beside the checkout (it may not exist)."""
    return PACKAGE_ROOT.parent / "shared" / "meshes"


# course mesh -> (bundled stand-in, synthetic noise level alpha for the stand-in or None)
_STAND_INS: dict[str, tuple[str, float | None]] = {
    "cube": ("cube.obj", None),
    "lilium_s": ("bumpy.obj", None),
    "plane": ("grid.obj", None),
    "armadillo": ("bumpy.obj", None),
    "plane_ns": ("grid.obj", 0.004),
    "fandisk": ("torus.obj", None),
    "fandisk_ns": ("torus.obj", 0.003),
}
_NOISE_SEED = 7

# --------------------------------------------------------------------------------------------
# document model
# --------------------------------------------------------------------------------------------


@dataclass
class _Para:
    text: str
    kind: str = "p"  # "p" | "note" | "code"


@dataclass
class _Fig:
    path: str  # relative to the output directory
    caption: str
    kind: str = "plot"  # "plot" | "screenshot" | "render"


@dataclass
class _FigRow:
    figs: list[_Fig]


@dataclass
class _Table:
    name: str
    caption: str
    columns: list[str]
    rows: list[list[Any]]
    csv: str
    max_rows: int | None = None


@dataclass
class _Section:
    key: str
    number: int
    title: str
    blocks: list[Any] = field(default_factory=list)
    seconds: float = 0.0
    error: str | None = None

    def p(self, text: str) -> None:
        self.blocks.append(_Para(text))

    def note(self, text: str) -> None:
        self.blocks.append(_Para(text, "note"))

    def add(self, block: Any) -> None:
        if block is not None:
            self.blocks.append(block)

    def figs(self, figs: Sequence[_Fig | None]) -> None:
        got = [f for f in figs if f is not None]
        if got:
            self.blocks.append(_FigRow(got))


@dataclass
class ReportResult:
    """What :func:`build_report` wrote and measured.

    Attributes
    ----------
    out_dir : Path
    markdown, html : Path
        ``report.md`` and ``report.html``.
    figures, tables : list of Path
        Every PNG and CSV written (tables: one CSV per table, shown or not).
    section_seconds : dict
        Wall-clock seconds per section key.
    total_seconds : float
    mesh_note : str
        Where the meshes came from (the sentence at the top of the report).
    screenshots_ok : int
        Viewer screenshots that succeeded.
    screenshot_failures : list of str
        Why screenshots failed (each also noted in the report).
    errors : dict
        Section key → error message for sections that failed (the report notes them too).
    """

    out_dir: Path
    markdown: Path
    html: Path
    figures: list[Path]
    tables: list[Path]
    section_seconds: dict[str, float]
    total_seconds: float
    mesh_note: str
    screenshots_ok: int
    screenshot_failures: list[str]
    errors: dict[str, str]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "out_dir": str(self.out_dir),
            "markdown": str(self.markdown),
            "html": str(self.html),
            "figures": [str(p) for p in self.figures],
            "tables": [str(p) for p in self.tables],
            "section_seconds": self.section_seconds,
            "total_seconds": self.total_seconds,
            "mesh_note": self.mesh_note,
            "screenshots_ok": self.screenshots_ok,
            "screenshot_failures": self.screenshot_failures,
            "errors": self.errors,
        }


# --------------------------------------------------------------------------------------------
# progress bar
# --------------------------------------------------------------------------------------------


class Progress:
    """A text progress bar per section, with elapsed seconds, on a stream (stderr).

    On a terminal the bar is redrawn in place (carriage return); otherwise each update is one
    line, so logs stay readable.
    """

    def __init__(self, stream: IO[str] | None, n_sections: int, width: int = 24) -> None:
        self.stream = stream
        self.n_sections = n_sections
        self.width = width
        self.tty = bool(stream is not None and getattr(stream, "isatty", lambda: False)())
        self.index = 0
        self.title = ""
        self.steps = 1
        self.done_steps = 0
        self.t0 = time.perf_counter()

    def begin(self, index: int, title: str, steps: int) -> None:
        self.index, self.title = index, title
        self.steps, self.done_steps = max(1, steps), 0
        self.t0 = time.perf_counter()
        self._draw("starting")

    def step(self, message: str) -> None:
        self.done_steps = min(self.done_steps + 1, self.steps)
        self._draw(message)

    def end(self, seconds: float, status: str = "done") -> None:
        self.done_steps = self.steps
        self._draw(f"{status} in {seconds:.1f} s", final=True)

    def _draw(self, message: str, final: bool = False) -> None:
        if self.stream is None:
            return
        frac = self.done_steps / self.steps
        filled = round(frac * self.width)
        bar = "#" * filled + "-" * (self.width - filled)
        elapsed = time.perf_counter() - self.t0
        line = (
            f"report [{bar}] section {self.index}/{self.n_sections} {self.title}: {message} "
            f"({elapsed:.1f} s)"
        )
        if self.tty:
            self.stream.write("\r" + line[:160].ljust(160) + ("\n" if final else ""))
        else:
            self.stream.write(line + "\n")
        self.stream.flush()


# --------------------------------------------------------------------------------------------
# meshes
# --------------------------------------------------------------------------------------------


@dataclass
class _Mesh:
    name: str  # the course name asked for
    V: FloatArray
    F: IntArray
    path: Path | None  # the file on disk (None for a generated noisy stand-in)
    label: str  # how the report names it
    substitute: bool


def _load_asset(file: str) -> tuple[FloatArray, IntArray, Path | None]:
    path = ASSETS_DIR / file
    if path.is_file():
        m = load_mesh(path)
        return m.V, m.F, path
    from . import primitives

    gen = {
        "bumpy.obj": lambda: primitives.bumpy_sphere(4),
        "icosphere.obj": lambda: primitives.icosphere(3),
        "torus.obj": lambda: primitives.torus(48, 24),
        "grid.obj": lambda: primitives.grid(20, 20),
        "cube.obj": lambda: primitives.cube(0),
    }[file]
    V, F = gen()
    return V, F, None


# --------------------------------------------------------------------------------------------
# formatting
# --------------------------------------------------------------------------------------------


def _fmt(x: Any) -> str:
    """A table cell: 4 significant digits, ``—`` for missing values, yes/no for booleans."""
    if x is None:
        return "—"
    if isinstance(x, bool | np.bool_):
        return "yes" if x else "no"
    if isinstance(x, int | np.integer):
        return f"{int(x):,}" if abs(int(x)) >= 10000 else str(int(x))
    if isinstance(x, float | np.floating):
        f = float(x)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "−inf"
        if f == 0:
            return "0"
        a = abs(f)
        if 1e-3 <= a < 1e5:
            return f"{f:.4g}"
        return f"{f:.3e}"
    return str(x)


def _csv_cell(x: Any) -> str:
    if x is None:
        return ""
    if isinstance(x, bool | np.bool_):
        return "true" if x else "false"
    if isinstance(x, int | np.integer):
        return str(int(x))
    if isinstance(x, float | np.floating):
        return repr(float(x))  # shortest string that reads back exactly
    return str(x)


def _num(x: float, digits: int = 3) -> str:
    """A number inside a sentence."""
    f = float(x)
    if not math.isfinite(f):
        return str(f)
    if f == 0:
        return "0"
    if 1e-3 <= abs(f) < 1e5:
        return f"{f:.{digits}g}"
    return f"{f:.{max(digits - 1, 1)}e}"


def _pct(x: float) -> str:
    return f"{float(x):.1f} %"


# --------------------------------------------------------------------------------------------
# the context: output folders, figures, tables, screenshots
# --------------------------------------------------------------------------------------------


class _Ctx:
    def __init__(
        self,
        out_dir: Path,
        meshes_dir: Path | None,
        meshes_explicit: bool,
        quick: bool,
        screenshots: bool,
        viewer_cmd: Sequence[str],
        progress: Progress,
        tmp: Path,
        max_screenshots: int | None = None,
    ) -> None:
        self.out = out_dir
        self.max_screenshots = max_screenshots
        self.fig_dir = out_dir / "figures"
        self.tab_dir = out_dir / "tables"
        self.fig_dir.mkdir(parents=True, exist_ok=True)
        self.tab_dir.mkdir(parents=True, exist_ok=True)
        self.meshes_dir = meshes_dir
        self.meshes_explicit = meshes_explicit
        self.meshes_wanted: Path | None = meshes_dir
        self.quick = quick
        self.screenshots = screenshots
        self.screenshot_reason = "" if screenshots else "screenshots were turned off"
        self.viewer_cmd = list(viewer_cmd)
        self.progress = progress
        self.tmp = tmp
        self.figures: list[Path] = []
        self.tables: list[Path] = []
        self.shots_ok = 0
        self.shot_failures: list[str] = []
        self._meshes: dict[str, _Mesh] = {}
        self.used: dict[str, _Mesh] = {}
        self.inputs: list[Path] = []

    # ---- meshes ----------------------------------------------------------------------------
    def shared_path(self, name: str) -> Path | None:
        if self.meshes_dir is None:
            return None
        p = self.meshes_dir / f"{name}.obj"
        return p if p.is_file() else None

    def mesh(self, name: str) -> _Mesh:
        if name in self._meshes:
            return self._meshes[name]
        path = self.shared_path(name)
        if path is not None:
            m = load_mesh(path)
            mesh = _Mesh(name, m.V, m.F, path, f"{name}.obj ({len(m.V):,} vertices)", False)
            self.inputs.append(path)
        else:
            file, alpha = _STAND_INS[name]
            V, F, apath = _load_asset(file)
            if alpha is not None:
                V = noise.add_noise(V, F, alpha, mode="isotropic", seed=_NOISE_SEED)
                label = (
                    f"assets/{file} + seeded Gaussian noise σ = {alpha:g} × bbox diagonal "
                    f"(stand-in for {name}, {len(V):,} vertices)"
                )
                apath = None
            else:
                label = f"assets/{file} (stand-in for {name}, {len(V):,} vertices)"
            mesh = _Mesh(name, V, F, apath, label, True)
        self._meshes[name] = mesh
        self.used[name] = mesh
        return mesh

    # ---- files -----------------------------------------------------------------------------
    def rel(self, p: Path) -> str:
        return p.relative_to(self.out).as_posix()

    def table(
        self,
        name: str,
        caption: str,
        columns: Sequence[str],
        rows: Sequence[Sequence[Any]],
        max_rows: int | None = None,
    ) -> _Table:
        path = self.tab_dir / f"{name}.csv"
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(list(columns))
        for r in rows:
            w.writerow([_csv_cell(x) for x in r])
        with atomic_write(path, "w", overwrite_inputs=self.inputs) as f:
            f.write(buf.getvalue())
        self.tables.append(path)
        return _Table(
            name, caption, list(columns), [list(r) for r in rows], self.rel(path), max_rows
        )

    def save_fig(self, fig: Any, name: str, caption: str, kind: str = "plot") -> _Fig:
        path = self.fig_dir / f"{name}.png"
        with atomic_write(path, "wb", overwrite_inputs=self.inputs) as fh:
            fig.savefig(fh, format="png", dpi=100)
        self.figures.append(path)
        return _Fig(self.rel(path), caption, kind)

    # ---- screenshots -----------------------------------------------------------------------
    def shot(
        self,
        name: str,
        caption: str,
        *,
        mesh: _Mesh | None = None,
        V: FloatArray | None = None,
        F: IntArray | None = None,
        panel: str = "curvature",
        field: str = "cotan",
        vertex: int | None = None,
        use_file: bool = False,
        label: str | None = None,
    ) -> _Fig | None:
        """A viewer screenshot of a mesh (saved to a temporary OBJ unless ``use_file``), or
        ``None`` when screenshots are unavailable (the reason is kept)."""
        if (
            self.screenshots
            and self.max_screenshots is not None
            and self.shots_ok >= self.max_screenshots
        ):
            self.screenshots = False
            self.screenshot_reason = (
                f"the limit of {self.max_screenshots} viewer screenshots "
                "was reached (--max-screenshots)"
            )
        if not self.screenshots:
            return None
        out = self.fig_dir / f"{name}.png"
        args: list[str] = []
        if mesh is not None and V is None:
            V, F = mesh.V, mesh.F
        if use_file and mesh is not None and mesh.path is not None:
            args.append(str(mesh.path))
        elif V is not None and F is not None:
            sub = self.tmp / f"shot{self.shots_ok + len(self.shot_failures)}_{name}"
            sub.mkdir(parents=True, exist_ok=True)
            tmp_obj = sub / f"{label or name}.obj"
            save_mesh(tmp_obj, V, F)
            args.append(str(tmp_obj))
        cmd = [*self.viewer_cmd, *args, "--screenshot", str(out), "--panel", panel]
        if panel == "curvature":
            cmd += ["--field", field]
        if vertex is not None:
            cmd += ["--vertex", str(vertex)]
        try:
            proc = subprocess.run(
                cmd,
                cwd=self.tmp,
                capture_output=True,
                text=True,
                timeout=180,
                env={**os.environ, "PYTHONWARNINGS": "ignore"},
            )
            ok = proc.returncode == 0 and out.is_file()
            why = _last_line(proc.stderr) or f"exit code {proc.returncode}"
        except (OSError, subprocess.TimeoutExpired) as exc:
            ok, why = False, f"{type(exc).__name__}: {exc}"
        if ok:
            try:
                ok = _autocrop(out)
            except Exception as exc:  # a broken PNG counts as a failed screenshot
                ok, why = False, f"unreadable PNG ({exc})"
            if not ok:
                why = why if "PNG" in why else "the screenshot is blank"
        if not ok:
            self.shot_failures.append(f"{name}: {why}")
            out.unlink(missing_ok=True)
            # every later screenshot would fail the same way: stop trying, say why once
            self.screenshots = False
            self.screenshot_reason = why
            return None
        self.shots_ok += 1
        self.figures.append(out)
        return _Fig(self.rel(out), caption, "screenshot")

    def shot_or_render(
        self,
        name: str,
        caption: str,
        mesh: _Mesh | None = None,
        *,
        V: FloatArray | None = None,
        F: IntArray | None = None,
        field: str = "cotan",
        values: FloatArray | None = None,
        cmap: str = "coolwarm",
        symmetric: bool = True,
        label: str | None = None,
    ) -> _Fig:
        """A screenshot; if unavailable, a matplotlib rendering of the same mesh and field."""
        if label is None and mesh is not None and V is None:
            label = mesh.name
        fig = self.shot(name, caption, mesh=mesh, V=V, F=F, field=field, label=label)
        if fig is not None:
            return fig
        if mesh is not None and V is None:
            V, F = mesh.V, mesh.F
        assert V is not None and F is not None
        if values is None:
            values = curvature.curvature_fields(V, F)[field]
        f = _new_figure(6.4, 4.8)
        ax = f.add_axes((0.0, 0.0, 0.84, 1.0))
        sm = _draw_mesh(ax, V, F, values, cmap=cmap, symmetric=symmetric)
        if sm is not None:
            cax = f.add_axes((0.86, 0.15, 0.03, 0.7))
            f.colorbar(sm, cax=cax)
        return self.save_fig(f, name, caption + " (matplotlib rendering: no screenshot)", "render")


def _last_line(text: str) -> str:
    lines = [ln.strip() for ln in (text or "").splitlines() if ln.strip()]
    lines = [ln for ln in lines if not ln.startswith("[polyscope]")] or lines
    return lines[-1][:300] if lines else ""


def _bbox(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return None
    return int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1


def _autocrop(path: Path, margin: int = 12) -> bool:
    """Compact a viewer screenshot: the mesh cut out of the empty background, with the viewer's
    panel (top right) placed beside it. ``False`` if the image is blank."""
    import matplotlib.image as mpimg

    img = mpimg.imread(path)
    if img.ndim != 3 or img.shape[0] < 2 or img.shape[1] < 2:
        return False
    if img.shape[2] == 3:
        img = np.concatenate([img, np.ones((*img.shape[:2], 1), img.dtype)], axis=2)
    rgb = img[..., :3]
    bg = rgb[-1, 0]
    diff = np.abs(rgb - bg).max(axis=2) > 0.02
    if not diff.any():
        return False
    h, w = diff.shape
    # the panel: the non-background run in the top rows that touches the right part
    panel = None
    top = diff[: max(h // 20, 4)]
    cols = np.flatnonzero(top.any(axis=0))
    if len(cols) and cols[0] > w // 3:
        c0 = int(cols[0])
        col = diff[:, min(c0 + 4, w - 1)]
        r1 = int(np.flatnonzero(col)[-1]) + 1 if col.any() else h
        panel = (0, r1, c0, w)
    scene = diff.copy()
    if panel is not None:
        scene[panel[0] : panel[1], panel[2] : panel[3]] = False
    sb = _bbox(scene)
    pieces = []
    if sb is not None:
        r0, r1, c0, c1 = sb
        pieces.append(
            img[
                max(r0 - margin, 0) : min(r1 + margin, h), max(c0 - margin, 0) : min(c1 + margin, w)
            ]
        )
    if panel is not None:
        pieces.append(img[panel[0] : panel[1], panel[2] : panel[3]])
    if not pieces:
        return False
    H = max(p.shape[0] for p in pieces)
    gap = margin
    W = sum(p.shape[1] for p in pieces) + gap * (len(pieces) - 1)
    out = np.ones((H, W, 4), dtype=np.float32)
    out[..., :3] = bg
    x = 0
    for p in pieces:
        y = (H - p.shape[0]) // 2 if p is pieces[0] and len(pieces) > 1 else 0
        out[y : y + p.shape[0], x : x + p.shape[1]] = p
        x += p.shape[1] + gap
    with atomic_write(path, "wb") as fh:
        mpimg.imsave(fh, np.clip(out, 0, 1), format="png")
    return True


# --------------------------------------------------------------------------------------------
# plotting helpers (matplotlib, Agg, imported lazily)
# --------------------------------------------------------------------------------------------


def _new_figure(w: float, h: float) -> Any:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h))
    FigureCanvasAgg(fig)
    return fig


def _rot_x(deg: float) -> FloatArray:
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _camera(direction: Sequence[float], up: Sequence[float] = (0.0, 1.0, 0.0)) -> FloatArray:
    """Rows: screen right, screen up, towards the camera (``direction`` points at the eye)."""
    c = np.asarray(direction, dtype=float)
    c = c / np.linalg.norm(c)
    r = np.cross(np.asarray(up, dtype=float), c)
    if np.linalg.norm(r) < 1e-8:
        r = np.cross(np.array([0.0, 0.0, 1.0]), c)
    r /= np.linalg.norm(r)
    return np.stack([r, np.cross(c, r), c])


def _view_dir(elev: float, azim: float) -> FloatArray:
    """Eye direction, y up, like the viewer: ``azim`` degrees around y from the front (−z),
    ``elev`` degrees above."""
    a, e = math.radians(azim), math.radians(elev)
    return np.array([-math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e)])


def _draw_mesh(
    ax: Any,
    V: FloatArray,
    F: IntArray,
    values: FloatArray | None = None,
    *,
    cam: FloatArray | None = None,
    cmap: str = "coolwarm",
    symmetric: bool = True,
    vmin: float | None = None,
    vmax: float | None = None,
    edges: bool = False,
    log: bool = False,
) -> Any:
    """Draw a shaded mesh with the painter's algorithm (2-D polygons, orthographic camera).

    Returns the ``ScalarMappable`` of the colour map (``None`` without ``values``).
    """
    import matplotlib as mpl
    from matplotlib.collections import PolyCollection

    R = _camera(_view_dir(15.0, -25.0)) if cam is None else cam
    P = V @ R.T
    T = P[F]
    nrm = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    ln = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.divide(nrm, ln, out=np.zeros_like(nrm), where=ln > 0)
    closed = metrics.is_closed(F) if len(F) else False
    keep = nrm[:, 2] > 0 if closed else np.ones(len(F), dtype=bool)
    light = np.array([0.35, 0.55, 1.0])
    light /= np.linalg.norm(light)
    shade = 0.3 + 0.7 * np.abs(nrm @ light)
    sm = None
    if values is None:
        base = np.tile(np.array([0.86, 0.80, 0.72, 1.0]), (len(F), 1))
    else:
        vals = np.asarray(values, dtype=float)
        fv = vals[F].mean(axis=1)
        finite = vals[np.isfinite(vals)]
        if vmin is None or vmax is None:
            if symmetric:
                r = float(np.percentile(np.abs(finite), 98)) if finite.size else 1.0
                lo, hi = -(r or 1.0), (r or 1.0)
            else:
                lo, hi = np.percentile(finite, [1, 99]) if finite.size else (0.0, 1.0)
                lo, hi = float(lo), float(hi)
                if hi <= lo:
                    hi = lo + 1.0
        else:
            lo, hi = vmin, vmax
        norm = (
            mpl.colors.LogNorm(max(lo, 1e-300), hi, clip=True)
            if log
            else mpl.colors.Normalize(lo, hi)
        )
        cm = mpl.colormaps[cmap]
        base = cm(norm(np.nan_to_num(np.maximum(fv, lo) if log else fv)))
        sm = mpl.cm.ScalarMappable(norm=norm, cmap=cm)
    col = base.copy()
    col[:, :3] *= shade[:, None]
    idx = np.flatnonzero(keep)
    order = idx[np.argsort(T[idx, :, 2].mean(axis=1))]
    pc = PolyCollection(
        T[order][:, :, :2],
        facecolors=col[order],
        edgecolors=(0.1, 0.1, 0.1, 0.6) if edges else col[order],
        linewidths=0.6 if edges else 0.25,
    )
    ax.add_collection(pc)
    lo2, hi2 = P[:, :2].min(axis=0), P[:, :2].max(axis=0)
    pad = 0.04 * float(max(hi2 - lo2))
    ax.set_xlim(lo2[0] - pad, hi2[0] + pad)
    ax.set_ylim(lo2[1] - pad, hi2[1] + pad)
    ax.set_aspect("equal")
    ax.axis("off")
    return sm


def _map_row(
    items: Sequence[tuple[str, FloatArray]],
    V: FloatArray,
    F: IntArray,
    vmax: float,
    label: str,
    vmin: float = 0.0,
    log: bool = False,
) -> Any:
    """One row of meshes coloured by per-vertex values on a shared vmin..vmax scale."""
    n = len(items)
    fig = _new_figure(3.4 * n + 0.9, 3.9)
    w = 0.94 / n * (3.4 * n) / (3.4 * n + 0.9)
    sm = None
    for i, (title, vals) in enumerate(items):
        ax = fig.add_axes((0.005 + i * w, 0.0, w, 0.86))
        sm = _draw_mesh(
            ax, V, F, vals, cmap="magma", symmetric=False, vmin=vmin, vmax=vmax, log=log
        )
        ax.set_title(title, fontsize=8)
    cax = fig.add_axes((0.005 + n * w + 0.01, 0.12, 0.012, 0.66))
    fig.colorbar(sm, cax=cax, label=label)
    return fig


def _stats_row(values: FloatArray) -> list[float]:
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return [float("nan")] * 6
    p01, med, p99 = np.percentile(v, [1, 50, 99])
    return [float(v.min()), float(v.max()), float(v.mean()), float(med), float(p01), float(p99)]


STAT_COLUMNS = ["min", "max", "mean", "median", "p01", "p99"]


# --------------------------------------------------------------------------------------------
# section 1: one-ring
# --------------------------------------------------------------------------------------------


def _section_onering(ctx: _Ctx, sec: _Section) -> None:
    mesh = ctx.mesh("cube")
    V, F = mesh.V, mesh.F
    n = len(V)
    ring = topology.one_ring(F, n)
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
    nb = ring[v0]
    N = curvature.vertex_normals(V, F)
    fig = _new_figure(6.4, 5.6)
    ax = fig.add_axes((0.02, 0.02, 0.96, 0.88))
    cam = _camera(N[v0] + 0.25 * _view_dir(25.0, -35.0))
    _draw_mesh(ax, V, F, None, cam=cam, edges=True)
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
    f1 = ctx.save_fig(
        fig,
        "onering_cube",
        f"The one-ring of vertex {v0} seen from outside: position i in the "
        "order is labelled 'i: v<index>' (0-based, as in the viewer) and the "
        "arrows follow the order, counter-clockwise.",
    )
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


# --------------------------------------------------------------------------------------------
# section 2: uniform mean curvature and Gaussian curvature
# --------------------------------------------------------------------------------------------


def _gauss_bonnet(V: FloatArray, F: IntArray) -> tuple[float, float]:
    """``(Σ K_i A_i, 2πχ)`` with the π boundary rule (the deficit already includes it)."""
    d = curvature.angle_deficit(V, F, "pi")
    return float(d.sum()), 2.0 * math.pi * topology.euler_characteristic(F, len(V))


def _section_uniform(ctx: _Ctx, sec: _Section) -> None:
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
        f = curvature.curvature_fields(m.V, m.F)
        fields[name] = f
        bnd = topology.boundary_vertex_mask(m.F, len(m.V))
        for key, label in (("uniform", "H uniform"), ("gaussian", "K angle deficit")):
            rows.append([name, label, "all", len(m.V), *_stats_row(f[key])])
            rows.append([name, label, "interior", int((~bnd).sum()), *_stats_row(f[key][~bnd])])
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
        f"max |H uniform| = {_num(np.abs(fpl['uniform']).max())}; max |K| over interior "
        f"vertices = {_num(np.abs(fpl['gaussian'][~bnd]).max() if (~bnd).any() else 0.0)}, "
        f"over boundary vertices = {_num(np.abs(fpl['gaussian'][bnd]).max() if bnd.any() else 0)}"
        " (a flat boundary vertex has Σθ = π except at the corners of the patch, where the "
        "π rule leaves the turning angle of the boundary as K·A). Gauss–Bonnet: "
        + "; ".join(
            f"{r[0]}: Σ K_i A_i = {_num(r[2], 6)} vs 2πχ = {_num(r[3], 6)}" for r in gb_rows
        )
        + "."
    )
    fig = _new_figure(10.0, 6.4)
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


# --------------------------------------------------------------------------------------------
# section 3: helicoid and convergence
# --------------------------------------------------------------------------------------------


def _section_helicoid(ctx: _Ctx, sec: _Section) -> None:
    geo = surfaces.point_geometry("helicoid", 0.0, 0.0)
    sec.p(
        "Helicoid p(u, v) = (u cos v, u sin v, v) (c = 1) at the origin (u, v) = (0, 0). "
        "Signs here are do Carmo's, as in `meshlap_core.surfaces`: n = p_u × p_v / |p_u × p_v| "
        "and e = p_uu · n, f = p_uv · n, g = p_vv · n. **The mesh code uses the opposite sign "
        "for H** (Δx = −2Hn), so for the same normal H(core) = −H(surfaces); K does not change. "
        "The closed forms below are the textbook ones for c = 1: E = 1, F = 0, G = 1 + u², "
        "e = g = 0, f = −1/√(1+u²), K = −1/(1+u²)², κ = ±1/(1+u²), κₙ(θ) = −sin 2θ at u = 0."
    )
    exact = {
        "E": 1.0,
        "F": 0.0,
        "G": 1.0,
        "e": 0.0,
        "f": -1.0,
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
            135.0,
            abs(math.degrees(geo.theta_max) - 135.0),
        ],
        [
            "theta_min (deg)",
            math.degrees(geo.theta_min),
            45.0,
            abs(math.degrees(geo.theta_min) - 45.0),
        ],
    ]
    sec.add(
        ctx.table(
            "helicoid_origin",
            "First and second fundamental forms and curvatures of the helicoid at the "
            "origin (do Carmo's sign), computed against the closed forms.",
            ["quantity", "computed", "closed_form", "abs_difference"],
            rows,
        )
    )
    theta, kn = surfaces.normal_curvature_curve("helicoid", 0.0, 0.0, 721)
    dev = float(np.abs(kn + np.sin(2 * theta)).max())
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
                -g.H,
                g.classification,
            ]
        )
    sec.add(
        ctx.table(
            "helicoid_principal",
            "Principal curvatures along the helicoid (κ₁ ≥ κ₂; H_core = −H_surfaces).",
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
    sec.p(
        f"Measured: at the origin the point is {geo.classification} with κ₁ = {_num(geo.k1)} "
        f"at θ = {math.degrees(geo.theta_max):.1f}° and κ₂ = {_num(geo.k2)} at "
        f"θ = {math.degrees(geo.theta_min):.1f}°; the sampled κₙ(θ) differs from −sin 2θ by at "
        f"most {_num(dev)} over 721 angles."
    )
    path = ctx.fig_dir / "helicoid_kn.png"
    surfaces.plot_normal_curvature("helicoid", 0.0, 0.0, path)
    ctx.figures.append(path)
    f1 = _Fig(
        ctx.rel(path),
        "Normal curvature κₙ(θ) of the helicoid at the origin, with κ₁, "
        "κ₂ and their directions (do Carmo's sign).",
    )
    ctx.progress.step("helicoid at the origin")
    f2 = ctx.shot(
        "helicoid_viewer",
        "The viewer's surfaces panel: the helicoid and the point "
        "(u, v) = (0, 0) with I, II, K, H (do Carmo's sign) and κₙ(θ).",
        panel="surfaces",
    )
    ctx.progress.step("screenshot")
    sec.figs([f1, f2])
    if f2 is None:
        sec.note(f"No viewer screenshot of the surfaces panel: {ctx.screenshot_reason}.")

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
        studies.append(surfaces.convergence_study(surf, res, mesher))
        ctx.progress.step(f"convergence {surf} {mesher}")
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
    sec.p(
        "Convergence: meshes of the parameter rectangle (`grid`) or subdivided icospheres, "
        "errors |discrete − exact| over interior vertices, with the exact H taken in the core's "
        "sign (−H of `surfaces`). order = log-log slope of the error against the mean edge "
        "length h between consecutive levels (2: the error shrinks 4× when h halves; 0: it "
        "stalls)."
    )
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
            rows,
            max_rows=0,
        )
    )
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
        + (", ".join(f"{s} {m}: {e} (max error {_num(x)})" for s, m, e, x, _ in stall) or "none")
        + "."
    )
    from matplotlib.ticker import NullFormatter

    fig = _new_figure(4.2 * len(studies), 3.8)
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


# --------------------------------------------------------------------------------------------
# section 4: cotangent versus uniform
# --------------------------------------------------------------------------------------------


def _section_cotan(ctx: _Ctx, sec: _Section) -> None:
    names = ["lilium_s", "plane"]
    sec.p(
        "Cotangent (Laplace–Beltrami) mean curvature H = −½ (M⁻¹C x) · n with C the cotangent "
        "stiffness and M the barycentric area, against the uniform H of section 2 (both "
        "negative semidefinite Laplacians, Δx = −2Hn). The difference map is H_uniform − "
        "H_cotan."
    )
    rows, fields = [], {}
    for name in names:
        m = ctx.mesh(name)
        f = curvature.curvature_fields(m.V, m.F)
        fields[name] = f
        bnd = topology.boundary_vertex_mask(m.F, len(m.V))
        for key, label in (
            ("uniform", "H uniform"),
            ("cotan", "H cotan"),
            ("difference", "H uniform − H cotan"),
        ):
            rows.append([name, label, "all", *_stats_row(f[key])])
            rows.append([name, label, "interior", *_stats_row(f[key][~bnd])])
    ctx.progress.step("fields")
    sec.add(
        ctx.table(
            "cotan_uniform_ranges",
            "Value ranges of both estimators and of their difference.",
            ["mesh", "field", "vertices", *STAT_COLUMNS],
            rows,
        )
    )
    m = ctx.mesh("lilium_s")
    f = fields["lilium_s"]
    bnd = topology.boundary_vertex_mask(m.F, len(m.V))
    inner = ~bnd
    r = (
        float(np.corrcoef(f["uniform"][inner], f["cotan"][inner])[0, 1])
        if inner.sum() > 2
        else float("nan")
    )
    # scaling: a curvature scales like 1/length; the uniform H scales like length
    s = 2.0
    f2 = curvature.curvature_fields(m.V * s, m.F)
    scale_rows = []
    for key, label in (("cotan", "H cotan"), ("uniform", "H uniform"), ("gaussian", "K")):
        a = float(np.median(np.abs(f[key][inner])))
        b = float(np.median(np.abs(f2[key][inner])))
        expect = 1.0 / s if key != "gaussian" else 1.0 / s**2
        scale_rows.append([label, a, b, b / a if a else float("nan"), expect])
    sec.add(
        ctx.table(
            "cotan_scaling",
            f"Median |value| over interior vertices of lilium_s "
            f"before and after scaling the mesh by {s:g} (a curvature must scale by "
            "1/s, K by 1/s²).",
            ["estimator", "median_abs_s1", "median_abs_s2", "ratio", "expected_for_a_curvature"],
            scale_rows,
        )
    )
    cot_ratio, uni_ratio = scale_rows[0][3], scale_rows[1][3]
    sec.p(
        f"Measured on lilium_s (interior vertices): the two estimators are correlated "
        f"(Pearson r = {r:.3f}) but differ in magnitude: median |H_cotan| = "
        f"{_num(scale_rows[0][1])} against median |H_uniform| = {_num(scale_rows[1][1])}. "
        f"Scaling the mesh by {s:g} multiplies the cotangent H by {_num(cot_ratio)} (a "
        f"curvature: 1/s = {1 / s:g}) but the uniform H by {_num(uni_ratio)}: the uniform "
        "Laplacian ignores edge lengths, so its 'H' is a length (about the edge length squared "
        "times the true H), a shape indicator rather than a curvature estimate."
    )
    fig = _new_figure(13.0, 3.8)
    for j, (key, c) in enumerate(
        (("uniform", "tab:blue"), ("cotan", "tab:red"), ("difference", "tab:purple"))
    ):
        ax = fig.add_subplot(1, 4, j + 1)
        v = f[key][inner]
        lo, hi = np.percentile(v, [1, 99])
        ax.hist(np.clip(v, lo, hi), bins=60, color=c)
        ax.set_yscale("log")
        ax.set_title(
            f"lilium_s interior: {'H ' + key if key != 'difference' else 'H_u − H_c'}", fontsize=9
        )
        ax.tick_params(labelsize=7)
    ax = fig.add_subplot(1, 4, 4)
    lim = np.percentile(np.abs(f["cotan"][inner]), 99)
    ax.scatter(f["cotan"][inner], f["uniform"][inner], s=3, alpha=0.5)
    ax.set_xlim(-lim, lim)
    ax.set_xlabel("H cotan")
    ax.set_ylabel("H uniform")
    ax.set_title(f"per vertex (r = {r:.3f})", fontsize=9)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    agree = float(np.mean(np.sign(f["uniform"][inner]) == np.sign(f["cotan"][inner])))
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "cotan_histograms",
                "Histograms over the interior vertices "
                "(log counts, values clipped to p01..p99; note the different x "
                "scales) and uniform against cotangent H per vertex: the sign agrees "
                f"at {100 * agree:.0f} % of the interior vertices.",
            )
        ]
    )
    ctx.progress.step("histograms")
    figs = []
    for fld, label in (
        ("uniform", "H uniform"),
        ("cotan", "H cotan"),
        ("difference", "H uniform − H cotan"),
    ):
        figs.append(ctx.shot_or_render(f"cotan_lilium_{fld}", f"lilium_s: {label}", m, field=fld))
        ctx.progress.step(f"map {fld}")
    sec.figs(figs)
    ratio = scale_rows[0][1] / scale_rows[1][1] if scale_rows[1][1] else float("inf")
    dom = (
        "dominated by −H_cotan"
        if ratio > 5
        else "dominated by H_uniform"
        if ratio < 0.2
        else "a mix of both"
    )
    sec.p(
        "Each map has its own colour range (symmetric about 0, clipped at 2 % each end), so "
        "the patterns can be compared side by side although the magnitudes differ: median "
        f"|H_cotan| / median |H_uniform| = {_num(ratio)} on lilium_s, so the difference map is "
        f"{dom}."
    )


# --------------------------------------------------------------------------------------------
# section 5: spectral reconstruction
# --------------------------------------------------------------------------------------------


def _ratio_words(a: float, b: float) -> str:
    """``a → b`` as words: "3.2× smaller", "2.5× larger", "about the same"."""
    if not (a > 0 and b > 0):
        return "n/a"
    r = a / b
    if 0.9 <= r <= 1.1:
        return "about the same"
    return f"{r:.1f}× smaller" if r > 1 else f"{1 / r:.1f}× larger"


def _euclidean_errors(
    V: FloatArray, U: FloatArray, ks: Sequence[int], diag: float, unit: bool
) -> FloatArray:
    """RMS error / diagonal of the *wrong* reconstruction ``Σ_{i<k} u_i (u_iᵀ x)`` (Euclidean
    inner product, no ``M``), with the solver's ``M``-orthonormal eigenvectors (``unit=False``)
    or with each scaled to unit Euclidean length (``unit=True``, what a general eigensolver for
    ``M⁻¹C`` returns)."""
    Ue = U / np.linalg.norm(U, axis=0, keepdims=True) if unit else U
    c = Ue.T @ V
    out = []
    for k in ks:
        R = Ue[:, :k] @ c[:k]
        out.append(float(np.sqrt(np.mean(np.sum((V - R) ** 2, axis=1))) / diag))
    return np.array(out)


def _section_spectral(ctx: _Ctx, sec: _Section) -> None:
    m = ctx.mesh("armadillo")
    V, F = m.V, m.F
    n = len(V)
    ks_all = [5, 15, 50, 100] if ctx.quick else [5, 15, 50, 100, 200, 500, 1000]
    ks = [k for k in ks_all if k <= max(n // 2, 1)]
    kmax = ks[-1]
    timed = [kmax] if ctx.quick else sorted({k for k in (100, 500, kmax) if k <= kmax})
    sec.p(
        f"Mesh: {m.label}. The eigenproblem is the generalized symmetric one K u = λ M u "
        "(K = −C, the negated cotangent stiffness, positive semidefinite; M the lumped Voronoi "
        "areas), so the λ ≥ 0 are the frequencies of −Δ and the eigenvectors are M-orthonormal "
        "(UᵀMU = I). The reconstruction from k modes is the M-orthogonal projection "
        "x̂ = U_k U_kᵀ M x. Every solve below is from scratch (no cache), timed on this machine."
    )
    solves = []
    basis = None
    for k in timed:
        ctx.progress.step(f"eigen-solve k={k}")
        t0 = time.perf_counter()
        b = spectral.SpectralBasis.compute(V, F, k, cache=False)
        sec_k = time.perf_counter() - t0
        solves.append(
            [
                m.name,
                n,
                k,
                b.info.method,
                sec_k,
                b.info.timings.get("eigensolve"),
                b.info.max_residual,
                float(b.eigenvalues[-1]),
            ]
        )
        basis = b
    assert basis is not None
    if not ctx.quick:
        big = ctx.shared_path("armadillo_igl")
        if big is not None:
            mb = load_mesh(big)
            ctx.inputs.append(big)
            for k in (100, 1000):
                ctx.progress.step(f"eigen-solve armadillo_igl k={k}")
                t0 = time.perf_counter()
                b2 = spectral.SpectralBasis.compute(mb.V, mb.F, k, cache=False)
                solves.append(
                    [
                        "armadillo_igl",
                        len(mb.V),
                        k,
                        b2.info.method,
                        time.perf_counter() - t0,
                        b2.info.timings.get("eigensolve"),
                        b2.info.max_residual,
                        float(b2.eigenvalues[-1]),
                    ]
                )
                del b2
    err = basis.errors(k_max=kmax)
    diag = err.diagonal
    sample = sorted({int(k) for k in np.unique(np.geomspace(1, kmax, 40).astype(int))} | set(ks))
    wrong = _euclidean_errors(V, basis.vectors, sample, diag, unit=True)
    nomass = _euclidean_errors(V, basis.vectors, sample, diag, unit=False)
    right = np.array([err.rms[k] / diag for k in sample])
    ctx.progress.step("errors for every k")
    rows = []
    for k in ks:
        rows.append(
            [
                k,
                float(basis.eigenvalues[k - 1]),
                err.mean[k] / diag,
                err.max[k] / diag,
                err.rms[k] / diag,
                float(nomass[sample.index(k)]),
                float(wrong[sample.index(k)]),
            ]
        )
    sec.add(
        ctx.table(
            "spectral_errors",
            "Reconstruction error per k, relative to the bounding-box diagonal "
            f"({_num(diag)}). The last two columns are the wrong-inner-product bug "
            "in its two forms (see below).",
            [
                "k",
                "lambda_k",
                "mean_error",
                "max_error",
                "rms_error",
                "rms_error_no_mass",
                "rms_error_unit_vectors",
            ],
            rows,
        )
    )
    course_fast, course_slow = COURSE_EIGEN_SECONDS
    solve_rows = [[*r, course_fast / r[4], course_slow / r[4]] for r in solves]
    sec.add(
        ctx.table(
            "spectral_timings",
            "Eigen-solve wall-clock times (from scratch, this machine, shared with "
            "other jobs), and how many times faster than the course report's 388 s "
            "and 5,771 s.",
            [
                "mesh",
                "vertices",
                "k",
                "method",
                "seconds",
                "eigensolve_seconds",
                "max_residual",
                "lambda_max",
                "speedup_vs_388s",
                "speedup_vs_5771s",
            ],
            solve_rows,
        )
    )
    k5, k100 = ks[0], (100 if 100 in ks else kmax)
    e5, e100 = err.rms[k5] / diag, err.rms[k100] / diag
    w5, w100 = wrong[sample.index(k5)], wrong[sample.index(k100)]
    n5, n100 = nomass[sample.index(k5)], nomass[sample.index(k100)]
    n_change = 100.0 * abs(n100 - n5) / n5 if n5 else float("nan")
    # the area-weighted L2 error of an M-orthogonal projection can only decrease with k
    mono = bool(np.all(np.diff(err.l2[1 : kmax + 1]) <= 1e-9 * diag))
    mono_txt = (
        f"its area-weighted L² error never increases with k (checked for every k up "
        f"to {kmax}, as an M-orthogonal projection must)"
        if mono
        else "its area-weighted L² error is NOT monotone in k (unexpected: check the solver)"
    )
    wrong_min_k = sample[int(np.argmin(wrong))]
    slow = max(solves, key=lambda r: r[4])
    sec.p(
        f"**Eigen-solve times.** The course report quotes {course_fast:.0f} s and "
        f"{course_slow:,.0f} s for its eigen-solves. Here the slowest solve took "
        f"{slow[4]:.1f} s ({slow[0]}, {slow[1]:,} vertices, k = {slow[2]}), "
        + "; ".join(f"k = {r[2]} on {r[0]}: {r[4]:.1f} s" for r in solves)
        + ". The method is shift-invert block Lanczos with spectrum slicing and a sparse "
        "Cholesky / LDLᵀ factorization (`spectral.laplacian_eigenpairs`); the max residual "
        "column shows the eigenpairs are converged, not approximated."
    )
    sec.p(
        "**The wrong inner product.** The eigenvectors are orthonormal for the M-inner product "
        "⟨u, v⟩ = uᵀMv, not for the Euclidean one, so the reconstruction must use the "
        "coefficients U_kᵀ M x. Dropping M — x̂ = U_k U_kᵀ x, the same formula with the "
        "Euclidean inner product — is not a projection, and its error stops responding to k. "
        "Measured on the same eigenvectors (table columns `rms_error_no_mass` and "
        "`rms_error_unit_vectors`):"
    )
    sec.p(
        f"(a) With the solver's M-orthonormal vectors and no M, the error is {_num(n5)} "
        f"diagonals at k = {k5} and {_num(n100)} at k = {k100}: it changes by only "
        f"{n_change:.1f} %"
        + (
            " — the course's symptom of an error that barely moves from k = 5 to 100"
            if n_change < 25
            else ""
        )
        + " (the reconstruction is scaled by about 1/(vertex area) and lands far from the "
        f"mesh). (b) With each eigenvector scaled to unit length (what a general eigensolver "
        f"for M⁻¹C returns), the error goes from {_num(w5)} to {_num(w100)} "
        f"({_ratio_words(w5, w100)}), is smallest at k = {wrong_min_k}, then "
        f"{'grows again' if wrong_min_k < sample[-1] else 'stalls'}: {_num(wrong[-1])} at "
        f"k = {sample[-1]}. (c) With M, as here, the RMS error falls from {_num(e5)} "
        f"(k = {k5}) to {_num(e100)} (k = {k100}), {_ratio_words(e5, e100)}, and "
        f"{_num(right[-1])} at k = {sample[-1]}; {mono_txt}."
    )
    fig = _new_figure(10.0, 4.0)
    ax = fig.add_subplot(1, 2, 1)
    kk = np.arange(1, kmax + 1)
    ax.loglog(kk, err.rms[1:] / diag, "-", color="tab:green", label="(c) with M (ours)")
    ax.loglog(
        sample, wrong, "o--", ms=3, color="tab:red", label="(b) no M, unit-length eigenvectors"
    )
    ax.loglog(
        sample,
        nomass,
        "s--",
        ms=3,
        color="tab:purple",
        label="(a) no M, M-orthonormal eigenvectors",
    )
    ax.loglog(kk, err.max[1:] / diag, ":", color="tab:green", alpha=0.7, label="max error, M")
    for k in ks:
        ax.axvline(k, color="0.85", lw=0.8, zorder=0)
    ax.set_xlabel("k (eigenvectors)")
    ax.set_ylabel("error / bbox diagonal")
    ax.set_title(f"{m.name}: reconstruction error against k", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    ax = fig.add_subplot(1, 2, 2)
    ax.semilogy(np.arange(1, kmax + 1), np.maximum(basis.eigenvalues[:kmax], 1e-12), ".", ms=2)
    ax.set_xlabel("index i")
    ax.set_ylabel("λ_i (frequency of −Δ)")
    ax.set_title("spectrum", fontsize=10)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "spectral_error_vs_k",
                "Left: RMS reconstruction error with the M inner product (solid; "
                "dotted: max error) and with the two forms of the Euclidean-inner-"
                "product bug (dashed). Right: the eigenvalues.",
            )
        ]
    )
    fig = _new_figure(10.0, 3.6)
    ax = fig.add_subplot(1, 1, 1)
    errs = {k: basis.vertex_error(k) / diag for k in ks}
    allv = np.concatenate([e[e > 0] for e in errs.values()])
    bins = np.geomspace(max(float(allv.min()), 1e-8), float(allv.max()), 60)
    for k in ks:
        ax.hist(np.maximum(errs[k], bins[0]), bins=bins, histtype="step", lw=1.5, label=f"k={k}")
    ax.set_xscale("log")
    ax.set_xlabel("per-vertex error |x − x̂| / bbox diagonal")
    ax.set_ylabel("vertices")
    ax.legend(fontsize=8)
    ax.set_title("per-vertex reconstruction error", fontsize=10)
    fig.tight_layout()
    meds = "; ".join(f"k = {k}: {_num(float(np.median(errs[k])))}" for k in ks)
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "spectral_error_histograms",
                "Histograms of the per-vertex error |x − x̂| / diagonal (log scale). "
                f"Median per k: {meds}.",
            )
        ]
    )
    ctx.progress.step("plots")
    shot_ks = [ks[0], ks[-1]] if ctx.quick else [k for k in ks if k in (5, 15, 50, 100, 500)]
    figs = (
        []
        if ctx.quick
        else [
            ctx.shot_or_render(
                "spectral_original", f"{m.name}: original, coloured by cotangent H", m
            )
        ]
    )
    for k in shot_ks:
        R = basis.reconstruct(k)
        figs.append(
            ctx.shot_or_render(
                f"spectral_k{k}",
                f"reconstruction from k = {k} eigenvectors (coloured by its cotangent H)",
                V=R,
                F=F,
                label=f"{m.name}_k{k}",
            )
        )
        ctx.progress.step(f"picture k={k}")
    sec.figs(figs)
    vmax = float(np.percentile(errs[shot_ks[0]], 99))
    vmin = max(float(np.percentile(errs[shot_ks[-1]], 1)), vmax * 1e-4)
    fig = _map_row(
        [(f"k = {k}", errs[k]) for k in shot_ks],
        V,
        F,
        vmax,
        "error / diagonal",
        vmin=vmin,
        log=True,
    )
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "spectral_error_maps",
                "Per-vertex error |x − x̂| / diagonal "
                f"drawn on the original {m.name} (one logarithmic colour scale for "
                "all k).",
                "render",
            )
        ]
    )


# --------------------------------------------------------------------------------------------
# section 6: smoothing
# --------------------------------------------------------------------------------------------


def _lam_grid(ctx: _Ctx, lap: str, method: str, limit: float) -> list[float]:
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


def _section_smoothing(ctx: _Ctx, sec: _Section) -> None:
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
    rows, hist = [], {}
    limits: dict[tuple[str, str], float] = {}
    mus: dict[tuple[str, str], float] = {}
    shots: list[tuple[str, str, str, str, float, bool, FloatArray]] = []
    for name in ("plane_ns", "fandisk_ns"):
        m = ctx.mesh(name)
        sec.p(f"Mesh `{name}`: {m.label}.")
        for lap in ("uniform", "cotan"):
            # μ_min once per mesh and Laplacian; the gains of every λ follow from it
            W, K = smoothing.operator_parts(m.V, m.F, lap)
            mu_min, _exact = smoothing.most_negative_eigenvalue(W, K)
            mus[(name, lap)] = mu_min
            limit = 2.0 / abs(mu_min) if mu_min < 0 else math.inf
            limits[(name, lap)] = limit
            mu_grid = np.linspace(mu_min, 0.0, 257)
            for method in ("explicit", "implicit"):
                for lam in _lam_grid(ctx, lap, method, limit):
                    gain = float(smoothing.amplification_curve(method, lam, [mu_min])[0])
                    radius = float(
                        np.abs(smoothing.amplification_curve(method, lam, mu_grid)).max()
                    )
                    stable = abs(gain) <= 1.0 + 1e-12
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", MeshWarning)
                        s = smoothing.Smoother(m.V, m.F, method, lap, lam, warn=False)
                    t0 = time.perf_counter()
                    s.run(iters)
                    dt = time.perf_counter() - t0
                    last = s.history[-1]
                    rows.append(
                        [
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
                    )
                    hist[(name, lap, method, lam)] = s.history
                    if not s.diverged:
                        shots.append(
                            (
                                name,
                                lap,
                                method,
                                f"{method} {lap} λ = {_num(lam)}",
                                lam / limit,
                                stable,
                                s.V.copy(),
                            )
                        )
                ctx.progress.step(f"{name} {lap} {method}")
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
            ", ".join(f"{r[0]} {r[1]} λ = {_num(r[3])} after {r[10]} steps" for r in div[:4])
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
        + "; ".join(f"{nm} {lap}: {_num(lim)}" for (nm, lap), lim in limits.items())
        + ". The uniform limit is at least 1 on any mesh (μ_min ≥ −2); the cotangent one has "
        "units of length² and shrinks with the square of the shortest edges."
    )
    import matplotlib as mpl

    hist_figs = []
    for name in ("plane_ns", "fandisk_ns"):
        closed = ctx.mesh(name).F is not None and metrics.is_closed(ctx.mesh(name).F)
        panels = [
            ("drift_rms", "RMS displacement from the input", True),
            ("step_rms", "RMS displacement of each step", True),
        ]
        if closed:
            panels.append(("volume_change_pct", "volume change %", False))
        fig = _new_figure(4.3 * len(panels), 6.4)
        for i, lap in enumerate(("uniform", "cotan")):
            runs = {k: h for k, h in hist.items() if k[0] == name and k[1] == lap}
            for j, (key, label, logy) in enumerate(panels):
                ax = fig.add_subplot(2, len(panels), i * len(panels) + j + 1)
                finite_stable = []
                for method, cmap, style in (("explicit", "Reds", "--"), ("implicit", "Blues", "-")):
                    lams = sorted(k[3] for k in runs if k[2] == method)
                    for q, lam in enumerate(lams):
                        h = runs[(name, lap, method, lam)]
                        pts = [
                            (e["iteration"], e[key])
                            for e in h
                            if e[key] is not None and (not logy or e[key] > 0)
                        ]
                        if not pts:
                            continue
                        it, y = zip(*pts, strict=True)
                        colour = mpl.colormaps[cmap](0.35 + 0.6 * q / max(len(lams) - 1, 1))
                        rel = lam / limits[(name, lap)]
                        ax.plot(
                            it,
                            y,
                            style,
                            color=colour,
                            lw=1.3,
                            label=f"{method[:4]} λ={_num(lam, 2)} ({rel:.2g}× limit)",
                        )
                        if rel <= 1.0 or method == "implicit":
                            finite_stable.extend(y)
                if not logy and finite_stable:
                    lo, hi = min(finite_stable), max(finite_stable)
                    pad = 0.08 * (hi - lo or 1.0)
                    ax.set_ylim(lo - pad, hi + pad)
                if logy:
                    ax.set_yscale("log")
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
    mu_min = mus[("fandisk_ns", "uniform")]
    mu = np.linspace(mu_min, 0.0, 400)
    fig = _new_figure(6.5, 3.8)
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
    ctx.progress.step("plots")
    # pictures: per mesh and Laplacian, one explicit and one implicit run
    # (quick: fandisk_ns with the uniform Laplacian only)
    figs = []
    for name in ("plane_ns", "fandisk_ns") if not ctx.quick else ("fandisk_ns",):
        mesh = ctx.mesh(name)
        if not ctx.quick:
            figs.append(ctx.shot_or_render(f"smoothing_{name}_input", f"{name}: input", mesh))
        for lap in ("uniform", "cotan") if not ctx.quick else ("uniform",):
            for meth in ("explicit", "implicit"):
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


# --------------------------------------------------------------------------------------------
# section 7: denoising
# --------------------------------------------------------------------------------------------


def _denoise_grid(ctx: _Ctx, lap: str, method: str, limit: float) -> list[float]:
    q = ctx.quick
    if lap == "uniform":
        fr = {
            "explicit": (0.1, 0.5, 0.9) if q else (0.1, 0.3, 0.5, 0.9),
            "implicit": (0.1, 0.3, 1.0) if q else (0.1, 0.3, 1.0, 3.0, 10.0),
            "taubin": (0.3, 0.6) if q else (0.3, 0.5, 0.7, 0.9),
        }[method]
        return list(fr)
    fr = {
        "explicit": (0.3, 0.9) if q else (0.1, 0.3, 0.5, 0.9),
        "implicit": (1.0, 10.0) if q else (0.3, 1.0, 3.0, 10.0, 100.0),
        "taubin": (0.5,) if q else (0.3, 0.5, 0.7),
    }[method]
    return [f * limit for f in fr]


def _config(r: dict[str, Any]) -> str:
    return f"{r['method']} {r['laplacian']} λ = {_num(r['lam'])} × {r['iters']}"


def _section_denoising(ctx: _Ctx, sec: _Section) -> None:
    clean = ctx.mesh("fandisk")
    noisy = ctx.mesh("fandisk_ns")
    V0, F = clean.V, clean.F
    if noisy.V.shape != V0.shape or not np.array_equal(noisy.F, F):
        raise MeshError(
            "fandisk_ns must have the same faces and vertex order as fandisk", noisy.label
        )
    alphas = (0.002, 0.005) if ctx.quick else (0.001, 0.002, 0.005, 0.01)
    iters = (1, 5, 10, 20) if ctx.quick else (1, 2, 5, 10, 20, 50, 100)
    methods = ("explicit", "implicit") if ctx.quick else ("explicit", "implicit", "taubin")
    sec.p(
        f"Clean reference: {clean.label}; noisy input: {noisy.label}, plus the clean mesh with "
        "seeded isotropic Gaussian noise of σ = α × bbox diagonal for α in "
        f"{', '.join(f'{a:g}' for a in alphas)} (seed 0). Every noisy mesh is smoothed with "
        f"each method ({', '.join(methods)}) and Laplacian (uniform, cotangent) over a grid of "
        f"λ and iteration counts {', '.join(map(str, iters))}; cotangent λ are multiples of the "
        "explicit limit 2/|μ_min| of that noisy mesh. Errors are against the clean mesh: RMSE "
        "of the vertex positions, volume change, mean absolute change of the dihedral angles."
    )
    cases: list[tuple[str, FloatArray]] = [(noisy.name, noisy.V)]
    for a in alphas:
        cases.append((f"α = {a:g}", noise.add_noise(V0, F, a, mode="isotropic", seed=0)))
    rows: list[dict[str, Any]] = []
    for label, Vn in cases:
        for lap in ("uniform", "cotan"):
            W, K = smoothing.operator_parts(Vn, F, lap)
            mu_min, _ = smoothing.most_negative_eigenvalue(W, K)
            limit = 2.0 / abs(mu_min)
            for method in methods:
                got = smoothing.denoise_sweep(
                    V0,
                    F,
                    V_noisy=Vn,
                    methods=(method,),
                    laplacians=(lap,),
                    lams=_denoise_grid(ctx, lap, method, limit),
                    iters=iters,
                )
                for r in got:
                    r["case"] = label
                    r["lam_over_limit"] = r["lam"] / limit
                rows.extend(got)
            ctx.progress.step(f"sweep {label} {lap}")
    cols = [
        "case",
        "noise",
        "method",
        "laplacian",
        "lam",
        "lam_over_limit",
        "iters",
        "rmse",
        "rmse_noisy",
        "max_error",
        "volume_change_pct",
        "volume_change_noisy_pct",
        "dihedral_mae_deg",
        "dihedral_mae_noisy_deg",
        "normal_dev_deg",
        "stable",
        "diverged",
        "seconds",
    ]
    sweep_tab = ctx.table(
        "denoise_sweep",
        "Every run of the sweep.",
        cols,
        [[r[c] for c in cols] for r in rows],
        max_rows=0,
    )
    by_case = {label: [r for r in rows if r["case"] == label] for label, _ in cases}
    level = {label: rs[0]["noise"] for label, rs in by_case.items()}

    # recommendation, from the measured rows only
    rec_rows = []
    for label, rs in by_case.items():
        b = smoothing.best_rows(rs, "rmse")[0]
        # a setting that collapses the mesh can have flat, "good" dihedral angles: only
        # settings that improve the positions (RMSE below the noisy one) qualify
        improving = [r for r in rs if math.isfinite(r["rmse"]) and r["rmse"] < r["rmse_noisy"]]
        bd = smoothing.best_rows(improving or rs, "dihedral_mae_deg")[0]
        vol_ok = [
            r
            for r in rs
            if r["volume_change_pct"] is not None
            and math.isfinite(r["volume_change_pct"])
            and abs(r["volume_change_pct"]) <= 1
        ]
        bv = smoothing.best_rows(vol_ok, "rmse")[0] if vol_ok else None
        rec_rows.append(
            [
                label,
                level[label],
                b["rmse_noisy"],
                _config(b),
                b["rmse"],
                100 * (1 - b["rmse"] / b["rmse_noisy"]),
                b["volume_change_pct"],
                _config(bd),
                bd["dihedral_mae_deg"],
                b["dihedral_mae_noisy_deg"],
                _config(bv) if bv else None,
                bv["rmse"] if bv else None,
                bv["volume_change_pct"] if bv else None,
            ]
        )
    rec_tab = ctx.table(
        "denoise_recommendation",
        "Recommendation per noise level, read off the sweep: the setting with the lowest RMSE, "
        "the one with the lowest dihedral-angle error among those that lower the RMSE, and the "
        "lowest RMSE among settings that change the volume by at most 1 %.",
        [
            "case",
            "noise_level",
            "rmse_noisy",
            "best_rmse_setting",
            "best_rmse",
            "rmse_reduction_pct",
            "best_rmse_volume_change_pct",
            "best_dihedral_setting",
            "best_dihedral_mae_deg",
            "noisy_dihedral_mae_deg",
            "best_rmse_volume_1pct_setting",
            "best_rmse_volume_1pct",
            "best_rmse_volume_1pct_change_pct",
        ],
        rec_rows,
    )
    per_method = []
    combos = [(lap, m) for lap in ("uniform", "cotan") for m in methods]
    wins: dict[tuple[str, str], int] = dict.fromkeys(combos, 0)
    for label, rs in by_case.items():
        best_by = {}
        for lap, m in combos:
            sub = [r for r in rs if r["laplacian"] == lap and r["method"] == m]
            b = smoothing.best_rows(sub, "rmse")
            if b:
                best_by[(lap, m)] = b[0]
                per_method.append(
                    [
                        label,
                        level[label],
                        lap,
                        m,
                        b[0]["lam"],
                        b[0]["lam_over_limit"],
                        b[0]["iters"],
                        b[0]["rmse"],
                        b[0]["rmse_noisy"],
                        b[0]["volume_change_pct"],
                        b[0]["dihedral_mae_deg"],
                        sum(1 for r in sub if r["diverged"]),
                        len(sub),
                    ]
                )
        if best_by:
            wins[min(best_by, key=lambda c: best_by[c]["rmse"])] += 1
    pm_tab = ctx.table(
        "denoise_best_per_method",
        "The best setting (lowest RMSE) of each Laplacian and method at each noise level.",
        [
            "case",
            "noise_level",
            "laplacian",
            "method",
            "lam",
            "lam_over_limit",
            "iters",
            "rmse",
            "rmse_noisy",
            "volume_change_pct",
            "dihedral_mae_deg",
            "diverged_runs",
            "runs",
        ],
        per_method,
    )
    ctx.progress.step("tables")

    # sentences generated from the numbers
    n_cases = len(by_case)
    ranking = sorted(wins.items(), key=lambda kv: -kv[1])
    top, top_wins = ranking[0]
    sec.p(
        "**Recommendation (computed from the table, not written by hand).** "
        + (
            f"The lowest RMSE is reached by {top[1]} smoothing with the {top[0]} Laplacian at "
            f"{top_wins} of {n_cases} noise levels"
            + (", ".join(f"; {c[1]} {c[0]} at {w}" for c, w in ranking[1:] if w) or "")
            + ". Per level: "
            + "; ".join(
                f"{r[0]} (noise {_num(r[1])}): {r[3]} lowers the RMSE from {_num(r[2])} "
                f"to {_num(r[4])} ({r[5]:.0f} % less) with a volume change of "
                f"{_pct(r[6]) if r[6] is not None else 'undefined'}"
                for r in rec_rows
            )
            + "."
        )
    )
    vol_same = sum(1 for r in rec_rows if r[10] == r[3])
    differ = [r for r in rec_rows if r[7] != r[3]]
    sec.p(
        f"The lowest-RMSE setting keeps the volume within 1 % at {vol_same} of {n_cases} "
        "levels (the last columns give the best setting under that constraint). Among the "
        "settings that lower the RMSE, the lowest dihedral-angle error is reached by "
        + "; ".join(f"{r[7]} at {r[0]} ({_num(r[9])}° → {_num(r[8])}°)" for r in rec_rows)
        + f": a different setting from the lowest-RMSE one at {len(differ)} of {n_cases} "
        "levels, so the recommendation depends on whether positions or normals matter more."
    )
    sec.add(rec_tab)
    sec.add(pm_tab)
    sec.add(sweep_tab)

    # RMSE against noise level
    fig = _new_figure(11.0, 4.0)
    ax = fig.add_subplot(1, 2, 1)
    synth = [label for label in by_case if label != noisy.name]
    xs = [level[lab] for lab in synth]
    ax.loglog(xs, [by_case[lab][0]["rmse_noisy"] for lab in synth], "k-o", label="noisy input")
    for lap, m in combos:
        ys = [
            next((r[7] for r in per_method if r[0] == lab and r[2] == lap and r[3] == m), np.nan)
            for lab in synth
        ]
        ax.loglog(xs, ys, "o-" if lap == "uniform" else "s--", ms=4, label=f"{m} {lap}")
    nl = level[noisy.name]
    ax.plot([nl], [by_case[noisy.name][0]["rmse_noisy"]], "k*", ms=12, label=f"{noisy.name}")
    ax.set_xlabel("noise level (RMS offset per coordinate / bbox diagonal)")
    ax.set_ylabel("RMSE against the clean mesh")
    ax.set_title("best RMSE of each method against noise level", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    ax = fig.add_subplot(1, 2, 2)
    rs = by_case[noisy.name]
    for lap, m in combos:
        bpm = next(
            (r for r in per_method if r[0] == noisy.name and r[2] == lap and r[3] == m), None
        )
        if bpm is None:
            continue
        sub = sorted(
            (r for r in rs if r["laplacian"] == lap and r["method"] == m and r["lam"] == bpm[4]),
            key=lambda r: r["iters"],
        )
        ax.plot(
            [r["iters"] for r in sub],
            [r["volume_change_pct"] for r in sub],
            "o-" if lap == "uniform" else "s--",
            ms=4,
            label=f"{m} {lap} λ = {_num(bpm[4], 2)}",
        )
    ax.axhline(0, color="0.5", lw=0.7)
    ax.set_xscale("log")
    ax.set_xlabel("iterations")
    ax.set_ylabel("volume change % (vs clean)")
    ax.set_title(f"{noisy.name}: volume change at each method's best λ", fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "denoise_rmse_volume",
                "Left: the best RMSE each method reaches, against the noise level "
                "(the star is the given noisy mesh). Right: volume change against "
                "iterations at the λ that gave each method its best RMSE.",
            )
        ]
    )

    # dihedral histograms and error maps on the given noisy mesh
    best_n = {
        c: next(
            r
            for r in rs
            if r["laplacian"] == c[0]
            and r["method"] == c[1]
            and r["lam"] == bp[4]
            and r["iters"] == bp[6]
        )
        for c in combos
        for bp in per_method
        if bp[0] == noisy.name and (bp[2], bp[3]) == c
    }
    sm_V: dict[tuple[str, str], FloatArray] = {}
    for c, r in best_n.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshWarning)
            sm_V[c] = smoothing.smooth(
                noisy.V, F, r["method"], r["laplacian"], r["lam"], r["iters"], warn=False
            )
    adj = metrics.edge_faces(F)
    th_clean = np.degrees(metrics.dihedral_angles(V0, F, adj))
    th_noisy = np.degrees(metrics.dihedral_angles(noisy.V, F, adj))
    both = np.concatenate([th_clean, th_noisy])
    both = both[np.isfinite(both)]
    lo_d = 5.0 * math.floor(float(both.min()) / 5.0)
    hi_d = 5.0 * math.ceil(float(both.max()) / 5.0)
    bins = np.linspace(lo_d, hi_d, max(int((hi_d - lo_d) / 2.5), 10) + 1)
    fig = _new_figure(11.0, 4.0)
    for j, (title, items) in enumerate(
        (
            ("input", [("clean", V0), ("noisy", noisy.V)]),
            (
                "best setting of each method",
                [(f"{c[1]} {c[0]}", v) for c, v in sm_V.items()] + [("clean", V0)],
            ),
        )
    ):
        ax = fig.add_subplot(1, 2, j + 1)
        for lab, Vx in items:
            th = np.degrees(metrics.dihedral_angles(Vx, F, adj))
            ax.hist(
                th[np.isfinite(th)],
                bins=bins,
                histtype="step",
                lw=1.4,
                label=lab,
                color="k" if lab == "clean" else None,
            )
        ax.set_yscale("log")
        ax.set_xlabel("dihedral angle (degrees; 180 = flat)")
        ax.set_ylabel("edges")
        ax.set_title(f"{noisy.name}: {title}", fontsize=10)
        ax.legend(fontsize=7)
    fig.tight_layout()
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "denoise_dihedral",
                "Dihedral-angle histograms (log counts) of the clean, the noisy and "
                "the denoised meshes (each method at its lowest-RMSE setting).",
            )
        ]
    )
    sharp = np.abs(th_clean - 180.0) > 30.0
    sharp_v = np.zeros(len(V0), dtype=bool)
    sharp_v[adj.edges[sharp].ravel()] = True

    def edge_err(Vx: FloatArray, mask: np.ndarray) -> float:
        th = np.degrees(metrics.dihedral_angles(Vx, F, adj))
        d = np.abs(th - th_clean)[mask]
        d = d[np.isfinite(d)]
        return float(d.mean()) if d.size else float("nan")

    if sharp.any():
        sec.p(
            f"Sharp edges: the clean {clean.name} has {int(sharp.sum())} edges whose dihedral "
            f"angle is more than 30° from flat ({int(sharp_v.sum())} vertices on them). Mean "
            f"|dihedral − clean| on those edges / on the other edges: noisy "
            f"{_num(edge_err(noisy.V, sharp))}° / {_num(edge_err(noisy.V, ~sharp))}°; "
            + "; ".join(
                f"{c[1]} {c[0]} {_num(edge_err(v, sharp))}° / {_num(edge_err(v, ~sharp))}°"
                for c, v in sm_V.items()
            )
            + ". Mean position error at vertices on sharp edges / elsewhere: "
            + "; ".join(
                f"{c[1]} {c[0]} {_num(float(np.linalg.norm(v - V0, axis=1)[sharp_v].mean()))}"
                f" / {_num(float(np.linalg.norm(v - V0, axis=1)[~sharp_v].mean()))}"
                for c, v in sm_V.items()
            )
            + "."
        )
    else:
        sec.p(
            f"The clean {clean.name} has no sharp edge (every dihedral angle is within 30° "
            "of flat), so feature preservation cannot be judged on it."
        )
    show = [("noisy input", noisy.V)] + [
        (f"{c[1]} {c[0]} ({_config(best_n[c]).split(' ', 2)[2]})", sm_V[c])
        for c in sorted(sm_V, key=lambda c: best_n[c]["rmse"])[:3]
    ]
    errs = [np.linalg.norm(Vx - V0, axis=1) for _, Vx in show]
    vmax = float(np.percentile(errs[0], 99))
    fig = _map_row(
        [
            (f"{title}\nRMSE {_num(float(np.sqrt(np.mean(e**2))))}", e)
            for (title, _Vx), e in zip(show, errs, strict=True)
        ],
        V0,
        F,
        vmax,
        "|x − x_clean|",
    )
    sec.figs(
        [
            ctx.save_fig(
                fig,
                "denoise_error_maps",
                f"Per-vertex error against the clean mesh, drawn on the clean "
                f"{clean.name} (same colour scale): the noisy input and the three "
                "methods with the lowest RMSE, each at its best setting.",
                "render",
            )
        ]
    )
    ctx.progress.step("plots")
    best_c = min(best_n, key=lambda c: best_n[c]["rmse"])
    sec.figs(
        [
            None
            if ctx.quick
            else ctx.shot_or_render("denoise_noisy", f"{noisy.name} (input)", noisy),
            ctx.shot_or_render(
                "denoise_best",
                f"{noisy.name} denoised with the lowest-RMSE setting: {_config(best_n[best_c])}",
                V=sm_V[best_c],
                F=F,
                label=f"{noisy.name}_denoised",
            ),
        ]
    )
    ctx.progress.step("pictures")


# --------------------------------------------------------------------------------------------
# rendering: markdown and HTML from the same blocks
# --------------------------------------------------------------------------------------------


def _md_table(t: _Table) -> list[str]:
    rows = t.rows if t.max_rows is None else t.rows[: t.max_rows]
    out = [f"*{t.caption}* ([CSV]({t.csv}), {len(t.rows)} rows)", ""]
    if rows:
        out.append("| " + " | ".join(t.columns) + " |")
        out.append("|" + "|".join("---" for _ in t.columns) + "|")
        for r in rows:
            out.append("| " + " | ".join(_fmt(x).replace("|", "\\|") for x in r) + " |")
        if len(rows) < len(t.rows):
            out.append("")
            out.append(f"({len(t.rows) - len(rows)} more rows in the CSV.)")
    return out


def _render_md(head: list[str], sections: list[_Section], timing: _Table) -> str:
    lines = list(head)
    for s in sections:
        lines += ["", f"## {s.number}. {s.title}", "", f"*Section time: {s.seconds:.1f} s.*", ""]
        if s.error:
            lines += [f"> **This section failed:** {s.error}", ""]
        for b in s.blocks:
            if isinstance(b, _Para):
                lines += [f"> **Note:** {b.text}" if b.kind == "note" else b.text, ""]
            elif isinstance(b, _FigRow):
                lines += [" ".join(f"![{f.caption}]({f.path})" for f in b.figs), ""]
                lines += ["*" + " | ".join(f.caption for f in b.figs) + "*", ""]
            elif isinstance(b, _Table):
                lines += [*_md_table(b), ""]
    lines += ["", "## Timings", "", *_md_table(timing), ""]
    return "\n".join(lines).rstrip() + "\n"


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1200px;
margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
table{border-collapse:collapse;font-size:12px;margin:.5em 0 1.2em}
th,td{border:1px solid #ccc;padding:2px 6px;text-align:right}
th{background:#f0f0f0}td.s{text-align:left}
.row{display:flex;flex-wrap:wrap;gap:10px;align-items:flex-start}
figure{margin:0;flex:1 1 320px;max-width:100%}
figure img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:12px;color:#444}
.note{background:#fff6d6;border-left:4px solid #e0b000;padding:.4em .8em}
.err{background:#ffe0e0;border-left:4px solid #c00;padding:.4em .8em}
code{background:#f3f3f3;padding:0 3px}
"""


def _html_inline(text: str) -> str:
    t = html.escape(text, quote=True)
    t = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", t)
    t = re.sub(r"`([^`]+)`", r"<code>\1</code>", t)
    return t


def _html_table(t: _Table) -> list[str]:
    rows = t.rows if t.max_rows is None else t.rows[: t.max_rows]
    out = [
        f'<p><em>{_html_inline(t.caption)}</em> (<a href="{html.escape(t.csv)}">CSV</a>, '
        f"{len(t.rows)} rows)</p>"
    ]
    if rows:
        out.append("<table>")
        out.append(
            "<thead><tr>"
            + "".join(f"<th>{html.escape(c)}</th>" for c in t.columns)
            + "</tr></thead>"
        )
        out.append("<tbody>")
        for r in rows:
            cells = "".join(
                f'<td class="s">{html.escape(_fmt(x))}</td>'
                if isinstance(x, str)
                else f"<td>{html.escape(_fmt(x))}</td>"
                for x in r
            )
            out.append(f"<tr>{cells}</tr>")
        out.append("</tbody></table>")
        if len(rows) < len(t.rows):
            out.append(f"<p>({len(t.rows) - len(rows)} more rows in the CSV.)</p>")
    return out


def _render_html(title: str, head_html: list[str], sections: list[_Section], timing: _Table) -> str:
    out = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8" />',
        f"<title>{html.escape(title)}</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        "<body>",
    ]
    out += head_html
    for s in sections:
        out.append(f'<section id="{s.key}">')
        out.append(f"<h2>{s.number}. {html.escape(s.title)}</h2>")
        out.append(f"<p><em>Section time: {s.seconds:.1f} s.</em></p>")
        if s.error:
            out.append(
                f'<p class="err"><strong>This section failed:</strong> {html.escape(s.error)}</p>'
            )
        for b in s.blocks:
            if isinstance(b, _Para):
                cls = ' class="note"' if b.kind == "note" else ""
                prefix = "<strong>Note:</strong> " if b.kind == "note" else ""
                out.append(f"<p{cls}>{prefix}{_html_inline(b.text)}</p>")
            elif isinstance(b, _FigRow):
                out.append('<div class="row">')
                for f in b.figs:
                    out.append(
                        f'<figure><a href="{html.escape(f.path)}"><img src="{html.escape(f.path)}"'
                        f' alt="{html.escape(f.caption)}" /></a>'
                        f"<figcaption>{_html_inline(f.caption)}</figcaption></figure>"
                    )
                out.append("</div>")
            elif isinstance(b, _Table):
                out += _html_table(b)
        out.append("</section>")
    out.append('<section id="timings">')
    out.append("<h2>Timings</h2>")
    out += _html_table(timing)
    out.append("</section>")
    out += ["</body>", "</html>"]
    return "\n".join(out) + "\n"


# --------------------------------------------------------------------------------------------
# the builder
# --------------------------------------------------------------------------------------------

_SECTION_FUNCS: dict[str, tuple[Callable[[_Ctx, _Section], None], int, int]] = {
    # key: (function, progress steps quick, progress steps full)
    "onering": (_section_onering, 3, 3),
    "uniform": (_section_uniform, 5, 6),
    "helicoid": (_section_helicoid, 5, 6),
    "cotan": (_section_cotan, 5, 5),
    "spectral": (_section_spectral, 5, 12),
    "smoothing": (_section_smoothing, 11, 17),
    "denoising": (_section_denoising, 9, 13),
}


def parse_sections(text: str | Sequence[str] | None) -> list[str]:
    """Section keys from ``"1,5"`` / ``"onering,spectral"`` (``None``: all, in order)."""
    if text is None:
        return list(SECTIONS)
    items = [t.strip() for t in (text.split(",") if isinstance(text, str) else text)]
    items = [t for t in items if t]
    if not items:
        raise MeshError("the list of sections is empty", "--sections")
    out = []
    for t in items:
        key = SECTIONS[int(t) - 1] if t.isdigit() and 1 <= int(t) <= len(SECTIONS) else t
        if key not in SECTIONS:
            raise MeshError(
                f"unknown section {t!r}; choose from 1-{len(SECTIONS)} or {', '.join(SECTIONS)}",
                "--sections",
            )
        if key not in out:
            out.append(key)
    return sorted(out, key=SECTIONS.index)


def _mesh_note(ctx: _Ctx) -> str:
    subs = {k: m for k, m in ctx.used.items() if m.substitute}
    real = {k: m for k, m in ctx.used.items() if not m.substitute}
    where = str(ctx.meshes_wanted) if ctx.meshes_wanted is not None else "(none)"
    if not ctx.used:
        return "No mesh files were needed by the selected sections."
    if not subs:
        return f"All meshes come from {where}."
    why = (
        f"{where} does not exist"
        if ctx.meshes_dir is None or not ctx.meshes_dir.is_dir()
        else f"{where} has no " + ", ".join(f"{k}.obj" for k in subs)
    )
    head = (
        "**The course meshes were not found, so this report uses the bundled assets instead** "
        if not real
        else "**Some course meshes were not found; bundled assets stand in for them** "
    )
    return (
        head
        + f"({why}). The numbers below are therefore NOT those of the course meshes: "
        + "; ".join(f"{k} → {m.label}" for k, m in subs.items())
        + ". Run with `--meshes DIR` (a folder with the course's .obj files) for the real "
        "study."
    )


def build_report(
    out_dir: str | os.PathLike,
    meshes_dir: str | os.PathLike | None = None,
    *,
    quick: bool = False,
    sections: Sequence[str] | str | None = None,
    screenshots: bool = True,
    progress_stream: IO[str] | None = None,
    viewer_cmd: Sequence[str] | None = None,
    max_screenshots: int | None = None,
) -> ReportResult:
    """Run the study and write ``report.md``, ``report.html``, ``figures/*.png`` and
    ``tables/*.csv`` into ``out_dir`` (created if needed).

    Parameters
    ----------
    out_dir : path
        Output folder.
    meshes_dir : path, optional
        Folder with the course meshes (``cube.obj``, ``lilium_s.obj``, ``plane.obj``,
        ``armadillo.obj``, ``plane_ns.obj``, ``fandisk.obj``, ``fandisk_ns.obj``; in the full
        report also ``armadillo_igl.obj`` if present). Default: :func:`default_meshes_dir`.
        Missing meshes are replaced by the bundled assets, and the report says so at the top.
    quick : bool
        Smaller sweeps, fewer eigenvectors and pictures (under 2 minutes on 2 cores).
    sections : list of str or str, optional
        Subset of :data:`SECTIONS` (names or numbers 1–7); default all.
    screenshots : bool
        Take viewer screenshots (a subprocess with polyscope's EGL backend). When ``False`` or
        when the first screenshot fails, meshes are drawn with matplotlib and the report says
        why.
    progress_stream : text stream, optional
        Where the progress bar goes (the CLI passes stderr); ``None``: silent.
    viewer_cmd : list of str, optional
        The command that takes screenshots (default
        ``[sys.executable, "-m", "meshlap_core.cli", "view"]``).
    max_screenshots : int, optional
        Take at most this many viewer screenshots (each is a subprocess of a few seconds); the
        later pictures are drawn with matplotlib and the report says so. Default: no limit.

    Returns
    -------
    ReportResult

    Raises
    ------
    MeshError
        ``meshes_dir`` given but not a directory, a bad section name, an output directory that
        cannot be created. A failure *inside* a section does not raise: the section is marked
        failed in the report and in :attr:`ReportResult.errors`.
    """
    t_start = time.perf_counter()
    keys = parse_sections(sections)
    if max_screenshots is not None and int(max_screenshots) < 0:
        raise MeshError(f"must be >= 0, got {max_screenshots}", "--max-screenshots")
    explicit = meshes_dir is not None
    mdir = Path(meshes_dir) if meshes_dir is not None else default_meshes_dir()
    if explicit and not mdir.is_dir():
        raise MeshError("is not a directory", os.fspath(mdir))
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise MeshError("exists and is not a directory", os.fspath(out))
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MeshError(
            f"cannot create the output directory: {exc.strerror or exc}", os.fspath(out)
        ) from None
    progress = Progress(progress_stream, len(keys))
    cmd = (
        list(viewer_cmd)
        if viewer_cmd is not None
        else [sys.executable, "-m", "meshlap_core.cli", "view"]
    )
    built: list[_Section] = []
    with tempfile.TemporaryDirectory(prefix="meshlap-report-") as tmp:
        ctx = _Ctx(
            out,
            mdir if mdir.is_dir() else None,
            explicit,
            quick,
            screenshots,
            cmd,
            progress,
            Path(tmp),
            max_screenshots,
        )
        ctx.meshes_wanted = mdir
        for i, key in enumerate(keys, start=1):
            func, steps_q, steps_f = _SECTION_FUNCS[key]
            sec = _Section(key, SECTIONS.index(key) + 1, SECTION_TITLES[key])
            progress.begin(i, key, steps_q if quick else steps_f)
            t0 = time.perf_counter()
            try:
                with np.errstate(all="ignore"):
                    func(ctx, sec)
                status = "done"
            except Exception as exc:  # one broken section must not lose the whole report
                sec.error = f"{type(exc).__name__}: {exc}"
                status = "FAILED"
            sec.seconds = time.perf_counter() - t0
            fallback = any(
                isinstance(b, _FigRow)
                and any(f.kind == "render" and f.caption.endswith("no screenshot)") for f in b.figs)
                for b in sec.blocks
            )
            noted = any(isinstance(b, _Para) and b.kind == "note" for b in sec.blocks)
            if fallback and not noted:
                sec.note(
                    "Pictures whose caption says 'matplotlib rendering' are not viewer "
                    f"screenshots: {ctx.screenshot_reason}."
                )
            progress.end(sec.seconds, status)
            built.append(sec)
        total = time.perf_counter() - t_start
        note = _mesh_note(ctx)
        timing = ctx.table(
            "section_timings",
            "Wall-clock seconds per section on this machine.",
            ["section", "title", "seconds", "figures", "tables", "status"],
            [
                [
                    f"{s.number}. {s.key}",
                    s.title,
                    s.seconds,
                    sum(len(b.figs) for b in s.blocks if isinstance(b, _FigRow)),
                    sum(1 for b in s.blocks if isinstance(b, _Table)),
                    "failed" if s.error else "ok",
                ]
                for s in built
            ]
            + [["total", "", total, len(ctx.figures), len(ctx.tables) + 1, ""]],
        )
        head_md, head_html = _head(ctx, built, keys, total, note)
        md_path, html_path = out / "report.md", out / "report.html"
        with atomic_write(md_path, "w", overwrite_inputs=ctx.inputs) as f:
            f.write(_render_md(head_md, built, timing))
        with atomic_write(html_path, "w", overwrite_inputs=ctx.inputs) as f:
            f.write(_render_html("meshlap report", head_html, built, timing))
    return ReportResult(
        out_dir=out,
        markdown=md_path,
        html=html_path,
        figures=list(ctx.figures),
        tables=list(ctx.tables),
        section_seconds={s.key: s.seconds for s in built},
        total_seconds=total,
        mesh_note=note,
        screenshots_ok=ctx.shots_ok,
        screenshot_failures=list(ctx.shot_failures),
        errors={s.key: s.error for s in built if s.error},
    )


def _machine() -> str:
    import scipy

    try:
        from importlib.metadata import version

        igl_v = version("libigl")
    except Exception:
        igl_v = "?"
    return (
        f"{platform.system()} {platform.machine()}, {os.cpu_count()} CPUs, Python "
        f"{platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"libigl {igl_v}"
    )


def _head(
    ctx: _Ctx, built: list[_Section], keys: list[str], total: float, note: str
) -> tuple[list[str], list[str]]:
    mode = "quick" if ctx.quick else "full"
    cmd = (
        "meshlap report"
        + (f" --meshes {ctx.meshes_dir}" if ctx.meshes_explicit else "")
        + f" --out {ctx.out}"
        + (" --quick" if ctx.quick else "")
        + ("" if len(keys) == len(SECTIONS) else f" --sections {','.join(keys)}")
    )
    shots = f"{ctx.shots_ok} viewer screenshots" if ctx.shots_ok else "no viewer screenshots"
    if ctx.shot_failures:
        shots += f" (screenshots stopped: {ctx.shot_failures[0]})"
    elif not ctx.screenshots and ctx.screenshot_reason:
        shots += f" ({ctx.screenshot_reason})"
    failed = [s for s in built if s.error]
    lines = [
        "# meshlap report",
        "",
        f"> {note}",
        "",
        f"Generated by meshlap {__version__} on {time.strftime('%Y-%m-%d %H:%M:%S')}, "
        f"{mode} mode, in {total:.1f} s on {_machine()}; {len(ctx.figures)} figures "
        f"({shots}), {len(ctx.tables)} tables (CSV in `tables/`).",
        "",
        f"Reproduce with `{cmd}`.",
        "",
        "Sign convention: every Laplacian is negative semidefinite, Δx = −2Hn (H > 0 on a "
        "sphere with outward normals); eigenvalues shown are the frequencies λ ≥ 0 of −Δ. "
        "`meshlap_core.surfaces` (section 3) uses do Carmo's sign, so its H is the negative of "
        "the mesh H for the same normal.",
        "",
    ]
    if failed:
        lines += [
            "> **Failed sections:** "
            + "; ".join(f"{s.number}. {s.key}: {s.error}" for s in failed),
            "",
        ]
    lines += [
        "Contents: "
        + " · ".join(
            f"[{s.number}. {s.title}](#{s.number}-{_slug(s.title)}) ({s.seconds:.1f} s)"
            for s in built
        )
    ]
    h = [
        "<h1>meshlap report</h1>",
        f'<p class="note">{_html_inline(note)}</p>',
        f"<p>{_html_inline(lines[4])}</p>",
        f"<p>{_html_inline(lines[6])}</p>",
        f"<p>{_html_inline(lines[8])}</p>",
    ]
    if failed:
        h.append(
            '<p class="err">'
            + html.escape(
                "Failed sections: " + "; ".join(f"{s.number}. {s.key}: {s.error}" for s in failed)
            )
            + "</p>"
        )
    h.append(
        "<p>Contents: "
        + " · ".join(
            f'<a href="#{s.key}">{s.number}. {html.escape(s.title)}</a> ({s.seconds:.1f} s)'
            for s in built
        )
        + "</p>"
    )
    return lines, h


def _slug(title: str) -> str:
    s = re.sub(r"[^\w\s-]", "", title.lower())
    return re.sub(r"\s+", "-", s.strip())


__all__ = [
    "COURSE_EIGEN_SECONDS",
    "SECTIONS",
    "SECTION_TITLES",
    "Progress",
    "ReportResult",
    "build_report",
    "default_meshes_dir",
    "parse_sections",
]
