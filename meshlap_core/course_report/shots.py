"""The interface through which the report gets viewer screenshots without importing the viewer.

The course report is part of the headless core, which never imports polyscope nor the viewer
package. :func:`~meshlap_core.course_report.build.build_report` therefore takes the screenshot
function as an argument: the ``meshlap report`` command (the top layer, which never imports the
viewer either) passes the viewer's (``meshlap_app.screenshots.ViewerScreenshots``, found through the
``meshlap.screenshots`` entry point); tests pass fakes.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, Protocol

from ..types import FloatArray, IntArray

MeshSource = Path | tuple[FloatArray, IntArray, str] | None
"""What to show: a mesh file, arrays ``(V (n, 3) float64, F (m, 3) int64, name)`` (the name is
what the viewer's panel calls the mesh), or ``None`` for the viewer's default mesh."""


class Screenshot(Protocol):
    """Render one viewer frame of ``mesh`` with ``panel`` open into the PNG ``out_png``.

    Parameters
    ----------
    mesh : MeshSource
        The mesh to show.
    panel : str
        The viewer panel shown (``"curvature"``, ``"onering"``, ``"surfaces"``, ...).
    options : mapping
        The panel's settings: ``field`` (curvature panel: the colour-mapped field) and
        ``vertex`` (one-ring panel: the selected vertex), when given.
    out_png : Path
        Where to write the frame (absolute; its folder exists).

    Returns
    -------
    bool
        ``True`` if ``out_png`` was written. Returning ``False`` or raising means the screenshot
        failed; the exception's message is the reason the report gives, and the report takes
        no further screenshots (every later one would fail the same way).
    """

    def __call__(
        self, mesh: MeshSource, panel: str, options: Mapping[str, Any], out_png: Path
    ) -> bool: ...


def failure_reason(exc: BaseException) -> str:
    """The reason a screenshot failed, in one line of at most 300 characters: the last line
    of the exception's message that is not polyscope's chatter, else the exception's type."""
    lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
    lines = [ln for ln in lines if not ln.startswith("[polyscope]")] or lines
    return lines[-1][:300] if lines else type(exc).__name__
