"""What every section works with: the course meshes (or their bundled stand-ins), the output
folders, tables and figures written atomically, viewer screenshots with a matplotlib fallback,
and the progress bar."""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import curvature, noise
from ..io import atomic_write, load_mesh
from ..progress import Progress
from ..types import FloatArray, IntArray
from .document import Fig, Table, csv_cell
from .figures import autocrop, draw_mesh, new_figure
from .shots import MeshSource, Screenshot, failure_reason

PACKAGE_ROOT = Path(__file__).resolve().parents[2]
ASSETS_DIR = PACKAGE_ROOT / "assets"


def default_meshes_dir() -> Path:
    """``../shared/meshes`` beside the checkout (it may not exist)."""
    return PACKAGE_ROOT.parent / "shared" / "meshes"


# course mesh -> (bundled stand-in, synthetic noise level alpha for the stand-in or None)
STAND_INS: dict[str, tuple[str, float | None]] = {
    "cube": ("cube.obj", None),
    "lilium_s": ("bumpy.obj", None),
    "plane": ("grid.obj", None),
    "armadillo": ("bumpy.obj", None),
    "plane_ns": ("grid.obj", 0.004),
    "fandisk": ("torus.obj", None),
    "fandisk_ns": ("torus.obj", 0.003),
}
NOISE_SEED = 7


@dataclass
class StudyMesh:
    """A course mesh as the report uses it: the file, or the bundled stand-in and why."""

    name: str  # the course name asked for
    V: FloatArray
    F: IntArray
    path: Path | None  # the file on disk (None for a generated noisy stand-in)
    label: str  # how the report names it
    substitute: bool


def _load_asset(file: str) -> tuple[FloatArray, IntArray, Path | None]:
    """A bundled mesh of ``assets/`` (generated like the bundled one if the file is missing)."""
    path = ASSETS_DIR / file
    if path.is_file():
        m = load_mesh(path)
        return m.V, m.F, path
    from .. import primitives

    gen = {
        "bumpy.obj": lambda: primitives.bumpy_sphere(4),
        "icosphere.obj": lambda: primitives.icosphere(3),
        "torus.obj": lambda: primitives.torus_mesh(48, 24),
        "grid.obj": lambda: primitives.grid(20, 20),
        "cube.obj": lambda: primitives.cube(0),
    }[file]
    V, F = gen()
    return V, F, None


