"""The heat-method distance exercise: its calls, its reference and its classic mistakes.

The reference is the lab's own :class:`~meshlap_core.diffusion.HeatGeodesic` (Crane, Weischedel
& Wardetzky, "Geodesics in heat", ACM TOG 2013), ``t = m·h²``. The mistakes are written with
:func:`heat_steps`, the three steps of the paper spelt out with switches for each classic
mistake (the test suite checks that without any switch it gives the reference's answer):

- ``unnormalised``: ``X = −∇u`` instead of ``−∇u/|∇u|`` (the distance then follows the heat's
  size, not the unit speed of a distance);
- ``time_not_scaled``: ``t = m`` instead of ``m·h²`` (a mesh scaled by 250 gets another answer);
- a wrong sign of the divergence or of ``X`` (``d`` decreasing away from the source) and a
  missing shift (``d ≠ 0`` at the source) are recognised by :func:`fits_negated` and
  :func:`fits_shifted`: they hold for any additive constant, so whatever vertex a student pinned
  in the Poisson solve, the diagnosis is the same.
"""

from __future__ import annotations

from typing import Any

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse import csgraph

from ..diffusion.geodesic import HeatGeodesic, mean_edge_length
from ..spectral.operators import spectral_operators
from .compare import compare_array
from .meshes import Case

HEAT_CASES = ("small_sphere", "scaled", "large", "huge")
"""Closed, connected, without symmetric ties (on a regular tetrahedron the face opposite the
source is at constant heat: its direction is round-off, and no two codes agree on it)."""
HEAT_M = 1.0
"""The time factor passed to the student: ``t = m·h²`` (the paper's choice)."""


STUB = '''
def heat_geodesic(V, F, source, m):
    """Geodesic distance from vertex ``source`` by the heat method (Crane, Weischedel &
    Wardetzky, "Geodesics in heat", ACM TOG 2013), on a closed connected mesh.

    K = −C (cotan_laplacian), M = mass_matrix (mixed Voronoi), h the mean edge length (each
    edge once), t = m·h² (the time must scale with the mesh):
    1. heat: solve (M + t K) u = δ, δ one at the source and zero elsewhere;
    2. per face: X = −∇u / |∇u| (∇ the gradient of the piecewise-linear u; X = 0 where ∇u = 0);
    3. Poisson: K φ = Gᵀ A X (G the (3m, n) face gradient, A the diagonal of face areas:
       Gᵀ A X is minus the integrated divergence of X); K is singular (constants): pin one
       vertex, e.g. φ_0 = 0, and solve for the others;
    4. d = φ − φ[source].

    Returns d : (n,), 0 at the source and increasing away from it (units of length).
    """
    raise NotImplementedError
'''
"""The template's stub (declared with the task in :mod:`.tasks`)."""


def heat_calls(case: Case) -> list[tuple[str, tuple[Any, ...]]]:
    """One call per mesh, ``(V, F, source, m)``; the source is not vertex 0 (a student who pins
    vertex 0 in the Poisson solve and forgets the shift is then caught)."""
    source = len(case.V) // 2
    return [(f"source={source}", (case.V.copy(), case.F.copy(), source, HEAT_M))]


def heat_reference(case: Case, args: tuple[Any, ...]) -> np.ndarray:
    """The lab's heat-method distance from ``args[2]`` with ``t = args[3]·h²``; on a mesh with
    boundary (the viewer's) the heat step is the template's, zero flux (``"neumann"``)."""
    return HeatGeodesic(case.V, case.F, m=args[3], boundary="neumann").distance([args[2]])


UNDERFLOW = 1e-290
"""A face whose three corners' heat is below this times the largest heat has underflowed
(0 or denormal): its gradient has no direction in double precision."""


def heat_not_judged(case: Case, args: tuple[Any, ...]) -> str | None:
    """Why a failing call on ``case`` is not held against the student, or ``None``.

    The heat of ``t = m·h²`` decays like ``exp(−d/√t)``: beyond about 700 edge lengths from the
    source (a big scan, a long tube) it underflows to 0, and the template's ``−∇u/|∇u|`` is
    0/0 there; a right answer written from the template is then NaN, or noise, on such a mesh.
    The lab's reference takes those faces' direction from a longer time's heat, which the
    template does not ask for, so such a mesh cannot judge the student (the battery does).
    A mesh of several pieces cannot judge it either: the template's method assumes one (the
    distance to another piece is infinite, and its heat exactly 0 by topology, not by
    underflow)."""
    pieces = _pieces(case)
    if pieces > 1:
        return (
            f"not judged on mesh {case.name}: it has {pieces} separate pieces (connected "
            "components); the template's heat method is for one connected mesh (the distance "
            "to another piece is infinite); the battery's meshes judge the task"
        )
    u = HeatGeodesic(case.V, case.F, m=args[3], boundary="neumann").heat([args[2]])
    a = np.abs(u)
    lost = a[case.F].max(axis=1) <= UNDERFLOW * float(a.max(initial=0.0))
    if not lost.any():
        return None
    return (
        f"not judged on mesh {case.name}: the heat of t = m·h² underflows to 0 on "
        f"{100 * lost.mean():.2g} % of its faces (far from the source), where −∇u/|∇u| has no "
        "direction; the battery's meshes judge the task"
    )


