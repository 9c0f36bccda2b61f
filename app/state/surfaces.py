"""Surfaces panel state: a parametric surface, its mesh, and the geometry at a chosen (u, v).

No polyscope import. Signs follow ``meshlap_core.surfaces`` (``e = −p_uu · n`` with
``n = p_u × p_v``: ``H > 0`` on a sphere, the mesh convention ``Δx = −2Hn`` too).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from meshlap_core import surfaces
from meshlap_core.errors import MeshError
from meshlap_core.options import DEFAULT_SURFACE_SIGNS, SURFACE_SIGNS
from meshlap_core.types import FloatArray

from ..panel_spec import PanelSpec
from ..text_numbers import sig
from .animation import RECORDER_WIDGETS, Animation, Option
from .isolines import isoline_fields
from .settings import Choice, Flag, Integer, Number, Settings

MAX_RES = 512  # cells per direction the viewer meshes (512² cells: 0.5 M triangles)
TURN_STEP_DEG = 5.0
"""θ step of the normal section turning (*turn*): one frame each, 72 frames per turn (as
``meshlap animate --panel surfaces --theta`` with its default ``--frames 72``)."""
PARAM_LIMIT = 1e3
"""The (u, v) a session may hold: beyond every surface's domain (the point is clamped into
the surface's own domain when it is set)."""
THETA_LIMIT = 3600.0
"""The section's θ a session may hold, in degrees (ten turns either way; taken modulo 360)."""

# fmt: off
SETTINGS = Settings(
    Choice("surface", "helicoid", choices=tuple(surfaces.SURFACES), label="surface",
           tooltip="a parametric surface p(u, v)",
           animate=Flag("--surface", "the parametric surface", default="saddle")),
    Integer("res", 48, lo=1, hi=MAX_RES, label="resolution",
            tooltip="cells per parameter direction; Enter applies"),
    Number("u", 0.0, lo=-PARAM_LIMIT, hi=PARAM_LIMIT, label="u", example=0.75,
           tooltip="first parameter of the point"),
    Number("v", 0.0, lo=-PARAM_LIMIT, hi=PARAM_LIMIT, label="v", example=0.5,
           tooltip="second parameter of the point"),
    Number("theta", 0.0, lo=-THETA_LIMIT, hi=THETA_LIMIT, slider=(0.0, 360.0),
           label="section theta", added=True, example=30.0,
           tooltip="direction of the normal section (orange) as a parameter angle theta: degrees "
           "in the (u, v) plane from the u axis towards v, i.e. the tangent p_u cos theta + "
           "p_v sin theta (normalized). phi is the same direction measured in the tangent "
           "plane from the first principal direction (the plot's axis). Drawn: its tangent "
           "t and its osculating arc of curvature k_n"),
    isoline_fields(("Gaussian curvature",)),
    Choice("signs", DEFAULT_SURFACE_SIGNS, choices=SURFACE_SIGNS, label="signs", added=True,
           tooltip="the sign of II: outward (meshlap's one convention, e = -p_uu . n: H > 0 on "
           "a sphere, as on meshes) or do-carmo (do Carmo's and the course's, e = p_uu . n: "
           "II, H, k1, k2 and k_n negated, k1 and k2 swap; K is the same), to check a hand "
           "calculation"),
)
# fmt: on
"""The Surfaces panel's settings: the surface, its resolution, the point (u, v) and the
normal section's θ (degrees)."""


def section_arc(
    p: surfaces.PointGeometry, t: FloatArray, kn: float, length: float, n: int = 80
) -> FloatArray:
    """Points ``(n,3)`` of the normal section's osculating arc at ``p.p``: the circle of
    curvature ``kn`` in the plane of the unit tangent ``t (3,)`` and the normal ``p.n``,
    bending the way the surface does whatever the sign of ``II`` (``p.signs``): the section's
    curvature vector is ``x'' = −κₙ n`` with meshlap's sign (``e = −p_uu · n``: a sphere's
    outward ``n`` has ``κₙ > 0`` while the sphere bends away from it), ``+κₙ n`` with do
    Carmo's. ``x(s) = p + t sin(κs)/κ + b (1 − cos(κs))/κ`` with ``b = ∓n``, at most one full
    turn; a straight segment when ``kn`` is 0."""
    b = -surfaces.signs_factor(p.signs) * np.asarray(p.n, dtype=np.float64)
    half = min(length, np.pi / abs(kn)) if abs(kn) > 1e-12 else length
    s = np.linspace(-half, half, n)
    if abs(kn) > 1e-9:
        along, up = np.sin(kn * s) / kn, (1.0 - np.cos(kn * s)) / kn
    else:
        along, up = s, 0.5 * kn * s * s
    return p.p[None, :] + along[:, None] * t[None, :] + up[:, None] * b[None, :]


