"""Fundamental forms, curvature fields, normal curvature, point classification and the
geometry of one point of a parametric surface (do Carmo, ch. 3, with ``II`` negated so that a
sphere with its outward normal has ``H > 0``: the signs are in the package notes; ``signs=
"do-carmo"`` gives do Carmo's own).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..curvature.principal import eig_sym2
from ..errors import MeshError
from ..options import (
    DEFAULT_SURFACE_SIGNS,
    DIRECTION_ANGLES,
    SURFACE_SIGNS,
    DirectionAngle,
    SurfaceSigns,
    check_choice,
)
from ..types import BoolArray, FloatArray
from .angles import tangent_angle, tangent_components
from .catalogue import ParametricSurface, check_uv, get_surface
from .derivatives import DerivativeMethod, Derivatives, surface_derivatives
from .singular import singular_description, singular_mask

CLASSIFICATIONS: tuple[str, ...] = ("elliptic", "hyperbolic", "parabolic", "planar", "umbilic")


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def signs_factor(signs: SurfaceSigns) -> float:
    """``+1`` for ``"outward"`` (``e = −p_uu · n``, the project's), ``−1`` for ``"do-carmo"``
    (``e = p_uu · n``): the factor on the project's ``II``.

    Raises
    ------
    MeshError
        ``signs`` is not one of :data:`~meshlap_core.options.SURFACE_SIGNS`.
    """
    return 1.0 if check_choice(signs, SURFACE_SIGNS, "signs") == "outward" else -1.0


def signs_note(signs: SurfaceSigns) -> str:
    """One line that says which sign ``II`` has (for text outputs, plots and the window)."""
    if signs_factor(signs) > 0:
        return (
            "signs: outward (meshlap's): e = -p_uu . n, n = p_u x p_v / |p_u x p_v| "
            "(H > 0 on a sphere, as on meshes)"
        )
    return (
        "signs: do-carmo (do Carmo's, the coursework's): e = p_uu . n, n = p_u x p_v / "
        "|p_u x p_v|; II, H, k1, k2 and k_n are meshlap's negated (k1, k2 and their directions "
        "swap), K is unchanged"
    )


@dataclass(frozen=True)
class CurvatureFields:
    """Fundamental forms and curvatures at a batch of points (every field has shape ``S``
    unless noted). ``singular`` marks the singular points of the parameterization (a declared
    pole, or ``p_u × p_v`` negligible against the surface's area scale: see
    :mod:`meshlap_core.surfaces.singular`); every curvature value is NaN there."""

    n: FloatArray  # S + (3,)
    E: FloatArray
    F: FloatArray
    G: FloatArray
    e: FloatArray
    f: FloatArray
    g: FloatArray
    K: FloatArray
    H: FloatArray
    k1: FloatArray
    k2: FloatArray
    w1: FloatArray  # S + (2,): parameter direction of k1, unit in the metric (w·I·w = 1)
    w2: FloatArray  # S + (2,)
    singular: BoolArray
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS  # the sign of e, f, g (and so H, k1, k2)


def surface_curvature_fields(
    surface: ParametricSurface | str,
    u: Any,
    v: Any,
    method: DerivativeMethod = "auto",
    derivatives: Derivatives | None = None,
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS,
) -> CurvatureFields:
    """Vectorized fundamental forms and curvatures at ``(u, v)`` (no domain check).

    Parameters
    ----------
    surface : ParametricSurface or str
    u, v : array_like, broadcastable to a shape ``S``
    method : see :func:`surface_derivatives`
    derivatives : Derivatives, optional
        ``surface_derivatives(surface, u, v, method)`` when the caller has it already (then
        ``method`` is not used): no second evaluation.
    signs : {"outward", "do-carmo"}
        The sign of ``II``: the project's ``e = −p_uu · n`` (default) or do Carmo's
        ``e = p_uu · n``. ``n``, ``E, F, G`` and ``K`` do not depend on it; ``e, f, g``, ``H``
        and the shape operator change sign, so ``κ₁``, ``κ₂`` become ``−κ₂``, ``−κ₁`` and
        ``w1``, ``w2`` swap (up to sign).

    Returns
    -------
    CurvatureFields

    Notes
    -----
    ``e = −p_uu · n, f = −p_uv · n, g = −p_vv · n`` (``= p_u · n_u, …``: positive where the
    surface bends away from ``n``; all three negated with ``signs="do-carmo"``),
    ``K = (eg − f²)/(EG − F²)`` and
    ``H = (eG − 2fF + gE)/(2(EG − F²))`` as in do Carmo. The
    principal curvatures are the eigenvalues of the shape operator ``I⁻¹II``, computed stably
    as those of the symmetric ``L⁻¹ II L⁻ᵀ`` (``I = LLᵀ``, Cholesky), so that ``κ₁ − κ₂`` is
    accurate to rounding even at umbilics; the principal parameter directions are
    ``w = L⁻ᵀ y`` for its unit eigenvectors ``y`` (so ``wᵀ I w = 1``), both in closed form
    (:func:`~meshlap_core.curvature.principal.eig_sym2`).
    """
    surface = get_surface(surface)
    sign = signs_factor(signs)
    D = surface_derivatives(surface, u, v, method) if derivatives is None else derivatives
    N = np.cross(D.p_u, D.p_v)
    nn = np.linalg.norm(N, axis=-1)
    singular = singular_mask(surface, u, v, N)
    n = np.divide(N, nn[..., None], out=np.full_like(N, np.nan), where=~singular[..., None])
    E, F, G = _dot(D.p_u, D.p_u), _dot(D.p_u, D.p_v), _dot(D.p_v, D.p_v)
    # II against the outward normal with the sign that makes a sphere positive (package notes),
    # or do Carmo's (sign = -1)
    e, f, g = -sign * _dot(D.p_uu, n), -sign * _dot(D.p_uv, n), -sign * _dot(D.p_vv, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        det = np.where(singular, np.nan, E * G - F * F)
        K = (e * g - f * f) / det
        H = (e * G - 2 * f * F + g * E) / (2 * det)
        l11 = np.sqrt(E)
        l21 = F / l11
        l22 = np.sqrt(det / E)
        # M = L^{-1} = [[m11, 0], [m21, m22]]
        m11, m21, m22 = 1 / l11, -l21 / (l11 * l22), 1 / l22
        a = m11 * m11 * e
        b = m11 * (m21 * e + m22 * f)
        c = m21 * m21 * e + 2 * m21 * m22 * f + m22 * m22 * g
    a, b, c = (np.where(singular, 0.0, x) for x in (a, b, c))
    k1, k2, x, y = eig_sym2(a, b, c)  # y1 = (x, y), the unit eigenvector of k1
    # at umbilics every direction is principal: report u (k1) and its metric-orthogonal (k2)
    umb = np.abs(k1 - k2) <= 1e-12 * np.maximum(1.0, np.maximum(np.abs(k1), np.abs(k2)))
    x, y = np.where(umb, 1.0, x), np.where(umb, 0.0, y)
    # w = L^{-T} y, L^{-T} = M^T = [[m11, m21], [0, m22]]; y2 = y1 turned by +90°
    w1, w2 = np.empty((*np.shape(k1), 2)), np.empty((*np.shape(k1), 2))
    w1[..., 0], w1[..., 1] = m11 * x + m21 * y, m22 * y
    w2[..., 0], w2[..., 1] = m21 * x - m11 * y, m22 * x
    nan = np.where(singular, np.nan, 1.0)
    return CurvatureFields(
        n=n,
        E=E,
        F=F,
        G=G,
        e=e,
        f=f,
        g=g,
        K=K,
        H=H,
        k1=k1 * nan,
        k2=k2 * nan,
        w1=w1 * nan[..., None],
        w2=w2 * nan[..., None],
        singular=singular,
        signs=signs,
    )


def normal_curvature(
    surface: ParametricSurface | str,
    u: float,
    v: float,
    theta: Any,
    method: DerivativeMethod = "auto",
    *,
    angle: DirectionAngle = "uv",
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS,
) -> FloatArray:
    """Normal curvature ``κₙ = II(d, d) / I(d, d)`` at ``(u, v)`` of the direction ``d`` at
    angle ``theta`` (:func:`normal_curvature_from_forms`).

    Parameters
    ----------
    surface, u, v, method : as in :func:`point_geometry`
    theta : array_like
        Radians: the parameter angle ``θ_uv`` (``angle="uv"``, the default) or the angle in the
        tangent plane from ``p_u / |p_u|`` (``angle="tangent"``).
    angle : {"uv", "tangent"}
    signs : {"outward", "do-carmo"}
        The sign of ``II`` (:func:`surface_curvature_fields`); do Carmo's negates ``κₙ``.

    Returns
    -------
    kn : float array of the shape of ``theta``
    """
    surface = get_surface(surface)
    check_choice(angle, DIRECTION_ANGLES, "angle")
    uu, vv = check_uv(surface, u, v)
    cf = surface_curvature_fields(surface, uu, vv, method, signs=signs)
    _require_regular(surface, cf, float(uu), float(vv))
    return normal_curvature_from_forms(cf, theta, angle)


def normal_curvature_from_forms(forms: Any, theta: Any, angle: DirectionAngle = "uv") -> FloatArray:
    """``κₙ = II(d, d) / I(d, d)`` of the direction at angle ``theta`` from fundamental forms
    already computed: ``forms`` has ``E, F, G, e, f, g`` (a :class:`CurvatureFields` or a
    :class:`PointGeometry`, whose ``signs`` the result has), broadcast against ``theta``.

    Parameters
    ----------
    forms : CurvatureFields or PointGeometry
    theta : array_like
        Radians, a parameter angle (``angle="uv"``: ``d = (cos θ, sin θ)`` in the ``(u, v)``
        plane, ``κₙ = (e c² + 2f cs + g s²)/(E c² + 2F cs + G s²)``) or a tangent-plane angle
        from ``p_u / |p_u|`` (``angle="tangent"``: ``d = L⁻ᵀ (cos θ, sin θ)``, unit in ``I``, so
        ``κₙ = II(d, d)``; :mod:`.angles`). In the tangent angle the curve is Euler's
        ``κ₁ cos²(θ − θ₁) + κ₂ sin²(θ − θ₁)``.
    angle : {"uv", "tangent"}

    Returns
    -------
    kn : float array of the broadcast shape
    """
    if check_choice(angle, DIRECTION_ANGLES, "angle") == "tangent":
        a, b = tangent_components(forms, theta)
        return forms.e * a * a + 2 * forms.f * a * b + forms.g * b * b
    th = np.asarray(theta, dtype=np.float64)
    c, s = np.cos(th), np.sin(th)
    second = forms.e * c * c + 2 * forms.f * c * s + forms.g * s * s
    first = forms.E * c * c + 2 * forms.F * c * s + forms.G * s * s
    return second / first


def normal_curvature_curve(
    surface: ParametricSurface | str,
    u: float,
    v: float,
    n: int = 361,
    *,
    angle: DirectionAngle = "uv",
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS,
) -> tuple[FloatArray, FloatArray]:
    """``κₙ`` sampled at ``n`` equally spaced angles in ``[0, 2π]`` (both ends, so that a plot
    closes; the default 361 is a 1° step), parameter angles or tangent-plane angles
    (``angle``, as in :func:`normal_curvature`), with the sign ``signs``.

    Returns
    -------
    theta : (n,) float
    kn : (n,) float
    """
    if int(n) < 2:
        raise MeshError(f"needs at least 2 samples, got {n}", "n")
    theta = np.linspace(0.0, 2 * np.pi, int(n))
    return theta, normal_curvature(surface, u, v, theta, angle=angle, signs=signs)


def classify(k1: float, k2: float, tol: float = 1e-8) -> str:
    """Classify a point from its principal curvatures ``κ₁ ≥ κ₂``.

    ``planar``: both ≈ 0; ``umbilic``: ``κ₁ ≈ κ₂ ≠ 0`` (a spherical point); ``parabolic``: one
    ≈ 0; ``elliptic``: same sign (``K > 0``); ``hyperbolic``: opposite signs (``K < 0``).
    "≈ 0" means ``|κ| ≤ tol`` and "≈" means ``|κ₁ − κ₂| ≤ tol·max(1, |κ₁|, |κ₂|)`` (curvatures in
    units of 1/length of ``p``).
    """
    a1, a2 = abs(k1) <= tol, abs(k2) <= tol
    if a1 and a2:
        return "planar"
    if abs(k1 - k2) <= tol * max(1.0, abs(k1), abs(k2)):
        return "umbilic"
    if a1 or a2:
        return "parabolic"
    return "elliptic" if k1 * k2 > 0 else "hyperbolic"


@dataclass(frozen=True)
class PointGeometry:
    """Everything at one point ``(u, v)`` of a surface (see the package notes for the signs).

    Attributes
    ----------
    surface : str
    u, v : float
    p, p_u, p_v, p_uu, p_uv, p_vv : (3,) float
    n : (3,) float
        ``(p_u × p_v) / |p_u × p_v|``.
    E, F, G, e, f, g : float
        First and second fundamental forms (``e = −p_uu · n``: positive on a sphere; with
        ``signs="do-carmo"`` ``e = p_uu · n``).
    K, H, k1, k2 : float
        Gaussian, mean and principal curvatures (``k1 ≥ k2``, ``H = (k1 + k2)/2``).
    dir1_uv, dir2_uv : (2,) float
        Principal directions in the parameter plane, unit Euclidean vectors
        ``(cos θ_uv, sin θ_uv)``.
    dir1, dir2 : (3,) float
        The same as unit 3-D tangent vectors ``(p_u cos θ_uv + p_v sin θ_uv) / |…|``.
    theta_max, theta_min : float
        Angles in the **tangent plane**, radians in ``[0, π)`` measured from the unit ``p_u``
        direction towards ``n × p_u`` (:func:`~.angles.tangent_angle`), of the directions where
        ``κₙ`` is largest (``= k1``, along ``dir1``) and smallest (``= k2``, along ``dir2``):
        always 90° apart. The extremes repeat at ``+π``. At an umbilic ``κₙ`` is constant and
        ``theta_max = 0`` (``p_u``).
    theta_uv_max, theta_uv_min : float
        The same two directions as angles in the ``(u, v)`` parameter plane, radians in
        ``[0, π)`` from the ``u`` axis towards ``v`` (the angles of ``dir1_uv``, ``dir2_uv``);
        90° apart only where ``I`` is a multiple of the identity.
    classification : str
        One of ``elliptic, hyperbolic, parabolic, planar, umbilic`` (see :func:`classify`);
        the same under both signs.
    signs : {"outward", "do-carmo"}
        The sign of ``II`` every curvature above was computed with
        (:func:`surface_curvature_fields`).
    """

    surface: str
    u: float
    v: float
    p: FloatArray
    p_u: FloatArray
    p_v: FloatArray
    p_uu: FloatArray
    p_uv: FloatArray
    p_vv: FloatArray
    n: FloatArray
    E: float
    F: float
    G: float
    e: float
    f: float
    g: float
    K: float
    H: float
    k1: float
    k2: float
    dir1_uv: FloatArray
    dir2_uv: FloatArray
    dir1: FloatArray
    dir2: FloatArray
    theta_max: float
    theta_min: float
    theta_uv_max: float
    theta_uv_min: float
    classification: str
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dict (lists for vectors); keys are the attribute names."""
        out: dict[str, Any] = {}
        for k in self.__dataclass_fields__:
            x = getattr(self, k)
            out[k] = x.tolist() if isinstance(x, np.ndarray) else x
        return out


def _require_regular(surface: ParametricSurface, cf: CurvatureFields, u: float, v: float) -> None:
    if bool(np.any(cf.singular)):
        D = surface_derivatives(surface, u, v)
        why = singular_description(surface, u, v, np.cross(D.p_u, D.p_v))
        raise MeshError(
            f"the parameterization of the {surface.name} is singular at (u, v) = ({float(u)!r}, "
            f"{float(v)!r}) ({why}): the normal, the forms and the curvatures are undefined there",
            "u, v",
        )


def _line_angle(t: float) -> float:
    """An angle of a line (direction up to sign) in ``[0, π)``."""
    t = float(t) % np.pi
    return 0.0 if t >= np.pi - 1e-15 else t


def _direction_angle(w: np.ndarray) -> float:
    """Angle in ``[0, π)`` of the line spanned by the parameter vector ``w``."""
    return _line_angle(math.atan2(float(w[1]), float(w[0])))


def point_geometry(
    surface: ParametricSurface | str,
    u: float | None = None,
    v: float | None = None,
    method: DerivativeMethod = "auto",
    tol: float = 1e-8,
    signs: SurfaceSigns = DEFAULT_SURFACE_SIGNS,
) -> PointGeometry:
    """Everything about the surface at one point ``(u, v)`` (default: ``surface.default_uv``).

    Parameters
    ----------
    surface : ParametricSurface or str
    u, v : float, optional
    method : see :func:`surface_derivatives`
    tol : float
        Of :func:`classify`.
    signs : {"outward", "do-carmo"}
        The sign of ``II`` (:func:`surface_curvature_fields`): the project's (default) or do
        Carmo's, which negates ``e, f, g``, ``H`` and ``κₙ``, turns ``κ₁, κ₂`` into
        ``−κ₂, −κ₁`` and so swaps ``dir1, dir2`` and ``theta_max, theta_min``; ``K``, ``n``
        and the classification do not change.

    Raises
    ------
    MeshError
        ``(u, v)`` outside the domain (naming ``u`` or ``v``) or a singular point of the
        parameterization (a declared pole, or ``|p_u × p_v|`` negligible against the surface's
        area scale: :func:`~meshlap_core.surfaces.singular.is_singular`), naming ``u, v``.

    Examples
    --------
    >>> import math
    >>> from meshlap_core import point_geometry
    >>> g = point_geometry("helicoid", 0.0, 0.0)
    >>> round(g.f, 12), round(g.K, 12), g.classification
    (1.0, -1.0, 'hyperbolic')
    >>> round(math.degrees(g.theta_max), 9)  # κₙ(θ) = sin 2θ at the origin
    45.0
    >>> dc = point_geometry("helicoid", 0.0, 0.0, signs="do-carmo")  # the course's sign
    >>> round(dc.f, 12), round(dc.K, 12), round(math.degrees(dc.theta_max), 9)
    (-1.0, -1.0, 135.0)
    """
    surface = get_surface(surface)
    u = surface.default_uv[0] if u is None else u
    v = surface.default_uv[1] if v is None else v
    uu, vv = check_uv(surface, u, v)
    if uu.ndim or vv.ndim:
        raise MeshError("expected a single number", "u" if uu.ndim else "v")
    uf, vf = float(uu), float(vv)
    D = surface_derivatives(surface, uf, vf, method)
    cf = surface_curvature_fields(surface, uf, vf, derivatives=D, signs=signs)
    _require_regular(surface, cf, uf, vf)
    dirs_uv, dirs_3d, angles_uv = [], [], []
    for w in (cf.w1, cf.w2):
        t = _direction_angle(w)
        d_uv = np.array([math.cos(t), math.sin(t)])
        d3 = d_uv[0] * D.p_u + d_uv[1] * D.p_v
        dirs_uv.append(d_uv)
        dirs_3d.append(d3 / np.linalg.norm(d3))
        angles_uv.append(t)
    # the same directions in the tangent plane (θ_uv ∈ [0, π) keeps θ ∈ [0, π))
    angles = [_line_angle(tangent_angle(cf, t)) for t in angles_uv]
    k1, k2 = float(cf.k1), float(cf.k2)
    return PointGeometry(
        surface=surface.name,
        u=uf,
        v=vf,
        p=D.p,
        p_u=D.p_u,
        p_v=D.p_v,
        p_uu=D.p_uu,
        p_uv=D.p_uv,
        p_vv=D.p_vv,
        n=np.asarray(cf.n),
        E=float(cf.E),
        F=float(cf.F),
        G=float(cf.G),
        e=float(cf.e),
        f=float(cf.f),
        g=float(cf.g),
        K=float(cf.K),
        H=float(cf.H),
        k1=k1,
        k2=k2,
        dir1_uv=dirs_uv[0],
        dir2_uv=dirs_uv[1],
        dir1=dirs_3d[0],
        dir2=dirs_3d[1],
        theta_max=angles[0],
        theta_min=angles[1],
        theta_uv_max=angles_uv[0],
        theta_uv_min=angles_uv[1],
        classification=classify(k1, k2, tol),
        signs=signs,
    )
