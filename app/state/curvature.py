"""Curvature fields of the current mesh (``CurvatureState``), their colour ranges, and the
Curvature panel's spec (its settings: field, area, boundary rule, clip, side by side, second
field, estimator; the state is the :class:`~.app.AppState`'s ``curv``, which the One-ring view
and the export read too)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core.curvature import all_curvature_fields
from meshlap_core.curvature.estimators import (
    PATCH_RINGS,
    curvature_at_vertex,
    estimate_curvature,
)
from meshlap_core.curvature.principal import PrincipalCurvatures
from meshlap_core.curvature.topology import CurvatureTopology
from meshlap_core.errors import MeshError
from meshlap_core.options import (
    AREA_KINDS,
    BOUNDARY_RULES,
    CURVATURE_AREA,
    CURVATURE_ESTIMATOR_LABELS,
    CURVATURE_ESTIMATORS,
    CURVATURE_FIELD_LABELS,
    CURVATURE_FIELDS,
    PRINCIPAL_FIELDS,
)
from meshlap_core.types import FloatArray

from ..panel_spec import PanelSpec
from .isolines import isoline_fields
from .mesh import MeshState
from .settings import Choice, Flag, Number, Settings, Toggle

ESTIMATOR_HELP = "\n".join(f"{k}: {v}" for k, v in CURVATURE_ESTIMATOR_LABELS.items())
"""The estimator combo's tooltip: every estimator with its paper."""
PRINCIPAL_JOB = "principal curvatures"
"""The job owner of the estimator's run (the Curvature and One-ring views both start it)."""
FIELD_HELP = (
    "H = |Lx|/2 with the uniform or cotangent Laplacian (signed by the normal); "
    "K = (2 pi - sum of angles) / A_i; k1,2 = H +- sqrt(H^2 - K)"
)

# fmt: off
SETTINGS = Settings(
    Choice("field", "cotan", choices=CURVATURE_FIELDS, label="field", tooltip=FIELD_HELP,
           view=Flag("--field", "the curvature field shown first")),
    Choice("area", CURVATURE_AREA, choices=AREA_KINDS, label="area",
           tooltip="vertex area A_i: barycentric (1/3 of each face) or Voronoi"),
    Choice("boundary", "pi", choices=BOUNDARY_RULES, label="boundary rule",
           tooltip="Gaussian curvature at boundary vertices: pi - sum(angles) (geodesic "
           "curvature) or not defined"),
    Number("clip", 2.0, lo=0.0, hi=49.0, slider=(0.0, 20.0), fmt="%.1f", label="clip %",
           tooltip="colour range clips this percentage of vertices at each end (0 to 49)"),
    Toggle("side_by_side", False, label="side by side",
           tooltip="show a second field on a copy beside the mesh"),
    Choice("second_field", "uniform", choices=CURVATURE_FIELDS, label="second field",
           tooltip="the field on the copy"),
    Choice("estimator", "cotan", choices=CURVATURE_ESTIMATORS, label="estimator",
           tooltip="k1, k2 (and the One-ring view's shape operator) by:\n" + ESTIMATOR_HELP,
           added=True),  # written only when not cotan: older meshlaps read the file
    isoline_fields(CURVATURE_FIELDS),
)
# fmt: on
"""The Curvature panel's settings (its section of a saved session, ``--field``, widgets)."""