def _pieces(case: Case) -> int:
    """Connected components of the faces' vertices (unreferenced vertices not counted)."""
    used = np.unique(case.F)
    if len(used) == 0:
        return 0
    n = len(case.V)
    e = np.concatenate([case.F[:, [0, 1]], case.F[:, [1, 2]]])
    A = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    _, labels = csgraph.connected_components(A, directed=False)
    return len(np.unique(labels[used]))


def heat_steps(
    V: np.ndarray,
    F: np.ndarray,
    source: int,
    t: float,
    *,
    normalise: bool = True,
) -> np.ndarray:
    """The heat method's three steps as the template states them (closed connected mesh).

    ``(M + tK) u = δ``; ``X = −∇u/|∇u|`` per face (``−∇u`` when ``normalise`` is False);
    ``K φ = Gᵀ A X`` with ``φ`` pinned at vertex 0; ``d = φ − φ[source]``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    source : int
    t : float
        The heat time (length²).
    normalise : bool

    Returns
    -------
    d : (n,) float
    """
    K, mass = spectral_operators(V, F, "cotan")
    n = len(V)
    delta = np.zeros(n)
    delta[source] = 1.0
    u = spla.spsolve((sp.diags(mass) + t * K).tocsc(), delta)
    G = igl.grad(V, F).tocsr()
    g = (G @ u).reshape(3, -1)
    if normalise:
        norm = np.linalg.norm(g, axis=0)
        g = np.divide(g, norm, out=np.zeros_like(g), where=norm > 0)
    area3 = np.tile(0.5 * igl.doublearea(V, F).ravel(), 3)
    b = G.T @ (area3 * -g.ravel())
    phi = np.zeros(n)
    phi[1:] = spla.spsolve(K[1:, 1:].tocsc(), b[1:])
    return phi - phi[source]


def heat_unnormalised(case: Case, args: tuple[Any, ...]) -> np.ndarray:
    """The mistake ``X = −∇u`` (the gradient not normalised)."""
    t = args[3] * mean_edge_length(case.V, case.F) ** 2
    return heat_steps(case.V, case.F, args[2], t, normalise=False)


def heat_time_not_scaled(case: Case, args: tuple[Any, ...]) -> np.ndarray:
    """The mistake ``t = m`` (not ``m·h²``)."""
    return heat_steps(case.V, case.F, args[2], args[3])


def heat_negated(case: Case, args: tuple[Any, ...]) -> np.ndarray:
    """A representative answer of the divergence sign mistake: ``−d``."""
    return -heat_reference(case, args)


def heat_unshifted(case: Case, args: tuple[Any, ...]) -> np.ndarray:
    """A representative answer of the missing shift: ``d`` plus a constant (one edge length)."""
    return heat_reference(case, args) + case.scale


def _constant_off(got: Any, target: np.ndarray, case: Case) -> tuple[bool, float]:
    """Whether ``got`` is ``target`` plus a constant (at the task's tolerance), and the constant."""
    try:
        g = np.asarray(got, dtype=np.float64).reshape(target.shape)
    except (TypeError, ValueError):
        return False, 0.0
    if not np.isfinite(g).all():
        return False, 0.0
    c = float(np.mean(g - target))
    return compare_array(g - c, target, case, 1).ok, c


def fits_negated(got: Any, expected: np.ndarray, case: Case) -> bool:
    """``got = −d + c``: the distance decreases away from the source (sign of ``∇·X``, or
    ``X = +∇u/|∇u|``), whatever the shift."""
    return _constant_off(got, -np.asarray(expected), case)[0]


def fits_shifted(got: Any, expected: np.ndarray, case: Case) -> bool:
    """``got = d + c`` with ``c ≠ 0``: right up to the shift that makes ``d = 0`` at the source."""
    ok, c = _constant_off(got, np.asarray(expected), case)
    return ok and not compare_array(np.asarray(expected) + c, expected, case, 1).ok
