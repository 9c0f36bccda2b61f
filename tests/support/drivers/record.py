"""The widgets every playing panel shares: play what, play / pause, the section's θ and turn,
and the *record* header (file, record, stop)."""

from __future__ import annotations

import polyscope as ps
from meshlap_app.record import RECORD_HEADER
from PIL import Image

RECORD_WIDGETS = ("record file", "record", "stop")


def tick(viewer, label: str | None = None, value=None) -> None:
    """One frame; ``label`` gets ``value`` (the record header is opened for its widgets)."""
    if label is not None:
        viewer.ui.script(label, value)
        if label in RECORD_WIDGETS:
            viewer.ui.script(RECORD_HEADER, True)
    ps.frame_tick()
    assert not viewer.ui.pending(), f"widget {label!r} was not drawn"
    internal = {k: m for k, m in viewer.state.errors.items() if "internal error" in m}
    assert not internal, internal


def basis(viewer, k: int) -> None:
    st = viewer.panels["spectral"].state
    st.k_request = k
    st.start(viewer.state.mesh.V, viewer.state.mesh.F, background=False)
    tick(viewer)


class Clock:
    """A clock the test moves (seconds)."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def drive_record_widgets(viewer, tmp_path) -> None:
    """Good and bad values for the play, θ and record widgets; ``test_every_widget_is_driven``
    in ``tests/app/test_viewer_widgets.py`` runs this too."""
    viewer.set_panel("spectral")
    basis(viewer, 8)
    st = viewer.panels["spectral"].state
    tick(viewer, "play what", "nonsense")
    assert "nonsense" in viewer.state.errors["spectral"]
    tick(viewer, "play what", "modes")
    st.clock = Clock()
    tick(viewer, "play", True)
    tick(viewer, "pause", True)
    tick(viewer, "play what", "k sweep")
    for panel in ("spectral", "smoothing"):  # each panel that plays has its record header
        viewer.set_panel(panel)
        tick(viewer)
        tick(viewer, "record file", str(tmp_path / f"{panel}.gif"))
        tick(viewer, "record", True)
        tick(viewer, "stop", True)
        assert (tmp_path / f"{panel}.gif").is_file()
    viewer.set_panel("surfaces")
    tick(viewer)
    tick(viewer, "section theta", 30.0)
    tick(viewer, "section theta", "nan")
    assert (
        viewer.panels["surfaces"].state.section_deg == 30.0
        and "theta" in viewer.state.errors["surfaces"]
    )
    tick(viewer, "turn", True)
    tick(viewer, "pause turn", True)
    assert not viewer.panels["surfaces"].state.turning
    tick(viewer, "record file", "bad.avi")
    tick(viewer, "record", True)
    assert ".avi" in viewer.state.errors["surfaces"]
    tick(viewer, "record file", str(tmp_path / "tour.gif"))
    tick(viewer, "record", True)
    tick(viewer, "section theta", 60.0)
    tick(viewer, "stop", True)
    assert Image.open(tmp_path / "tour.gif").n_frames == 2