def signed_sig(x: float, scale: float) -> str:
    """``x`` with its sign to 4 significant digits, or ``0`` when it is round-off against
    ``scale`` (κₙ = 4.4e-16 beside κ₁ = 1 is 0: :func:`..text_numbers.sig`)."""
    text = sig(x, scale)
    return text if text == "0" or text.startswith("-") else f"+{text}"


def tangent_frame(p: surfaces.PointGeometry) -> tuple[FloatArray, FloatArray]:
    """The orthonormal tangent frame ``(e1, e2)`` at ``p``: ``e1`` the first principal direction
    (of ``κ₁``), ``e2 = n × e1`` (along the second)."""
    e1 = p.dir1 / np.linalg.norm(p.dir1)
    return e1, np.cross(p.n, e1)


def geometric_angle(p: surfaces.PointGeometry, theta: float) -> float:
    """The angle φ in ``[0, 2π)``, measured in the tangent plane from the first principal
    direction (towards ``n × e1``), of the direction of parameter angle ``theta`` (radians,
    ``d = p_u cos θ + p_v sin θ``): the core's tangent-plane angle from ``p_u``
    (:func:`meshlap_core.surfaces.tangent_angle`, what ``meshlap surface`` reports) less
    that of the first principal direction, ``p.theta_max``."""
    phi = float(surfaces.tangent_angle(p, theta)) - p.theta_max
    return float(phi % (2 * np.pi))


def euler_curve(p: surfaces.PointGeometry, n: int = 181) -> tuple[FloatArray, FloatArray]:
    """``κₙ(φ)`` at ``n`` angles ``φ ∈ [0, 2π]`` measured in the tangent plane from the first
    principal direction: the core's ``κₙ`` at the tangent-plane angle ``p.theta_max + φ``
    (:func:`meshlap_core.surfaces.normal_curvature_from_forms` with ``angle="tangent"``, the
    curve ``meshlap surface --plot`` draws, shifted), evaluated from the point's forms, so the
    curve is Euler's ``κ₁ cos² φ + κ₂ sin² φ`` (what the tests check), not an assumption of it.

    Returns
    -------
    phi : (n,) float
        Radians.
    kn : (n,) float
    """
    phi = np.linspace(0.0, 2 * np.pi, int(n))
    kn = surfaces.normal_curvature_from_forms(p, p.theta_max + phi, angle="tangent")
    return phi, np.asarray(kn, dtype=float)