def robust_range(values: FloatArray, signed: bool, percentile: float = 2.0) -> tuple[float, float]:
    """Colour-map range that one outlier cannot wash out.

    Parameters
    ----------
    values : (n,) float
    signed : bool
        Symmetric range ``[-r, r]`` around zero (diverging maps) when true.
    percentile : float
        Clip this percentage at each end (0 = full range).

    Returns
    -------
    lo, hi : float
        ``lo < hi`` always (a constant field gets a small symmetric range).
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return -1.0, 1.0
    p = float(np.clip(percentile, 0.0, 49.0))
    lo, hi = np.percentile(v, [p, 100.0 - p])
    if signed:
        r = max(abs(lo), abs(hi))
        r = r if r > 0 else 1.0
        return -float(r), float(r)
    if hi <= lo:
        return float(lo) - 0.5, float(lo) + 0.5
    return float(lo), float(hi)


@dataclass
class CurvatureState:
    """Curvature fields of the current mesh for the chosen area and boundary rule, and how
    they are shown (the field, its clip percentage, a second field side by side)."""

    area: str = SETTINGS.default("area")
    boundary: str = SETTINGS.default("boundary")
    field_name: str = SETTINGS.default("field")
    percentile: float = SETTINGS.default("clip")
    side_by_side: bool = SETTINGS.default("side_by_side")
    second_field: str = SETTINGS.default("second_field")
    estimator: str = SETTINGS.default("estimator")
    principal: PrincipalCurvatures | None = None  # the estimator's, for ``_pkey``
    principal_error: str = ""  # the last failed estimator run's message
    _pkey: tuple[Any, ...] = ()
    _pjob: tuple[Any, ...] = ()  # the inputs of the estimator job started last
    _pfailed: tuple[Any, ...] = ()  # the inputs whose run failed (not retried)
    _key: tuple[Any, ...] = ()
    fields: dict[str, FloatArray] = field(default_factory=dict)
    _summaries: dict[tuple[Any, ...], dict[str, Any]] = field(default_factory=dict)
    _topology: tuple[Any, CurvatureTopology | None] = (None, None)  # (mesh version, topology)

    def update(self, mesh: MeshState) -> bool:
        """Recompute when the mesh, area or boundary rule changed. Returns whether it did."""
        if self.current(mesh):
            return False
        self.adopt(mesh, self.compute(mesh.V, mesh.F, self.area, self.boundary))
        return True

    def current(self, mesh: MeshState) -> bool:
        """The fields are those of ``mesh`` with the chosen area and boundary rule."""
        return self._key == (mesh.version, self.area, self.boundary)

    def computed_for(self) -> tuple[Any, ...]:
        """``(mesh version, area, boundary rule)`` the fields were computed for (``()``:
        none yet)."""
        return self._key

    @staticmethod
    def compute(
        V: FloatArray, F: Any, area: str, boundary: str, progress: Any = None
    ) -> dict[str, FloatArray]:
        """Every curvature field (any thread or a child process: touches no state)."""
        return all_curvature_fields(V, F, area, boundary)

    def adopt(self, mesh: MeshState, fields: dict[str, FloatArray]) -> None:
        """Take ``fields``, computed for ``mesh`` with the current area and boundary rule."""
        self.fields = fields
        self._key = (mesh.version, self.area, self.boundary)

    def set_estimator(self, name: str) -> None:
        """The estimator of the ``k1``, ``k2`` fields and of the shape operator
        (:data:`~meshlap_core.options.CURVATURE_ESTIMATORS`).

        Raises
        ------
        MeshError
            An unknown name (the previous one stays).
        """
        self.estimator = SETTINGS["estimator"].checked(name, "estimator")

    def principal_inputs(self, mesh: MeshState) -> tuple[Any, ...]:
        """What the estimate depends on: the mesh, the estimator, and for ``cotan`` the area
        and the boundary rule."""
        rules = (self.area, self.boundary) if self.estimator == "cotan" else ()
        return (mesh.version, self.estimator, *rules)

    def principal_current(self, mesh: MeshState) -> bool:
        """:attr:`principal` is the estimator's on ``mesh`` with the current rules."""
        return self.principal is not None and self._pkey == self.principal_inputs(mesh)

    @staticmethod
    def estimate(
        V: FloatArray, F: Any, estimator: str, area: str, boundary: str, progress: Any = None
    ) -> PrincipalCurvatures:
        """The estimator's principal curvatures and directions (any thread or a child
        process; ``area`` and ``boundary`` are cotan's)."""
        options = {"area": area, "boundary": boundary} if estimator == "cotan" else {}
        return estimate_curvature(V, F, estimator, **options)

    def adopt_principal(self, inputs: tuple[Any, ...], p: PrincipalCurvatures) -> None:
        """Take the estimate ``p`` computed for ``inputs`` (:meth:`principal_inputs`)."""
        self.principal, self._pkey = p, inputs
        self._summaries.clear()

    def values(self, name: str) -> FloatArray:
        """The field ``name`` as shown: ``k1`` and ``k2`` from the chosen estimator (once
        computed; the cotan fields' until then and for ``cotan``), the others as computed."""
        p, mesh_version = self.principal, self._key[:1]
        if name in PRINCIPAL_FIELDS[:2] and self.estimator != "cotan" and p is not None:
            if self._pkey[:2] == (*mesh_version, self.estimator):
                return p.k1 if name == "k1" else p.k2
        return self.fields[name]

    def want_principal(self, mesh: MeshState, jobs: Any, background: bool) -> bool:
        """Bring :attr:`principal` up to date for ``mesh``: right here outside the window, a
        job (:data:`PRINCIPAL_JOB`, a child process) in it. True when it is current; a failed
        run is not retried until an input changes (its message in :attr:`principal_error`)."""
        wanted = self.principal_inputs(mesh)
        if self.principal_current(mesh):
            return True
        if self._pfailed == wanted or (
            jobs.running(PRINCIPAL_JOB) is not None and self._pjob == wanted
        ):
            return False

        def apply(p: PrincipalCurvatures) -> None:
            if self.principal_inputs(mesh) == wanted:
                self.adopt_principal(wanted, p)

        def fail(message: str) -> None:
            self._pfailed, self.principal_error = wanted, message

        self._pjob, self.principal_error = wanted, ""
        args = (mesh.V, mesh.F, self.estimator, self.area, self.boundary)
        jobs.start(
            PRINCIPAL_JOB,
            f"principal curvatures ({self.estimator})",
            jobs.offload(self.estimate, *args),
            apply,
            fail,
            background=background,
        )
        return self.principal_current(mesh)

    def shape_operator(self, mesh: MeshState, vertex: int) -> dict[str, Any] | None:
        """The estimator's 2×2 shape operator at ``vertex`` in its tangent basis
        (:meth:`~meshlap_core.curvature.principal.PrincipalCurvatures.shape_operator`): ``S``,
        ``t1``, ``t2``, ``k1``, ``k2`` and ``estimator``. From the whole mesh's estimate when it is
        current, else from a patch around the vertex (milliseconds on a big scan:
        :func:`~meshlap_core.curvature.estimators.curvature_at_vertex`); ``None`` for the jet
        until its whole-mesh estimate is there (:meth:`want_principal`)."""
        if not 0 <= vertex < len(mesh.V):
            return None
        p, i = self.principal, vertex
        if p is None or not self.principal_current(mesh):
            if self.estimator not in PATCH_RINGS:
                return None
            options = {"area": self.area, "boundary": self.boundary}
            p, i = curvature_at_vertex(
                mesh.V,
                mesh.F,
                vertex,
                self.estimator,
                topology=self.topology(mesh),
                **(options if self.estimator == "cotan" else {}),
            )
        S, t1, t2 = p.shape_operator(i)
        return {
            "S": S,
            "t1": t1,
            "t2": t2,
            "k1": float(p.k1[i]),
            "k2": float(p.k2[i]),
            "estimator": self.estimator,
        }

    def topology(self, mesh: MeshState) -> CurvatureTopology:
        """``mesh``'s faces for the estimators' patches (:meth:`shape_operator`), built on the
        first click and kept for the mesh: the next clicks read only the faces near the
        vertex (a patch at 692k vertices: about 0.1 s with a new topology, 30–40 ms with it)."""
        if self._topology[0] != mesh.version or self._topology[1] is None:
            self._topology = (mesh.version, CurvatureTopology.of(mesh.F, len(mesh.V)))
        return self._topology[1]

    def set_percentile(self, percentile: float) -> None:
        """Clip percentage of the colour range, clamped into its setting's range (0 to 49).

        Raises
        ------
        MeshError
            ``percentile`` is not a finite number (the previous one stays).
        """
        clip = SETTINGS["clip"]
        p = float(percentile)
        if not np.isfinite(p):
            raise MeshError(f"must be a finite number, got {percentile!r}", clip.label)
        self.percentile = clip.clamp(p)

    def color_range(self, name: str | None = None) -> tuple[float, float]:
        """Robust colour range of a field (symmetric around 0 for signed fields)."""
        return self.summary(name)["range"]

    def summary(self, name: str | None = None, bins: int = 60) -> dict[str, Any]:
        """Range, min/max and histogram of a field, cached until the field or the clip
        percentage changes (the panel reads it every frame)."""
        name = name or self.field_name
        key = (self._key, name, self.percentile, bins, self.estimator, self._pkey)
        cached = self._summaries.get(key)
        if cached is None:
            values = self.values(name)
            lo, hi = robust_range(values, CURVATURE_FIELD_LABELS[name][1], self.percentile)
            counts, edges = np.histogram(np.clip(values, lo, hi), bins=bins, range=(lo, hi))
            cached = {
                "range": (lo, hi),
                "min": float(values.min()),
                "max": float(values.max()),
                "centers": 0.5 * (edges[1:] + edges[:-1]),
                "counts": counts.astype(np.float64),
                "width": float(edges[1] - edges[0]),
            }
            self._summaries = {k: v for k, v in self._summaries.items() if k[0] == self._key}
            self._summaries[key] = cached
        return cached


SPEC = PanelSpec(
    name="curvature",
    title="Curvature",
    summary="a curvature field as a colour map (uniform or cotangent H, K, k1, k2), its "
    "histogram, a second field side by side",
    panel="CurvaturePanel",
    settings=SETTINGS,
)
"""The Curvature panel (its state is the app's ``curv``: no slice of its own)."""
