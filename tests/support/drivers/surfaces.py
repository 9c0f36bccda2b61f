"""The Surfaces view's widgets: the surface, its resolution and the point (u, v)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import polyscope as ps

from tests.support.widgets import drive, frames


def drive_surfaces_widgets(viewer):
    viewer.set_panel("surfaces")
    s = viewer.panels["surfaces"].state
    frames(viewer)
    drive(viewer, "surface", "torus")
    assert s.name == "torus" and ps.has_surface_mesh("surface")
    drive(viewer, "resolution", 24)
    assert s.res == 24 and s.mesh is not None
    for bad in (0, -3, 2, 10**6, "", "nan", "1e309"):
        drive(viewer, "resolution", bad)
        assert s.res == 24 and viewer.state.errors["surfaces"]
    drive(viewer, "u", 1.0)
    drive(viewer, "v", 0.5)
    assert (s.u, s.v) == (1.0, 0.5)
    _, u1, _, _ = s.domain
    drive(viewer, "u", u1 + 10.0)  # out of range: clamped into the domain
    assert s.u == u1
    for bad in ("nan", "1e309"):
        drive(viewer, "v", bad)
        assert s.v == 0.5
    drive_signs(viewer)


def drive_signs(viewer) -> None:
    """The sign of II: do Carmo's (the course's) re-evaluates the point with it, a bad value
    is refused (the sign stays), meshlap's comes back."""
    s = viewer.panels["surfaces"].state
    k1 = s.point.k1
    drive(viewer, "signs", "do-carmo")
    assert s.signs == "do-carmo" and s.point.signs == "do-carmo"
    assert s.point.k2 == -k1  # II negated: k1 and k2 swap and change sign
    drive(viewer, "signs", "nonsense")
    assert s.signs == "do-carmo" and "signs" in viewer.state.errors["surfaces"]
    drive(viewer, "signs", "outward")
    assert s.signs == "outward" and s.point.k1 == k1


def drive_panel_surfaces(viewer, tmp_path: Path) -> None:
    drive_surfaces_widgets(viewer)


# ------------------------------------------------------------------ shown for the export test
def show_for_export(viewer, tmp_path: Path) -> Any:
    """What the view shows for the export test (``tests/app/test_export_views.py``): its
    fields and copies; a generator yields once per state to export."""
    drive(viewer, "surface", "torus")
