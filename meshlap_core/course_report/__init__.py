"""``meshlap report``: the course report, the whole curvature / spectral / smoothing analysis of
the course reproduced and checked.

Not :mod:`meshlap_core.curvature.study`, which measures the curvature estimators against exact
surfaces. This package was ``meshlap_core.study`` in 0.1.0 (docs/commands.md, "Renamed since
0.1.0"); the older module name ``meshlap_core.report`` is gone, and this name says which
report it is.

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
fundamental form against ``n = p_u × p_v`` with the same sign (``e = −p_uu · n``), so its ``H``
is the core's for the same normal.

This package is headless: it never imports polyscope nor the viewer. Mesh pictures come from a
screenshot function the caller passes (:class:`~meshlap_core.course_report.shots.Screenshot`; the
``meshlap report`` command passes the viewer's, rendering with polyscope's EGL backend in its own
process); without one, or when it fails (no EGL, no display libraries), the report still builds,
says why, and draws the mesh with matplotlib instead. Plots use matplotlib's Agg canvas
(imported lazily). Every file is written atomically (:func:`meshlap_core.io.atomic_write`).

Modules: :mod:`.document` (blocks, result, number formatting), :mod:`.render_md`,
:mod:`.render_html`, :mod:`.figures` (matplotlib rasterizer, autocrop), :mod:`.shots` (the
screenshot interface), :mod:`.context` (meshes, files, screenshots, progress bar),
:mod:`.sections` (one module per section), :mod:`.build` (:func:`build_report`,
:func:`parse_sections`).
"""

from __future__ import annotations

from .build import build_report, parse_sections
from .context import ASSETS_DIR, PACKAGE_ROOT, default_meshes_dir
from .document import ReportResult
from .sections import COURSE_EIGEN_SECONDS, SECTION_TITLES, SECTIONS
from .shots import MeshSource, Screenshot

__all__ = [
    "ASSETS_DIR",
    "COURSE_EIGEN_SECONDS",
    "PACKAGE_ROOT",
    "SECTIONS",
    "SECTION_TITLES",
    "MeshSource",
    "ReportResult",
    "Screenshot",
    "build_report",
    "default_meshes_dir",
    "parse_sections",
]
