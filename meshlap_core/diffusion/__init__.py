"""Heat diffusion, geodesic distance and spectral filters: the Laplacian's other half.

Sign convention: ``Δ = M⁻¹C`` is negative semidefinite (``C`` the cotangent stiffness, ``M``
the lumped Voronoi mass); ``K = −C``; the frequencies ``λ ≥ 0`` are those of ``−Δ``
(``K φ = λ M φ``).

Modules
-------
``sources``
    Source vertices (checked) and a unit of heat at them.
``heat``
    ``u_t = Δu`` by backward Euler (:class:`HeatDiffusion`) and by the eigen-expansion
    (:func:`heat_spectral`), with the truncation bound ``e^{−λ_{k−1} t}``.
``geodesic``
    The heat method (:class:`HeatGeodesic`, Crane et al. 2013) and the exact polyhedral
    distance (:func:`exact_distance`, MMP through libigl).
``isolines``
    Level curves of a per-vertex field (``igl.isolines``) and their OBJ polyline file.
``filters``
    Spectral filters ``U h(Λ) Uᵀ M X``, the smoothers' transfer functions and a drawn one.
``hks``
    The heat kernel signature (Sun et al. 2009).
"""

from ..laplacian import mean_edge_length  # the heat time t = m h²; re-exported here
from .filters import (
    SpectralFilter,
    band_gain,
    curve_gain,
    low_pass,
    measured_amplification,
    smoother_transfer,
    transfer,
)
from .geodesic import (
    HeatGeodesic,
    boundary_vertices,
    exact_distance,
    igl_heat_distance,
)
from .heat import HeatDiffusion, heat_kernel_column, heat_spectral, truncation_bound
from .hks import heat_kernel_signature, hks_distance, hks_times
from .isolines import isoline_values, isolines, save_polylines
from .sources import check_sources, unit_heat

__all__ = [
    "HeatDiffusion",
    "HeatGeodesic",
    "SpectralFilter",
    "band_gain",
    "boundary_vertices",
    "check_sources",
    "curve_gain",
    "exact_distance",
    "heat_kernel_column",
    "heat_kernel_signature",
    "heat_spectral",
    "hks_distance",
    "hks_times",
    "igl_heat_distance",
    "isoline_values",
    "isolines",
    "low_pass",
    "mean_edge_length",
    "measured_amplification",
    "save_polylines",
    "smoother_transfer",
    "transfer",
    "truncation_bound",
    "unit_heat",
]
