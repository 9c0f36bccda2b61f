"""The mesh's up axis: the display rotation, the rule (given, then known meshes, then y), ``view
--up`` and the session's ``up``, and a z-up mesh seen from the side through the viewer on
``openGL_mock`` (the Nefertiti bust upright, facing the camera, when the shared meshes are here)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from meshlap_app.state.app import AppState
from meshlap_app.state.display import UP_BY_MESH, Display, up_rotation
from meshlap_app.state.session import Session, from_dict, write_session

from meshlap_core.errors import MeshError
from meshlap_core.io import save_mesh
from meshlap_core.options import DEFAULT_UP, UP_AXES
from meshlap_core.primitives import icosphere

NEFERTITI = Path(__file__).resolve().parents[3] / "shared" / "meshes" / "nefertiti.obj"


@pytest.mark.parametrize("up", UP_AXES)
def test_the_up_rotation_is_a_rotation_taking_the_axis_to_display_y(up):
    R = up_rotation(up)
    assert np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) == pytest.approx(1.0)
    e = np.zeros(3)
    e["xyz".index(up[-1])] = -1.0 if up.startswith("-") else 1.0
    assert np.allclose(R @ e, [0.0, 1.0, 0.0])


def test_z_up_by_hand_and_the_display_of_a_tall_box():
    # a quarter turn about x: (x, y, z) -> (x, z, -y)
    assert np.allclose(up_rotation("z") @ [1.0, 2.0, 3.0], [1.0, 3.0, -2.0])
    assert np.allclose(up_rotation("y"), np.eye(3))
    d = Display()
    box = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 5)], dtype=float)
    d.fit(box, "z")
    P = d.points(box)
    assert np.argmax(np.ptp(P, axis=0)) == 1  # the box's tall z side stands up on screen
    assert np.allclose(d.vectors(np.array([[0.0, 0.0, 1.0]])), [[0.0, d.scale, 0.0]])
    with pytest.raises(MeshError, match="unknown up axis 'w'"):
        d.fit(box, "w")


def test_the_up_rule_given_then_known_meshes_then_y():
    state = AppState()
    assert state.up_for("bumpy.obj") == DEFAULT_UP == "y"
    assert state.up_for("nefertiti.obj") == UP_BY_MESH["nefertiti.obj"] == "z"
    state.up_given["bumpy.obj"] = "-x"
    assert state.up_for("bumpy.obj") == "-x"


def test_view_up_is_refused_unknown_and_with_a_session(tmp_path, capsys):
    from meshlap_core.cli import main

    with pytest.raises(SystemExit) as exit_:
        main(["view", "--up", "w"])
    assert exit_.value.code == 2 and "invalid choice: 'w'" in capsys.readouterr().err
    write_session(tmp_path / "s.json", Session())
    assert main(["view", "--session", str(tmp_path / "s.json"), "--up", "z"]) == 2
    assert "--up cannot be combined with --session" in capsys.readouterr().err


def test_the_session_keeps_a_given_up_and_refuses_a_bad_one(tmp_path):
    s = Session(up="z")
    data = s.to_dict()
    assert data["up"] == "z" and from_dict(data).up == "z"
    assert "up" not in Session().to_dict()  # the rule's: not written (older readers)
    assert from_dict(Session().to_dict()).up is None
    with pytest.raises(MeshError, match='"up" must be one of'):
        from_dict({**data, "up": "w"})


ps = pytest.importorskip("polyscope")


def eye_direction_in_mesh_axes(viewer) -> np.ndarray:
    """The unit direction from the mesh's centre to the camera, in the mesh's own axes."""
    d = viewer.state.display
    eye = np.asarray(ps.get_view_camera_parameters().get_position(), dtype=float)
    centre = d.points(viewer.state.mesh.V).mean(axis=0)
    v = d.rotation.T @ (eye - centre)
    return v / np.linalg.norm(v)


def test_a_z_up_mesh_is_seen_from_the_side_saved_and_restored(mock, viewer, tmp_path):
    from meshlap_app.session import capture

    tall = tmp_path / "tall.obj"
    V, F = icosphere(2)
    save_mesh(tall, V * [1.0, 1.0, 3.0], F)
    viewer.state.up_given["tall.obj"] = "z"
    assert viewer.open(tall)
    ps.frame_tick()
    assert viewer.state.display.up == "z"
    v = eye_direction_in_mesh_axes(viewer)
    assert abs(v[2]) < 0.3  # looked at from the side (y-up, the eye was on its z axis)
    P = viewer.state.display.points(viewer.state.mesh.V)
    assert np.argmax(np.ptp(P, axis=0)) == 1  # standing: its long z axis is up on screen
    assert capture(viewer).up == "z"
    viewer.state.up_given.clear()
    assert viewer.open(tall)
    assert viewer.state.display.up == "y" and capture(viewer).up is None


def test_nefertiti_stands_upright_facing_the_camera(mock, viewer):
    if not NEFERTITI.exists():
        pytest.skip(f"{NEFERTITI} is absent (the shared meshes)")
    assert viewer.open(NEFERTITI)
    ps.frame_tick()
    V = viewer.state.mesh.V
    z = V[:, 2]
    lo, hi = z.min(), z.max()
    # the bust is z-up: its crown leans back, so the face is on the side the crown leans from
    crown = V[z > hi - 0.2 * (hi - lo), 1].mean()
    base = V[z < lo + 0.2 * (hi - lo), 1].mean()
    face = np.array([0.0, -np.sign(crown - base), 0.0])
    v = eye_direction_in_mesh_axes(viewer)
    assert abs(v[2]) < 0.3, v  # not from below (the base) nor from above
    assert v @ face > 0.9, v  # in front of the face
