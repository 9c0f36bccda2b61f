"""Texture coordinates in the OBJ writer (``save_mesh(..., uv=, uv_faces=)``): ``vt`` lines and
``f v/vt`` corners, read back by hand and by libigl, and every bad argument refused by name."""

from __future__ import annotations

import igl
import numpy as np
import pytest

from meshlap_core.errors import MeshError
from meshlap_core.io import load_mesh, save_mesh

V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
F = np.array([[0, 1, 2], [0, 2, 3]])
UV = np.array([[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5], [1.0, 1.0]])
FT = np.array([[0, 1, 2], [4, 2, 3]])  # vertex 0 has two texture coordinates: a seam


def read_obj_texture(path):
    """``(vt (t,2), f (m,3,2))`` parsed by hand: ``vt`` values and ``v/vt`` pairs (1-based)."""
    vt, faces = [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "vt":
            vt.append([float(x) for x in parts[1:]])
        elif parts and parts[0] == "f":
            faces.append([[int(i) for i in c.split("/")] for c in parts[1:]])
    return np.array(vt), np.array(faces)


def test_uv_with_seams_round_trips(tmp_path):
    path = tmp_path / "square.obj"
    save_mesh(path, V, F, uv=UV, uv_faces=FT)
    vt, faces = read_obj_texture(path)
    np.testing.assert_array_equal(vt, UV)  # 17 digits: exact
    np.testing.assert_array_equal(faces[:, :, 0] - 1, F)
    np.testing.assert_array_equal(faces[:, :, 1] - 1, FT)
    mesh = load_mesh(path)  # the loader reads v/vt corners
    np.testing.assert_array_equal(mesh.V, V)
    np.testing.assert_array_equal(mesh.F, F)
    _, TC, _, Fi, FTC, _ = igl.readOBJ(str(path))
    np.testing.assert_allclose(TC, UV)
    np.testing.assert_array_equal(FTC, FT)
    np.testing.assert_array_equal(Fi, F)


def test_one_uv_per_vertex_by_default(tmp_path):
    path = tmp_path / "square.obj"
    save_mesh(path, V, F, uv=UV[:4])
    vt, faces = read_obj_texture(path)
    np.testing.assert_array_equal(vt, UV[:4])
    np.testing.assert_array_equal(faces[:, :, 1], faces[:, :, 0])


@pytest.mark.parametrize(
    "name, kwargs, source, words",
    [
        ("out.ply", {"uv": UV[:4]}, "out.ply", "only .obj"),
        ("out.off", {"uv": UV[:4]}, "out.off", "only .obj"),
        ("out.obj", {"uv_faces": FT}, "uv", "without uv"),
        ("out.obj", {"uv": UV[:, :1]}, "uv", "shape"),
        ("out.obj", {"uv": UV.T}, "uv", "shape"),
        ("out.obj", {"uv": np.where(UV > 0.7, np.nan, UV)}, "uv", "nan"),
        ("out.obj", {"uv": UV > 0}, "uv", "boolean"),
        ("out.obj", {"uv": UV.astype(str)}, "uv", "numbers"),
        ("out.obj", {"uv": UV[:3]}, "uv", "uv_faces"),
        ("out.obj", {"uv": UV, "uv_faces": FT + 5}, "uv_faces", "5 vertices"),
        ("out.obj", {"uv": UV, "uv_faces": FT[:1]}, "uv_faces", "shape"),
        ("out.obj", {"uv": UV, "uv_faces": FT + 0.5}, "uv_faces", "integers"),
    ],
)
def test_bad_texture_arguments_are_refused_by_name(tmp_path, name, kwargs, source, words):
    path = tmp_path / name
    path.write_text("keep")
    with pytest.raises(MeshError) as info:
        save_mesh(path, V, F, **kwargs)
    assert str(info.value.source).endswith(source)
    assert words in str(info.value).lower()
    assert path.read_text() == "keep"  # nothing written