class Context:
    """The state shared by the sections of one report: options, meshes loaded once, the files
    written so far, the screenshot status (on, or the reason it is off) and the progress bar."""

    def __init__(
        self,
        out_dir: Path,
        meshes_dir: Path | None,
        meshes_explicit: bool,
        quick: bool,
        screenshot: Screenshot | None,
        progress: Progress,
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
        self.screenshot = screenshot
        self.screenshots = screenshot is not None
        self.screenshot_reason = "" if self.screenshots else "screenshots were turned off"
        self.progress = progress
        self.figures: list[Path] = []
        self.tables: list[Path] = []
        self.shots_ok = 0
        self.shot_failures: list[str] = []
        self._meshes: dict[str, StudyMesh] = {}
        self.used: dict[str, StudyMesh] = {}
        self.inputs: list[Path] = []

    # ---- meshes ----------------------------------------------------------------------------
    def shared_path(self, name: str) -> Path | None:
        if self.meshes_dir is None:
            return None
        p = self.meshes_dir / f"{name}.obj"
        return p if p.is_file() else None

    def mesh(self, name: str) -> StudyMesh:
        if name in self._meshes:
            return self._meshes[name]
        path = self.shared_path(name)
        if path is not None:
            m = load_mesh(path)
            mesh = StudyMesh(name, m.V, m.F, path, f"{name}.obj ({len(m.V):,} vertices)", False)
            self.inputs.append(path)
        else:
            file, alpha = STAND_INS[name]
            V, F, apath = _load_asset(file)
            if alpha is not None:
                V = noise.add_noise(V, F, alpha, mode="isotropic", seed=NOISE_SEED)
                label = (
                    f"assets/{file} + seeded Gaussian noise σ = {alpha:g} × bbox diagonal "
                    f"(stand-in for {name}, {len(V):,} vertices)"
                )
                apath = None
            else:
                label = f"assets/{file} (stand-in for {name}, {len(V):,} vertices)"
            mesh = StudyMesh(name, V, F, apath, label, True)
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
    ) -> Table:
        path = self.tab_dir / f"{name}.csv"
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(list(columns))
        for r in rows:
            w.writerow([csv_cell(x) for x in r])
        with atomic_write(path, "w", overwrite_inputs=self.inputs) as f:
            f.write(buf.getvalue())
        self.tables.append(path)
        return Table(
            name, caption, list(columns), [list(r) for r in rows], self.rel(path), max_rows
        )

    def save_fig(self, fig: Any, name: str, caption: str, kind: str = "plot") -> Fig:
        path = self.fig_dir / f"{name}.png"
        with atomic_write(path, "wb", overwrite_inputs=self.inputs) as fh:
            fig.savefig(fh, format="png", dpi=100)
        self.figures.append(path)
        return Fig(self.rel(path), caption, kind)

    # ---- screenshots -----------------------------------------------------------------------
    def shot(
        self,
        name: str,
        caption: str,
        *,
        mesh: StudyMesh | None = None,
        V: FloatArray | None = None,
        F: IntArray | None = None,
        panel: str = "curvature",
        field: str = "cotan",
        vertex: int | None = None,
        use_file: bool = False,
        label: str | None = None,
    ) -> Fig | None:
        """A viewer screenshot of a mesh (its file if ``use_file``, else its arrays named
        ``label``), or ``None`` when screenshots are unavailable (the reason is kept)."""
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
        source: MeshSource = None
        if mesh is not None and V is None:
            V, F = mesh.V, mesh.F
        if use_file and mesh is not None and mesh.path is not None:
            source = mesh.path
        elif V is not None and F is not None:
            source = (V, F, label or name)
        options: dict[str, Any] = {"field": field} if panel == "curvature" else {}
        if vertex is not None:
            options["vertex"] = vertex
        ok, why = self._take(source, panel, options, out)
        if not ok:
            self.shot_failures.append(f"{name}: {why}")
            out.unlink(missing_ok=True)
            # every later screenshot would fail the same way: stop trying, say why once
            self.screenshots = False
            self.screenshot_reason = why
            return None
        self.shots_ok += 1
        self.figures.append(out)
        return Fig(self.rel(out), caption, "screenshot")

    def _take(
        self, source: MeshSource, panel: str, options: dict[str, Any], out: Path
    ) -> tuple[bool, str]:
        """Call the screenshot function and autocrop its PNG: ``(ok, reason if not ok)``."""
        take = self.screenshot
        if take is None:
            return False, self.screenshot_reason
        try:
            ok = bool(take(source, panel, options, out.resolve())) and out.is_file()
            why = "the viewer wrote no screenshot"
        except Exception as exc:  # whatever the viewer raises is the reason, given once
            ok, why = False, failure_reason(exc)
        if ok:
            try:
                ok = autocrop(out)
            except Exception as exc:  # a broken PNG counts as a failed screenshot
                ok, why = False, f"unreadable PNG ({exc})"
            if not ok:
                why = why if "PNG" in why else "the screenshot is blank"
        return ok, why

    def shot_or_render(
        self,
        name: str,
        caption: str,
        mesh: StudyMesh | None = None,
        *,
        V: FloatArray | None = None,
        F: IntArray | None = None,
        field: str = "cotan",
        values: FloatArray | None = None,
        cmap: str = "coolwarm",
        symmetric: bool = True,
        label: str | None = None,
    ) -> Fig:
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
            values = curvature.all_curvature_fields(V, F)[field]
        f = new_figure(6.4, 4.8)
        ax = f.add_axes((0.0, 0.0, 0.84, 1.0))
        sm = draw_mesh(ax, V, F, values, cmap=cmap, symmetric=symmetric)
        if sm is not None:
            cax = f.add_axes((0.86, 0.15, 0.03, 0.7))
            f.colorbar(sm, cax=cax)
        return self.save_fig(f, name, caption + " (matplotlib rendering: no screenshot)", "render")
