"""The Check view's widgets: the student file, the task, *check*, the vertex and its rows."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.support.drivers.isolines import drive_check_isolines
from tests.support.students import STUDENTS
from tests.support.widgets import drive, settle_jobs


def drive_panel_check(viewer, tmp_path: Path) -> None:
    """Every Check widget with good and bad values (also run by the every-widget tour)."""
    viewer.set_panel("check")
    st = viewer.panels["check"].state
    drive(viewer, "check", True)  # nothing typed: said in red, nothing checked
    assert "student file" in viewer.state.errors["check"] and st.check is None
    drive(viewer, "student file", str(STUDENTS / "wrong_cotan_full.py"))
    for bad in ("eigenbase", "nonsense"):
        drive(viewer, "task", bad)
        assert st.task == "cotan_laplacian" and "check" in viewer.state.errors
    drive(viewer, "task", "cotan_laplacian")
    drive(viewer, "check", True)
    assert st.check is not None and st.check.result.tasks[0].diagnosis == "cot_not_half"
    assert "check" not in viewer.state.errors
    drive(viewer, "vertex", 5)
    table = viewer.ui.tables[("check", "check rows")]
    assert table.headers == ["term", "student", "reference"]
    assert table.rows and all(
        float(s) == pytest.approx(2 * float(r), rel=1e-5) for _, s, r in table.rows
    )
    for bad in (-2, 10**6):
        drive(viewer, "vertex", bad)
        assert st.vertex == 5 and "out of range" in viewer.state.errors["check"]
    drive(viewer, "vertex", 6)
    drive_check_isolines(viewer)
    # the eigenbasis on the mesh on screen: its rows are λ_j and u_j[i], the map is shown
    drive(viewer, "student file", str(STUDENTS / "wrong_spectral.py"))
    drive(viewer, "task", "eigenbasis")
    drive(viewer, "check", True)
    assert st.check.result.tasks[0].diagnosis == "ordinary_eigenproblem"
    drive(viewer, "vertex", 3)
    rows = viewer.ui.tables[("check", "check rows")].rows
    assert [r[0] for r in rows[:2]] == ["λ0", "u0[3]"] and len(rows) == 12
    assert st.check.difference is not None and st.check.difference.max() > 0
    # a crashing student file: reported, the viewer and the last good map stay
    drive(viewer, "student file", str(STUDENTS / "hostile_crash.py"))
    drive(viewer, "task", "uniform_laplacian")
    drive(viewer, "check", True)
    assert st.check.result.tasks[0].status == "crashed"
    assert st.verdict()[0].split()[-1] == "CRASHED"


# ------------------------------------------------------------------ shown for the export test
STUDENTS_FOR_EXPORT = Path(__file__).resolve().parents[2] / "exercises"


def show_for_export(viewer, tmp_path: Path) -> Any:
    """What the view shows for the export test (``tests/app/test_export_views.py``): its
    fields and copies; a generator yields once per state to export."""
    drive(viewer, "student file", str(STUDENTS_FOR_EXPORT / "wrong_cotan_full.py"))
    drive(viewer, "task", "cotan_laplacian")
    drive(viewer, "check", True)
    settle_jobs(viewer)
    assert viewer.panels["check"].state.check.difference is not None
