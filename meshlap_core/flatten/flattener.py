"""One mesh, every map: :class:`Flattener` builds the disk and the operators once, then gives
each map (:meth:`Flattener.map`) with its distortion, and ARAP one iteration at a time.

Precompute once, solve many: the disk (:func:`~meshlap_core.flatten.disk.make_disk`), the face
frames, the cotangent and graph Laplacians and every factorization are made on first use and
kept, so a second boundary shape for Tutte's or the harmonic map is two back substitutions and
the ARAP object reuses LSCM's map. :func:`flatten` is the one-shot wrapper.

Scales: Tutte's and the harmonic map put the boundary on the unit circle or ``[−1, 1]²``; LSCM
keeps its pins at ``(0, 0)`` and ``(d, 0)`` (``d`` their distance in space); the spectral map is
scaled to the surface's area; ARAP starts from a map of the surface's area (LSCM's, scaled, or
with a fixed boundary Tutte's on a circle or square of the surface's area). The distortion
measures are scale-free (:mod:`.distortion`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import MeshError, check_cancel
from ..io import save_mesh
from ..io.atomic import PathLike
from ..laplacian import cotangents_intrinsic
from ..linalg.common import ProgressCallback, report_progress
from ..options import (
    DEFAULT_ARAP_ITERS,
    FLATTEN_METHOD_BOUNDARIES,
    FLATTEN_METHODS,
    MAX_FLATTEN_ITERS,
    check_choice,
)
from ..topology import EdgeTable
from ..types import FloatArray
from .arap import ARAP
from .boundary import boundary_positions
from .conformal import LSCMSolver, far_pair, image_area
from .disk import Disk, make_disk
from .distortion import Distortion, measure_distortion
from .fixed_boundary import DirichletSolver, cotan_laplacian, graph_laplacian, squared_lengths
from .jacobian import FaceFrames, face_frames
from .spectral_conformal import spectral_conformal


def check_options(method: Any, boundary: Any = None, iters: Any = None) -> tuple[str, str, int]:
    """``(method, boundary, iters)`` checked, with the method's defaults filled in.

    Raises
    ------
    MeshError
        An unknown method or boundary, a boundary the method does not take (``"free"`` with
        Tutte's or the harmonic map, ``"circle"`` with LSCM, ...), ``iters`` with a method
        other than ARAP, or ``iters`` not an integer in ``[0, MAX_FLATTEN_ITERS]``.
    """
    check_choice(method, FLATTEN_METHODS, "method")
    allowed = FLATTEN_METHOD_BOUNDARIES[method]
    if boundary is None:
        boundary = allowed[0]
    if boundary not in allowed:
        takes = [m for m, b in FLATTEN_METHOD_BOUNDARIES.items() if boundary in b]
        raise MeshError(
            f"{method} takes the boundary {' or '.join(allowed)}, not {boundary!r}"
            + (f" ({boundary} applies to {', '.join(takes)})" if takes else ""),
            "boundary",
        )
    if method != "arap":
        if iters is not None:
            raise MeshError(f"iterations apply to arap only, not to {method}", "iters")
        return method, boundary, 0
    return method, boundary, check_iters(DEFAULT_ARAP_ITERS if iters is None else iters)


def check_iters(iters: Any, name: str = "iters") -> int:
    """``iters`` as an int in ``[0, MAX_FLATTEN_ITERS]``, else :class:`MeshError`."""
    if isinstance(iters, bool) or not isinstance(iters, int | np.integer):
        raise MeshError(f"must be an integer, got {iters!r}", name)
    if not 0 <= int(iters) <= MAX_FLATTEN_ITERS:
        raise MeshError(f"must be between 0 and {MAX_FLATTEN_ITERS}, got {int(iters)}", name)
    return int(iters)


@dataclass(eq=False)
class UVMap:
    """One map of a disk to the plane.

    Attributes
    ----------
    method : str
    boundary : str
    uv : (n',2) float
        One point per disk vertex (``disk.V``).
    disk : Disk
    seconds : float
        The map's own time (the disk and operators shared with other maps not counted).
    iterations : int
        ARAP's iterations (0 for the other maps).
    energies : list of float
        ARAP's energy at the start and after each iteration.
    pins : tuple of int
        LSCM's pinned disk vertices.

    Examples
    --------
    Tutte's map of a flat grid: its boundary on the unit circle, no face flipped:

    >>> import numpy as np
    >>> from meshlap_core import Flattener, grid
    >>> flat = Flattener(*grid(5, 5))
    >>> tutte = flat.map("tutte")
    >>> float(np.abs(np.linalg.norm(tutte.uv[flat.disk.outer], axis=1) - 1).max()) < 1e-12
    True
    >>> tutte.summary()["flipped"]
    0
    """

    method: str
    boundary: str
    uv: FloatArray
    disk: Disk
    seconds: float
    iterations: int = 0
    energies: list[float] = field(default_factory=list)
    pins: tuple[int, ...] = ()
    flattener: Flattener | None = field(default=None, repr=False)
    _distortion: Distortion | None = field(default=None, repr=False)

    def distortion(self) -> Distortion:
        """The per-face distortion (computed once; the face frames are the flattener's)."""
        if self._distortion is None:
            if self.flattener is not None:
                self._distortion = self.flattener.distortion(self.uv)
            else:
                self._distortion = measure_distortion(self.disk.V, self.disk.F, self.uv)
        return self._distortion

    def corner_uv(self) -> FloatArray:
        """The texture coordinate of every face corner, ``(3m,2)`` (face ``f``'s corners at
        rows ``3f, 3f+1, 3f+2``: what a viewer's per-corner parameterization takes)."""
        return self.uv[self.disk.F].reshape(-1, 2)

    def summary(self) -> dict[str, Any]:
        """The map's row of the distortion table: ``method``, ``boundary``, ``seconds``,
        ``iterations``, the distortion summary (:meth:`Distortion.summary`) and, for ARAP,
        ``energy``."""
        row = {"method": self.method, "boundary": self.boundary, "seconds": self.seconds}
        row["iterations"] = self.iterations
        row.update(self.distortion().summary())
        if self.energies:
            row["energy"] = self.energies[-1]
        return row


def distortion_table(maps: list[UVMap]) -> list[dict[str, Any]]:
    """One row per map (:meth:`UVMap.summary`), in the given order."""
    return [m.summary() for m in maps]


def unit_square_uv(uv: FloatArray) -> FloatArray:
    """``uv`` moved and scaled uniformly into ``[0, 1]²`` (centred, aspect kept): texture
    coordinates for a file; the distortion is unchanged."""
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    size = float((hi - lo).max())
    scale = 1.0 / size if size > 0 else 1.0
    return (uv - 0.5 * (lo + hi)) * scale + 0.5


class Flattener:
    """The maps of one mesh to the plane, sharing one disk and its operators.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    seam : (k,) int, optional
        A path of vertex indices to cut first (:func:`~meshlap_core.flatten.disk.make_disk`).
    cut : bool
        Cut handles and slit spheres automatically (default); ``False``: a mesh that is not
        a disk is refused.
    progress : callable, optional
        ``progress(fraction, message)`` while the disk is made.
    cancel : threading.Event or callable, optional
        Checked before and after the disk is made (:class:`~meshlap_core.errors.Cancelled`).

    Notes
    -----
    Its caches are filled on first use, so one thread (one job) at a time may call it; the
    :class:`UVMap` and :class:`~meshlap_core.flatten.arap.ARAP` objects it returns are
    independent of it once made.

    Attributes
    ----------
    disk : Disk
    V_input : (n,3) float
        The input's vertices (for :meth:`save_obj`).
    seconds : float
        The time to make the disk.

    Examples
    --------
    >>> from meshlap_core import Flattener
    >>> from meshlap_core.primitives import grid
    >>> flat = Flattener(*grid(6, 6))
    >>> tutte = flat.map("tutte")
    >>> tutte.summary()["flipped"]
    0
    >>> arap = flat.arap()  # starts from LSCM
    >>> arap.step() <= arap.energies[0]
    True

    A flat grid is its own conformal map: LSCM reproduces it up to a similarity, with
    angle distortion 1 and no area distortion:

    >>> import numpy as np
    >>> from meshlap_core import Flattener, grid
    >>> lscm = Flattener(*grid(5, 5)).map("lscm")
    >>> d = lscm.distortion()
    >>> bool(np.allclose(d.angle, 1) and np.allclose(d.area, 0, atol=1e-9))
    True
    """

    def __init__(
        self,
        V: Any,
        F: Any,
        seam: Any = None,
        *,
        cut: bool = True,
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> None:
        t0 = time.perf_counter()
        check_cancel(cancel, "flattening")
        report_progress(progress, 0.0, "cutting to a disk")
        self.disk = make_disk(V, F, seam, cut=cut)
        check_cancel(cancel, "flattening")
        self.V_input = np.array(V, dtype=np.float64)
        table = self.disk.table
        if table is None:  # (a Disk made by hand)
            table = EdgeTable.from_faces(self.disk.F, self.disk.n_vertices)
        self._table = table
        self.halfedges = table.boundary_halfedges()
        self._cache: dict[str, Any] = {}
        self.seconds = time.perf_counter() - t0
        report_progress(progress, 1.0, "disk ready")

    @property
    def frames(self) -> FaceFrames:
        """Every face's isometric frame (made on first use)."""
        return self._once("frames", lambda: face_frames(self.disk.V, self.disk.F))

    @property
    def area(self) -> float:
        """The surface's area."""
        return float(self.frames.area.sum())

    def distortion(self, uv: Any) -> Distortion:
        """The per-face distortion of any map ``uv`` ``(n',2)`` of the disk (the frames
        shared)."""
        return measure_distortion(self.disk.V, self.disk.F, uv, self.frames)

    @property
    def messages(self) -> tuple[str, ...]:
        """What was done to make the disk (:attr:`Disk.messages`)."""
        return self.disk.messages

    def _once(self, key: str, make: Any) -> Any:
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    @property
    def cotangents(self) -> FloatArray:
        """The cotangent of every corner angle ``(m,3)`` (made once)."""
        V, F = self.disk.V, self.disk.F
        return self._once("cot", lambda: cotangents_intrinsic(squared_lengths(V, F)))

    def stiffness(self, weights: str) -> Any:
        """``K`` with ``"uniform"`` (Tutte) or ``"cotan"`` weights (made once)."""
        if weights == "uniform":
            return self._once("K uniform", lambda: graph_laplacian(self._table))
        V, F = self.disk.V, self.disk.F
        return self._once("K cotan", lambda: cotan_laplacian(V, F, self.cotangents, self._table))

    def _fixed(self, weights: str, shape: str, scale: float = 1.0) -> FloatArray:
        solver = self._once(
            f"dirichlet {weights}",
            lambda: DirichletSolver(self.stiffness(weights), self.disk.outer),
        )
        return solver.solve(scale * boundary_positions(self.disk.V, self.disk.outer, shape))

    def lscm(self) -> tuple[FloatArray, tuple[int, int]]:
        """LSCM's map and its two pins (factorized once)."""
        solver = self._once(
            "lscm",
            lambda: LSCMSolver(
                self.disk.V,
                self.stiffness("cotan"),
                self.halfedges,
                far_pair(self.disk.V, self.disk.outer),
            ),
        )
        return solver.solve(), solver.pins

    def arap(self, boundary: str = "free", *, cancel: Any = None) -> ARAP:
        """A new ARAP iteration object: from LSCM's map scaled to the surface's area (free
        boundary), or from Tutte's with the outer loop pinned on a circle or square of the
        surface's area (``cancel`` checked between the start map and ARAP's factorization)."""
        check_options("arap", boundary, 0)
        check_cancel(cancel, "ARAP")
        if boundary == "free":
            uv, _ = self.lscm()
            uv = uv * np.sqrt(self.area / max(image_area(uv, self.halfedges), np.finfo(float).tiny))
            pinned = None
        else:
            shape_area = np.pi if boundary == "circle" else 4.0
            uv = self._fixed("uniform", boundary, np.sqrt(self.area / shape_area))
            pinned = self.disk.outer
        check_cancel(cancel, "ARAP")
        return ARAP(
            self.disk.V,
            self.disk.F,
            uv,
            pinned=pinned,
            frames=self.frames,
            cot=self.cotangents,
            K=self.stiffness("cotan"),
        )

    def map(
        self,
        method: str,
        boundary: str | None = None,
        *,
        iters: int | None = None,
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> UVMap:
        """The map ``method`` with the ``boundary`` shape (default: the method's first,
        :data:`~meshlap_core.options.FLATTEN_METHOD_BOUNDARIES`) and, for ARAP, ``iters``
        iterations (default :data:`~meshlap_core.options.DEFAULT_ARAP_ITERS`).

        Raises
        ------
        MeshError
            Bad options (:func:`check_options`), a spectral map on too long a boundary.
        Cancelled
            ``cancel`` asked to stop (SCP between solves, ARAP between iterations).
        """
        method, boundary, n_iter = check_options(method, boundary, iters)
        t0 = time.perf_counter()
        report_progress(progress, 0.0, f"{method} map")
        out: dict[str, Any] = {}
        weights = {"tutte": "uniform", "harmonic": "cotan"}.get(method)  # the fixed-boundary maps
        if weights is not None:
            uv = self._fixed(weights, boundary)
        elif method == "lscm":
            uv, out["pins"] = self.lscm()
        elif method == "scp":
            uv = spectral_conformal(
                self.stiffness("cotan"),
                self.halfedges,
                self.disk.boundary,
                self.area,
                progress=progress,
                cancel=cancel,
            )
        else:
            solver = self.arap(boundary, cancel=cancel)
            solver.run(n_iter, progress=progress, cancel=cancel)
            uv, out["iterations"], out["energies"] = solver.uv, n_iter, solver.energies
        seconds = time.perf_counter() - t0
        report_progress(progress, 1.0, f"{method} map done")
        return UVMap(method, boundary, uv, self.disk, seconds, flattener=self, **out)

    def save_obj(
        self, path: PathLike, uvmap: UVMap, *, overwrite_inputs: Any = (), unit: bool = True
    ) -> None:
        """Write the input mesh with the map as ``vt`` texture coordinates (faces
        ``f v/vt``), atomically; ``unit``: the coordinates moved and scaled uniformly into
        ``[0, 1]²`` (:func:`unit_square_uv`)."""
        uv = unit_square_uv(uvmap.uv) if unit else uvmap.uv
        save_mesh(
            path,
            self.V_input,
            self.disk.input_faces(),
            uv=uv,
            uv_faces=self.disk.F,
            overwrite_inputs=overwrite_inputs,
        )


def flatten(
    V: Any,
    F: Any,
    method: str = "tutte",
    boundary: str | None = None,
    *,
    iters: int | None = None,
    seam: Any = None,
    cut: bool = True,
    progress: ProgressCallback | None = None,
    cancel: Any = None,
) -> UVMap:
    """One map of ``(V, F)`` to the plane (a :class:`Flattener` used once).

    Examples
    --------
    >>> from meshlap_core.primitives import grid
    >>> uvmap = flatten(*grid(5, 5), "harmonic", "square")
    >>> bool(abs(uvmap.uv).max() <= 1.0)
    True
    """
    check_options(method, boundary, iters)  # before the disk is made
    return Flattener(V, F, seam, cut=cut).map(
        method, boundary, iters=iters, progress=progress, cancel=cancel
    )
