"""The Smoothing view's widgets: method, Laplacian, noise, λ typed, play, pause, reset."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from tests.support.widgets import BAD_NUMBERS, drive, frames


def drive_smoothing_lambda_typed_keeps_the_mesh(viewer):
    """The crash of issue 13: typing ``0.5`` passes through ``0``; nothing may end the session."""
    viewer.set_panel("smoothing")
    st = viewer.panels["smoothing"].state
    frames(viewer)
    drive(viewer, "noise alpha", 0.01)
    drive(viewer, "step", True, True, True)
    smoother, V = st.smoother, np.array(st.V)
    assert smoother.iteration == 3
    for bad in BAD_NUMBERS:
        drive(viewer, "lambda", bad)
        assert st.lam == 0.5 and "lambda" in viewer.state.errors["smoothing"]
    drive(viewer, "lambda", "0.25")
    assert st.lam == 0.25 and "smoothing" not in viewer.state.errors
    # a λ edit keeps the current mesh, its noise and the iteration count (set_lam only)
    assert st.smoother is smoother and smoother.lam == 0.25 and smoother.iteration == 3
    np.testing.assert_array_equal(st.V, V)


def drive_smoothing_widgets(viewer):
    viewer.set_panel("smoothing")
    st = viewer.panels["smoothing"].state
    frames(viewer)
    for method in ("explicit", "taubin", "implicit"):
        drive(viewer, "method", method)
        assert st.smoother.method == method
    drive(viewer, "Laplacian", "cotan")
    assert st.smoother.laplacian == "cotan"
    drive(viewer, "noise alpha", 0.02)
    assert st.noise_alpha == 0.02
    start = np.array(st.V_start)
    for bad in ("nan", "1e309", -0.5):
        drive(viewer, "noise alpha", bad)
        assert st.noise_alpha == 0.02 and "alpha" in viewer.state.errors["smoothing"]
        np.testing.assert_array_equal(st.V_start, start)
    drive(viewer, "noise seed", 3)
    assert st.seed == 3
    for bad in (-1, "", "1e309", "abc"):
        drive(viewer, "noise seed", bad)
        assert st.seed == 3
    drive(viewer, "play", True)
    assert st.playing
    frames(viewer, 3)
    drive(viewer, "pause", True)
    assert not st.playing and st.smoother.iteration >= 3
    shown = st.smoother.iteration
    drive(viewer, "back", True)  # one step back through the kept positions
    assert st.smoother.iteration == shown - 1
    drive(viewer, "reset", True)
    assert st.smoother.iteration == 0


def drive_panel_smoothing(viewer, tmp_path: Path) -> None:
    drive_smoothing_widgets(viewer)
    drive_smoothing_lambda_typed_keeps_the_mesh(viewer)


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path: Path) -> Any:
    """What the view shows for the export test (``tests/app/test_export_views.py``): its
    fields and copies; a generator yields once per state to export."""
    drive(viewer, "noise alpha", 0.01)
    drive(viewer, "step", True, True)
