"""Driving the viewer's widgets on polyscope's ``openGL_mock`` backend, one frame at a time.

The ``viewer`` fixture (``tests/conftest.py``) draws through the scripted UI adapter
(:class:`tests.support.scripted_ui.ScriptedUI`): a test says what a widget returns on a frame
and runs the frame. These helpers are shared by the widget tests and the drivers of the
every-widget tour (:mod:`tests.support.drivers`).
"""

from __future__ import annotations

import time
from pathlib import Path

import polyscope as ps
from meshlap_app.viewer import Viewer

from meshlap_core import primitives
from meshlap_core.io import save_mesh

BAD_NUMBERS = ["", "0", "-1", "nan", "1e309", "abc"]

EXPORT_WIDGETS = ("folder", "screenshot", "export what is shown")
HELP_WIDGETS = ("polyscope's own panels", "UI scale")
HELP_HEADER = "Help and window (H)"


def frames(viewer: Viewer, n: int = 1) -> None:
    """Run ``n`` frames; no exception may end the session and nothing may be an internal error."""
    for _ in range(n):
        ps.frame_tick()
    internal = {k: m for k, m in viewer.state.errors.items() if "internal error" in m}
    assert not internal, internal


def drive(viewer: Viewer, label: str, *values, panel: str | None = None) -> None:
    """Give widget ``label`` one value per frame (with the Export or Help header open if
    needed); it must have been drawn."""
    for value in values:
        if panel is not None:
            viewer.set_panel(panel)
        viewer.ui.script(label, value)
        if label in EXPORT_WIDGETS:
            viewer.ui.script("Export", True)
        if label in HELP_WIDGETS and HELP_HEADER not in viewer.ui.pending():
            viewer.ui.script(HELP_HEADER, True)  # (unless the test opened it for this frame)
        frames(viewer)
        assert not viewer.ui.pending(), f"widget {label!r} was not drawn"


def wait_for_basis(viewer: Viewer) -> None:
    st = viewer.panels["spectral"].state
    t0 = time.monotonic()
    while st.busy:
        assert time.monotonic() - t0 < 300, "the eigen worker never finished"
        time.sleep(0.02)
    frames(viewer, 2)  # the panel adopts the finished basis


def compute_basis(viewer, k: int = 12) -> None:
    """A ``k``-mode eigenbasis through the Spectral view's widgets, waited for and adopted."""
    viewer.set_panel("spectral")
    drive(viewer, "modes to compute", k)
    drive(viewer, "compute eigenbasis", True)
    st = viewer.panels["spectral"].state
    t0 = time.monotonic()
    while st.busy:
        assert time.monotonic() - t0 < 300
        time.sleep(0.02)
    frames(viewer, 2)
    assert st.basis is not None


def settle(viewer, owner: str = "diffusion") -> None:
    """Wait for the panel's jobs (worker threads when ``viewer.background``) and let the host
    apply them (an applied job may start the next one)."""
    t0 = time.monotonic()
    while viewer.state.jobs.running(owner) is not None:
        assert time.monotonic() - t0 < 120, "the diffusion job never finished"
        viewer.state.jobs.wait(owner, 1.0)
        frames(viewer, 1)
    frames(viewer, 2)


def settle_jobs(viewer) -> None:
    """Let every job finish and be applied."""
    for _ in range(200):
        frames(viewer)
        if not viewer.state.jobs.busy:
            break
        viewer.state.jobs.wait(timeout=5)
    frames(viewer, 3)


def sphere_file(folder: Path) -> Path:
    """An icosphere (level 2) written to ``folder`` (the ``sphere`` fixture's mesh)."""
    path = folder / "sphere.obj"
    if not path.is_file():
        save_mesh(path, *primitives.icosphere(2))
    return path


class FakeClock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t
