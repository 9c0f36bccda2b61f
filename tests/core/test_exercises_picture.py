"""The notebook picture of a check result (``_repr_png_``): the difference map drawn on the
failing mesh by polyscope's EGL snapshot renderer, or by matplotlib with the reason said when
EGL cannot render."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

from meshlap_core.exercises import check_file
from meshlap_core.exercises.meshes import case_named

PNG = b"\x89PNG\r\n\x1a\n"
TWO_VERTICES_WRONG = '''
import numpy as np


def barycentric_areas(V, F):
    """Right (a third of each face), then, on a mesh of more than 1000 vertices, wrong at the
    highest and the lowest vertex (the checker skips the big meshes once a task has failed on
    a small one: wrong only on big ones, it fails on the 2562-vertex sphere)."""
    P = V[F]
    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    a = np.bincount(F.ravel(), np.repeat(A / 3.0, 3), minlength=len(V))
    if len(V) > 1000:
        wrong = [int(np.argmax(V[:, 2])), int(np.argmin(V[:, 2]))]
        a[wrong] += 0.5 * a.max()
    return a
'''


@pytest.fixture(scope="module")
def two_wrong(tmp_path_factory):
    """A check whose mistake is at two vertices of each big mesh only."""
    path = tmp_path_factory.mktemp("student") / "two_wrong.py"
    path.write_text(TWO_VERTICES_WRONG)
    return check_file(path, ["barycentric_areas"])


def _rgb(png: bytes) -> np.ndarray:
    from PIL import Image

    assert png[:8] == PNG
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)


def _red(img: np.ndarray) -> np.ndarray:
    """Towards coolwarm's positive end (red over blue), not the grey of a zero difference
    (the shaded sphere has red ≈ blue)."""
    return (img[..., 0] - img[..., 2] > 40) & (img[..., 0] > 120)


def test_the_map_is_on_the_largest_failing_mesh(two_wrong):
    t = two_wrong.tasks[0]
    assert t.status == "failed"
    V, _F, d, name, signed = t.picture
    assert name == "large" and signed and len(V) == len(case_named("large").V)
    hit = np.flatnonzero(np.abs(d) > 1e-6 * np.abs(d).max())  # round-off elsewhere
    assert sorted(hit) == sorted({int(np.argmax(V[:, 2])), int(np.argmin(V[:, 2]))})
    assert (d[hit] > 0).all()  # student − reference: too large there


@pytest.mark.egl
def test_the_picture_is_drawn_by_egl_where_the_mistake_is(two_wrong):
    """Rendered by EGL: the mesh half of the picture is red only around the wrong vertex that
    faces the camera (a small patch), the rest of the sphere at the colour of 0."""
    pic = two_wrong.picture()
    assert pic.renderer == "egl" and pic.reason == ""
    assert two_wrong._repr_png_()[:8] == PNG
    img = _rgb(pic.png)
    right = img[:, img.shape[1] // 2 :]
    red = _red(right)
    assert red.sum() > 5  # the wrong vertex's neighbourhood
    ys, xs = np.nonzero(red)
    mesh = (right.sum(axis=2) < 3 * 245) & ~red  # drawn, not the white background
    _, mx = np.nonzero(mesh)
    assert mesh.sum() > 50 * red.sum()  # a patch, not the sphere
    width = mx.max() - mx.min()
    assert xs.max() - xs.min() < 0.25 * width and ys.max() - ys.min() < 0.25 * width
    left = _red(img[:, : img.shape[1] // 2])
    assert left.sum() > 1000  # the failed task's cell


def _egl_process_fails(*args, progress=None) -> None:
    """Stands in for the EGL child's body: its process ends with exit code 1 (as one whose
    EGL start-up aborted)."""
    import os

    os._exit(1)


def test_without_egl_the_picture_falls_back_to_matplotlib_and_says_why(two_wrong, monkeypatch):
    """EGL's process failing (here it ends with exit code 1 before drawing): matplotlib draws
    the map, and the picture says why; ``renderer="egl"`` raises instead."""
    screenshots = pytest.importorskip("meshlap_app.screenshots")
    monkeypatch.setattr(screenshots, "render_difference", _egl_process_fails)
    pic = two_wrong.picture()
    assert pic.renderer == "matplotlib"
    assert "EGL backend did not render" in pic.reason and "exit code 1" in pic.reason
    assert _red(_rgb(pic.png)).sum() > 1000
    with pytest.raises(RuntimeError, match="did not render"):
        two_wrong.picture("egl")


def test_without_the_viewer_the_picture_says_so(two_wrong, monkeypatch):
    import importlib.metadata

    real = importlib.metadata.entry_points
    monkeypatch.setattr(
        importlib.metadata,
        "entry_points",
        lambda **kw: [] if kw.get("group") == "meshlap.check_picture" else real(**kw),
    )
    pic = two_wrong.picture()
    assert pic.renderer == "matplotlib" and "not installed" in pic.reason


def test_a_passing_result_has_no_map(tmp_path):
    path = Path(__file__).parents[1] / "exercises" / "right_vectorized.py"
    pic = check_file(path, ["one_ring"]).picture()
    assert pic.renderer == "none" and pic.reason == "" and pic.png[:8] == PNG
