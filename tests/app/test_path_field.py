"""The Mesh section's path field: a session file typed there opens the session and the field
empties; a mesh opens the same way; a missing file is refused under the field, kept in it."""

from __future__ import annotations

import pytest

ps = pytest.importorskip("polyscope")


from tests.support.widgets import drive  # noqa: E402


def test_path_field_opens_a_session_and_empties(viewer, tmp_path, sphere):
    from meshlap_app.state.session import Session, write_session

    path = write_session(tmp_path / "s.json", Session(mesh=sphere, panel="smoothing"))
    viewer.set_panel("curvature")
    drive(viewer, "path", str(path))
    assert viewer.state.panel == "smoothing" and "mesh_info" not in viewer.state.errors
    assert viewer.panels["mesh_info"].path_text == ""
    drive(viewer, "path", str(sphere))
    assert viewer.panels["mesh_info"].path_text == ""  # not the old path any more
    drive(viewer, "path", str(tmp_path / "missing.json"))
    assert viewer.state.errors["mesh_info"]  # refused, said under the field
    assert viewer.panels["mesh_info"].path_text.endswith("missing.json")