@dataclass
class SurfaceState:
    """The chosen surface, its mesh at ``res`` and everything at ``(u, v)``."""

    name: str = SETTINGS.default("surface")
    res: int = SETTINGS.default("res")
    u: float = SETTINGS.default("u")
    v: float = SETTINGS.default("v")
    signs: str = SETTINGS.default("signs")  # the sign of II (meshlap's, or do Carmo's)
    error: str = ""
    mesh: surfaces.SurfaceMesh | None = None
    point: surfaces.PointGeometry | None = None
    theta: FloatArray = field(default_factory=lambda: np.zeros(0))
    kn: FloatArray = field(default_factory=lambda: np.zeros(0))
    phi: FloatArray = field(default_factory=lambda: np.zeros(0))  # geometric angles (radians)
    kn_phi: FloatArray = field(default_factory=lambda: np.zeros(0))  # κₙ at ``phi``
    version: int = 0  # bumped when the mesh changes (re-register), not when (u, v) moves
    section_deg: float = SETTINGS.default("theta")  # θ of the section in 3D, in [0, 360)
    turning: bool = False  # *turn*: θ advances TURN_STEP_DEG per frame
    _turn_left: int = 0  # steps left in this turn

    @property
    def names(self) -> list[str]:
        return list(surfaces.SURFACES)

    @property
    def domain(self) -> tuple[float, float, float, float]:
        return tuple(float(x) for x in surfaces.get_surface(self.name).domain)  # type: ignore[return-value]

    def set_surface(self, name: str, res: int | None = None) -> bool:
        """Switch surface (and resolution); (u, v) goes to the surface's default point."""
        try:
            surf = surfaces.get_surface(name)
            mesh = surfaces.mesh_surface(surf, res if res is not None else self.res)
        except MeshError as exc:
            self.error = str(exc)
            return False
        self.name, self.mesh = name, mesh
        self.res = res if res is not None else self.res
        self.version += 1
        u, v = surf.default_uv
        return self.set_uv(u, v)

    def set_resolution(self, res: int) -> None:
        """Re-mesh the surface with ``res`` cells per direction.

        Raises
        ------
        MeshError
            ``res`` too small or too large for this surface (the old mesh stays).
        """
        if res > MAX_RES:
            raise MeshError(f"at most {MAX_RES} in the viewer, got {res}", "resolution")
        if not self.set_surface(self.name, int(res)):
            message, self.error = self.error, ""
            raise MeshError(message)

    def set_uv(self, u: float, v: float) -> bool:
        """Move the point (clamped into the domain); singular points keep the old point.

        Raises
        ------
        MeshError
            ``u`` or ``v`` is not a finite number (the point stays).
        """
        if not (np.isfinite(u) and np.isfinite(v)):
            raise MeshError(f"must be finite numbers, got u = {u!r}, v = {v!r}", "(u, v)")
        u0, u1, v0, v1 = self.domain
        u = float(np.clip(u, u0, u1))
        v = float(np.clip(v, v0, v1))
        try:
            point = surfaces.point_geometry(self.name, u, v, signs=self.signs)
            theta, kn = surfaces.normal_curvature_curve(self.name, u, v, n=181, signs=self.signs)
        except MeshError as exc:
            self.error = str(exc)
            return False
        self.u, self.v, self.point, self.theta, self.kn = u, v, point, theta, kn
        self.phi, self.kn_phi = euler_curve(point, n=181)
        self.error = ""
        return True

    def set_signs(self, signs: str) -> None:
        """Use the sign ``signs`` of ``II`` (:data:`~meshlap_core.options.SURFACE_SIGNS`): the
        point, its curves and the section are evaluated again with it.

        Raises
        ------
        MeshError
            Not one of the signs (nothing changes).
        """
        self.signs = SETTINGS["signs"].checked(signs, "signs")
        if self.point is not None:
            self.set_uv(self.u, self.v)

    def signs_line(self) -> str:
        """The line that says which sign ``II`` has (:func:`meshlap_core.surfaces.signs_note`)."""
        return surfaces.signs_note(self.signs)  # type: ignore[arg-type]

    def pick_vertex(self, i: int) -> bool:
        """Move the point to the parameters of mesh vertex ``i`` (a click on the surface)."""
        if self.mesh is None or not 0 <= i < len(self.mesh.uv):
            return False
        u, v = self.mesh.uv[i]
        return self.set_uv(float(u), float(v))

    def direction_vectors(self, scale: float = 0.25) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Base point ``(1,3)`` and the two principal directions ``(1,3)`` scaled for drawing."""
        p = self.point
        if p is None:
            raise MeshError("no point selected on the surface yet", "surface")
        return p.p[None, :], scale * p.dir1[None, :], scale * p.dir2[None, :]

    # ------------------------------------------------------------------ the normal section
    def set_section(self, degrees: float) -> None:
        """Turn the normal section to θ = ``degrees`` (taken modulo 360).

        Raises
        ------
        MeshError
            ``degrees`` is not a finite number (θ stays).
        """
        d = float(degrees)
        if not np.isfinite(d):
            raise MeshError(f"must be a finite angle in degrees, got {degrees!r}", "theta")
        self.section_deg = d % 360.0

    def section(self) -> tuple[FloatArray, float]:
        """The unit tangent ``t(θ) (3,)`` (``p_u cos θ + p_v sin θ``, normalized) and the normal
        curvature ``κₙ(θ)`` of the section at θ = ``section_deg``."""
        p = self.point
        if p is None:
            raise MeshError("no point selected on the surface yet", "surface")
        theta = np.radians(self.section_deg)
        c, s = float(np.cos(theta)), float(np.sin(theta))
        d = p.p_u * c + p.p_v * s
        # from the point's forms (surfaces.normal_curvature evaluates the surface's
        # derivatives again: ~6 ms, too much for every frame)
        kn = surfaces.normal_curvature_from_forms(p, theta)
        return d / np.linalg.norm(d), float(kn)

    def section_caption(self) -> str:
        """``saddle at (u, v) = (0.3, 0)   θ =  45.0°   κₙ(θ) = +0.5   (κ₁ = 1, κ₂ = -1)``
        (and ``signs: do-carmo`` when do Carmo's sign of ``II`` is on): the caption of a θ
        frame (``meshlap animate --theta`` and the viewer's recording)."""
        p = self.point
        if p is None:
            raise MeshError("no point selected on the surface yet", "surface")
        _, kn = self.section()
        signs = "   signs: do-carmo" if self.signs != DEFAULT_SURFACE_SIGNS else ""
        return (
            f"{self.name} at (u, v) = ({self.u:.3g}, {self.v:.3g})   θ = {self.section_deg:5.1f}°"
            f" in (u, v), φ = {self.section_phi_deg():5.1f}° from κ₁"
            f"   κₙ = {signed_sig(kn, max(abs(p.k1), abs(p.k2)))}"
            f"   (κ₁ = {sig(p.k1, max(abs(p.k1), abs(p.k2)))}, "
            f"κ₂ = {sig(p.k2, max(abs(p.k1), abs(p.k2)))}){signs}"
        )

    def section_phi_deg(self) -> float:
        """The section's direction as the geometric angle φ in degrees, ``[0, 360)``, measured
        in the tangent plane from the first principal direction (:func:`geometric_angle` of
        the parameter angle ``section_deg``)."""
        if self.point is None:
            raise MeshError("no point selected on the surface yet", "surface")
        return float(np.degrees(geometric_angle(self.point, np.radians(self.section_deg))))

    def toggle_turn(self) -> None:
        """*turn* / *pause turn*: one full turn of θ from where it is, ``TURN_STEP_DEG`` per
        frame (a pause goes on from there); it stops by itself after the turn."""
        if self.turning:
            self.turning = False
            return
        if self._turn_left <= 0:
            self._turn_left = round(360.0 / TURN_STEP_DEG) - 1
        self.turning = self._turn_left > 0

    def tick_turn(self) -> bool:
        """Advance θ by one step while turning (called every frame); True when θ moved."""
        if not self.turning or self.point is None:
            self.turning = False
            return False
        self.set_section(self.section_deg + TURN_STEP_DEG)
        self._turn_left -= 1
        self.turning = self._turn_left > 0
        return True


# ---------------------------------------------------------------- meshlap animate
def parse_uv(text: str | None) -> tuple[float, float] | None:
    """``"U,V"`` as two finite numbers (``None`` stays ``None``).

    Raises
    ------
    MeshError
        Not two finite numbers separated by a comma (``--uv``).
    """
    if text is None:
        return None
    try:
        u, v = (float(t) for t in text.split(","))
    except ValueError:
        raise MeshError(f"expected U,V such as 0.5,1.0, got {text!r}", "--uv") from None
    if not (math.isfinite(u) and math.isfinite(v)):
        raise MeshError(f"must be finite, got {text!r}", "--uv")
    return u, v


def _animation_from_session(opts: dict[str, Any], sf: dict[str, Any], source: Any) -> None:
    """``--theta`` implied, and the session's (u, v) unless another surface or a point is
    typed (the surface's flag then takes the session's surface)."""
    opts["theta"] = True
    if opts.get("uv") is None and opts.get("surface") in (None, sf["surface"]):
        opts["uv"] = f"{sf['u']!r},{sf['v']!r}"


def _animation_check(opts: dict[str, Any]) -> None:
    if not opts.get("theta"):
        raise MeshError("the surfaces animation is the normal section: add --theta", "--panel")
    if not 2 <= opts["frames"] <= 2000:
        raise MeshError(f"must be 2 to 2000, got {opts['frames']}", "--frames")
    if isinstance(opts.get("uv"), str):
        opts["uv"] = parse_uv(opts["uv"])


ANIMATION = Animation(
    summary="a turning normal section of a parametric surface (--theta)",
    options=(
        Option("--theta", "surfaces: turn the normal section", store_true=True),
        Option("--uv", "surfaces: the point (default: the surface's)", metavar="U,V"),
        Option("--frames", "surfaces: frames per turn (default 72)", 72, int),
    ),
    session_help=(
        "surfaces   the session's surface, resolution and (u, v); --theta is implied (--uv or\n"
        "           another --surface replace the point)"
    ),
    check=_animation_check,
    kind=lambda opts: "theta",
    fps={"theta": 15.0},
    frame_count=lambda opts: int(opts["frames"]),
    from_session=_animation_from_session,
    uses_mesh=False,
)
"""``meshlap animate --panel surfaces --theta``."""


SPEC = PanelSpec(
    name="surfaces",
    title="Surfaces",
    summary="parametric surfaces with their exact first and second fundamental forms, "
    "curvatures, principal directions and a normal section at theta",
    panel="SurfacesPanel",
    state=SurfaceState,
    settings=SETTINGS,
    animation=ANIMATION,
    unsaved={
        "turn": "an action: turns the section (its theta is declared)",
        "pause turn": "an action: stops at the theta shown (declared)",
        **RECORDER_WIDGETS,
    },
)
"""The Surfaces panel."""
