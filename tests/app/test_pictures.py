"""Pictures in notebooks (``meshlap_core.show``, ``show_side_by_side``, ``turntable``,
``open_viewer``): every argument checked with an error naming it; the viewer's scene on
``openGL_mock`` (what is registered); its pixels on EGL (the colour map's colours, the colour
bars, the one-ring, the crosses); the matplotlib fallback saying why."""

from __future__ import annotations

import io

import numpy as np
import pytest

import meshlap_core as ml
from meshlap_core.errors import MeshError
from meshlap_core.pictures import picture as picture_module
from meshlap_core.pictures import scene as sc
from meshlap_core.pictures import window

V2, F2 = ml.icosphere(2)  # 162 vertices
N = len(V2)


def _grid():
    """A flat unit square in the plane z = 0, facing the default camera (from −z)."""
    return ml.grid(16, 16)


# ---------------------------------------------------------------------- input validation
def _bad_field(k: int, value: float) -> np.ndarray:
    f = V2[:, 0].copy()
    f[k] = value
    return f


def _bad_vectors() -> np.ndarray:
    v = V2.copy()
    v[2, 1] = np.inf
    return v


BAD_CALLS = [
    # (call, argument named, words of the message)
    (lambda: ml.show(V2), "F", "faces are missing"),
    (lambda: ml.show(V2[:, :2], F2), "V", "shape (n,3)"),
    (lambda: ml.show(np.where(np.arange(N)[:, None] == 3, np.nan, V2), F2), "V", "vertex 3"),
    (lambda: ml.show(V2.astype(complex), F2), "V", "real numbers"),
    (lambda: ml.show(V2, F2 + 0.5), "F", "integers"),
    (lambda: ml.show(V2, F2 + N), "F", f"the mesh has {N} vertices"),
    (lambda: ml.show(V2, F2[:0]), "F", "no face"),
    (lambda: ml.show(ml.load_mesh, F2), "V", "vertex coordinates"),
    (lambda: ml.show(V2, F2, V2[:-1, 0]), "field", f"shape ({N},)"),
    (lambda: ml.show(V2, F2, V2), "field", f"shape ({N},)"),
    (lambda: ml.show(V2, F2, _bad_field(5, np.nan)), "field", "first at vertex 5"),
    (lambda: ml.show(V2, F2, _bad_field(7, -np.inf)), "field", "first at vertex 7"),
    (lambda: ml.show(V2, F2, V2[:, 0] > 0), "field", "boolean"),
    (lambda: ml.show(V2, F2, np.array(["a"] * N)), "field", "numbers"),
    (lambda: ml.show(V2, F2, "mean"), "field", "cotan"),
    (lambda: ml.show(V2, F2, vertex=N), "vertex", f"out of range (the mesh has {N}"),
    (lambda: ml.show(V2, F2, vertex=-1), "vertex", "out of range"),
    (lambda: ml.show(V2, F2, vertex=1.5), "vertex", "integer"),
    (lambda: ml.show(V2, F2, vertex=True), "vertex", "integer"),
    (lambda: ml.show(V2, F2, vertex="0"), "vertex", "integer"),
    (lambda: ml.show(V2, F2, vectors=V2[:, :2]), "vectors", f"shape ({N}, 3)"),
    (lambda: ml.show(V2, F2, vectors=_bad_vectors()), "vectors", "vector 2"),
    (lambda: ml.show(V2, F2, camera=(0, 1, 0)), "camera", "up axis"),
    (lambda: ml.show(V2, F2, camera=(0, 0, 0)), "camera", "zero"),
    (lambda: ml.show(V2, F2, camera=(0, 1)), "camera", "direction"),
    (lambda: ml.show(V2, F2, camera=("a", "b", "c")), "camera", "numbers"),
    (lambda: ml.show(V2, F2, camera=(0, np.nan, 1)), "camera", "finite"),
    (lambda: ml.show(V2, F2, size=(10, 600)), "size", "64 to 4096"),
    (lambda: ml.show(V2, F2, size="big"), "size", "(width, height)"),
    (lambda: ml.show(V2, F2, size=(800.5, 600)), "size", "64 to 4096"),
    (lambda: ml.show(V2, F2, V2[:, 0], isolines=-1), "isolines", "0 to 200"),
    (lambda: ml.show(V2, F2, V2[:, 0], isolines=2.5), "isolines", "integer"),
    (lambda: ml.show(V2, F2, V2[:, 0], cmap="jet"), "cmap", "coolwarm"),
    (lambda: ml.show(V2, F2, V2[:, 0], clip=60), "clip", "percentage"),
    (lambda: ml.show(V2, F2, up="w"), "up", "up axis"),
    (lambda: ml.show(V2, F2, renderer="vulkan"), "renderer", "egl"),
    (lambda: ml.show(V2, F2, renderer=None), "renderer", "egl"),
    (lambda: ml.show_side_by_side(V2, F2, V2[:, 0], V2[:-1, 0]), "right field", f"({N},)"),
    (lambda: ml.show_side_by_side(V2, F2, other=V2[:, :2]), "V", "shape (n,3)"),
    (lambda: ml.turntable(V2, F2, frames=1), "frames", "2 to 120"),
    (lambda: ml.turntable(V2, F2, fps=0), "fps", "0.1 and 120"),
    (lambda: ml.turntable(V2, F2, degrees=np.nan), "degrees", "finite"),
    (lambda: ml.open_viewer(V2, F2, vertex=N), "vertex", "out of range"),
    (lambda: ml.open_viewer(V2, F2, field="mean"), "field", "cotan"),
]


@pytest.mark.parametrize(("call", "name", "words"), BAD_CALLS)
def test_bad_input_is_refused_naming_the_argument(call, name, words):
    with pytest.raises(MeshError) as info:
        call()
    assert str(info.value).startswith(f"{name}: "), str(info.value)
    assert words in str(info.value)


def test_a_mesh_object_names_the_picture_and_refuses_faces_beside_it():
    mesh = ml.validate_mesh(V2, F2, "shapes/ball.obj")
    assert sc.subject(mesh)[2] == "ball.obj"  # the window's up axis and front view by name
    assert sc.subject((V2, F2))[2] == "mesh"
    with pytest.raises(MeshError, match=r"^F: give F only with a vertex array"):
        ml.show(mesh, F2)


def test_inputs_are_not_modified():
    V, F = ml.icosphere(1)
    f = V[:, 2].copy()
    vec = np.cross(V, [0.0, 0.0, 1.0])
    before = (V.copy(), F.copy(), f.copy(), vec.copy())
    ml.show(V, F, f, vectors=vec, isolines=4, renderer="matplotlib", size=(96, 72))
    ml.show_side_by_side(V, F, f, -f, other=V * 2, renderer="matplotlib", size=(96, 72))
    for now, then in zip((V, F, f, vec), before, strict=True):
        np.testing.assert_array_equal(now, then)


# ---------------------------------------------------------------------- the colour range
def test_colour_range_by_hand():
    assert sc.colour_range(np.array([-1.0, 0.0, 3.0]), signed=True, clip=0) == (-3.0, 3.0)
    assert sc.colour_range(np.array([1.0, 2.0, 3.0]), signed=False, clip=0) == (1.0, 3.0)
    lo, hi = sc.colour_range(np.array([2.0, 2.0]), signed=False)
    assert lo < 2.0 < hi  # a constant field still has a range
    assert sc.colour_range(np.zeros(4), signed=True) == (-1.0, 1.0)
    v = np.arange(101, dtype=float)  # 0 … 100: the 2nd and 98th percentiles are 2 and 98
    assert sc.colour_range(v, signed=False) == pytest.approx((2.0, 98.0))


def test_colour_range_is_the_windows_rule():
    """The core's range equals the viewer's curvature view's (its own copy of the rule)."""
    state = pytest.importorskip("meshlap_app.state.curvature")
    rng = np.random.default_rng(3)
    for values in (rng.normal(size=500), rng.exponential(size=500), rng.normal(size=7) - 9):
        for signed in (True, False):
            for clip in (0.0, 2.0, 10.0):
                ours = sc.colour_range(values, signed, clip)
                assert ours == pytest.approx(state.robust_range(values, signed, clip))


def test_the_fallback_stands_a_mesh_up_as_the_window_does():
    """The fallback's copy of the window's up rule gives the same rotation for every axis."""
    display = pytest.importorskip("meshlap_app.state.display")
    from meshlap_core.options import UP_AXES
    from meshlap_core.pictures import fallback

    for up in UP_AXES:
        np.testing.assert_array_equal(fallback.up_rotation(up), display.up_rotation(up))


def test_the_map_follows_the_sign_and_a_curvature_name_uses_the_windows_field():
    V, F = ml.icosphere(2)
    p = sc.pane(V, F, V[:, 0], label=None, cmap=None, clip=2, isolines=0, vectors=None)
    assert p["cmap"] == "coolwarm" and p["range"][0] == -p["range"][1]
    p = sc.pane(V, F, V[:, 0] + 2, label="x", cmap=None, clip=2, isolines=0, vectors=None)
    assert p["cmap"] == "viridis" and p["range"][0] > 0 and p["label"] == "x"
    p = sc.pane(V, F, "gaussian", label=None, cmap=None, clip=0, isolines=3, vectors=None)
    np.testing.assert_allclose(p["field"], ml.curvature_field(V, F, "gaussian"))
    assert p["cmap"] == "coolwarm" and p["label"].startswith("Gaussian curvature")
    assert p["isolines"] == 3


# ---------------------------------------------------------------------- images
def _rgb(png: bytes) -> np.ndarray:
    from PIL import Image

    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)


def _nearest_t(pixels: np.ndarray, cmap: str) -> tuple[np.ndarray, np.ndarray]:
    """For each RGB pixel, the colour map's nearest parameter t in [0, 1] and the distance."""
    from matplotlib import colormaps

    samples = colormaps[cmap](np.linspace(0, 1, 256))[:, :3] * 255
    d = np.linalg.norm(pixels[:, None, :] - samples[None, :, :], axis=2)
    return d.argmin(axis=1) / 255.0, d.min(axis=1)


def _mesh_row_ends(
    img: np.ndarray, x0: int, x1: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Mean colour of the left and right tenth of the mesh along the middle rows, between
    pixel columns ``x0`` and ``x1`` (clear of the colour bars)."""
    h = img.shape[0]
    band = img[h // 2 - 15 : h // 2 + 15, x0:x1].astype(float)
    drawn = band.sum(axis=2) < 3 * 235  # not the white background
    cols = np.flatnonzero(drawn.mean(axis=0) > 0.5)
    assert cols.size > 50, "no mesh in the middle of the picture"
    tenth = max(cols.size // 10, 3)
    return band[:, cols[:tenth]].reshape(-1, 3).mean(0), band[:, cols[-tenth:]].reshape(-1, 3).mean(
        0
    )


def _caption_ink(img: np.ndarray) -> int:
    """Dark pixels in the bottom 6 % of the picture (a caption's text)."""
    bottom = img[int(0.94 * img.shape[0]) :]
    return int((bottom.sum(axis=2) < 3 * 170).sum())


def _colour_bar_fit(img: np.ndarray, x0: int, x1: int, cmap: str) -> tuple[float, np.ndarray]:
    """The column of ``img`` between ``x0`` and ``x1`` whose pixels in rows 45–270 (where
    polyscope draws a colour bar at the top) are nearest the colour map: its mean distance
    to the map and its parameters t from top to bottom."""
    best = (np.inf, np.zeros(0))
    for x in range(x0, x1):
        t, d = _nearest_t(img[45:270, x].astype(float), cmap)
        if d.mean() < best[0]:
            best = (float(d.mean()), t)
    return best


def _is_bar(fit: tuple[float, np.ndarray]) -> bool:
    """A colour bar: near the map, from its top (t ≈ 1) down to its bottom (t ≈ 0)."""
    distance, t = fit
    rows = np.arange(t.size)
    return (
        distance < 30
        and t[:5].mean() > 0.85
        and t[-5:].mean() < 0.15
        and np.corrcoef(rows, t)[0, 1] < -0.95
    )


@pytest.mark.egl
def test_egl_draws_the_colour_maps_colours_and_its_colour_bar():
    V, F = _grid()
    pic = ml.show(V, F, V[:, 0], cmap="viridis", clip=0, renderer="egl", size=(640, 480))
    assert pic.renderer == "egl" and pic.reason == ""
    img = pic.image
    left, right = _mesh_row_ends(img, 160)
    assert left[0] > left[2] + 60 and left[1] > left[2] + 60  # x = 1: viridis' yellow
    assert right[2] > right[1] + 20 and right[0] > right[1]  # x = 0: viridis' purple
    assert _is_bar(_colour_bar_fit(img, 10, 70, "viridis"))
    signed = ml.show(V, F, V[:, 0] - 0.5, renderer="egl", size=(640, 480)).image
    left, right = _mesh_row_ends(signed, 160)
    assert left[0] > left[2] + 60 and right[2] > right[0] + 40  # coolwarm: red, blue
    assert _is_bar(_colour_bar_fit(signed, 10, 70, "coolwarm"))
    plain = ml.show(V, F, renderer="egl", size=(640, 480)).image
    assert not _is_bar(_colour_bar_fit(plain, 10, 70, "viridis"))  # no field, no bar


@pytest.mark.egl
def test_egl_side_by_side_has_a_colour_bar_per_field():
    V, F = ml.icosphere(3)
    pic = ml.show_side_by_side(V, F, V[:, 1], V[:, 1] + 2, titles=("a", "b"), renderer="egl",
                               size=(900, 450))  # fmt: skip
    img = pic.image
    assert _is_bar(_colour_bar_fit(img, 10, 70, "coolwarm"))  # signed, on the left
    assert _is_bar(_colour_bar_fit(img, 900 - 150, 900 - 90, "viridis"))  # one sign, right
    assert _caption_ink(img) > 30  # "left: a | right: b"


@pytest.mark.egl
def test_egl_draws_the_one_ring_and_the_crosses():
    V, F = ml.icosphere(2)
    red = lambda img: int(((img[..., 0] > 170) & (img[..., 1] < 90) & (img[..., 2] < 90)).sum())  # noqa: E731
    ring = ml.show(V, F, vertex=0, renderer="egl", size=(640, 480)).image.astype(int)
    plain = ml.show(V, F, renderer="egl", size=(640, 480)).image.astype(int)
    h, w = ring.shape[:2]
    centre = ring[h // 4 : 3 * h // 4, w // 4 : 3 * w // 4]
    assert red(centre) > 200 and red(plain) == 0  # the selected vertex, drawn red
    Vt, Ft = ml.torus_mesh(40, 16)
    pc = ml.estimate_curvature(Vt, Ft, "rusinkiewicz")
    dark = lambda img: int((img.sum(axis=2) < 200).sum())  # noqa: E731
    with_crosses = ml.show(Vt, Ft, vectors=pc, up="z", renderer="egl").image.astype(int)
    without = ml.show(Vt, Ft, up="z", renderer="egl").image.astype(int)
    assert dark(with_crosses) > dark(without) + 1000  # black k1 crosses at the vertices
    img = with_crosses
    green = (img[..., 1] - img[..., 2] > 50) & (img[..., 1] > 100) & (img[..., 0] < 80)
    assert green.sum() > 150  # the green k2 crosses (K2_COLOR), none on the plain mesh
    img = without
    assert ((img[..., 1] - img[..., 2] > 50) & (img[..., 1] > 100) & (img[..., 0] < 80)).sum() == 0


@pytest.mark.egl
def test_egl_turntable_turns():
    V, F = ml.icosphere(2)
    t = ml.turntable(V, F, V[:, 0], frames=4, size=(400, 300), renderer="egl")
    assert t.renderer == "egl" and len(t.frames) == 4
    assert not np.array_equal(t.frames[0], t.frames[1])
    # half a turn shows the other side: the field's colours are mirrored left to right
    red = [[c[0] - c[2] for c in _mesh_row_ends(t.frames[k], 160)] for k in (0, 2)]
    assert red[0][0] > red[0][1] + 40 and red[1][1] > red[1][0] + 40  # left red, then right


# ---------------------------------------------------------------------- the scene, mocked
def _scene(**kw):
    V, F = ml.icosphere(2)
    panes = [sc.pane(V, F, V[:, 0], label="x", cmap=None, clip=2, isolines=4, vectors=None)]
    if kw.pop("pair", False):
        panes.append(sc.pane(2 * V, F, V[:, 1], label="y", cmap=None, clip=2, isolines=0,
                             vectors=None))  # fmt: skip
    return sc.build_scene(panes, "mesh", **kw)


def test_the_viewer_registers_the_scene_on_the_mock_backend(polyscope_mock):
    pictures = pytest.importorskip("meshlap_app.pictures")
    from meshlap_app.scene import MESH, RING_CENTER, RING_CURVE

    ps = polyscope_mock
    # polyscope's window size and pane width are global: the next module's viewer needs its own
    size, pane = tuple(ps.get_window_size()), ps.get_right_gui_pane_width()
    try:
        _viewer, points = pictures.set_up(_scene(pair=True))
        assert ps.has_surface_mesh(MESH) and ps.has_surface_mesh(pictures.SECOND)
        assert not ps.has_curve_network(RING_CURVE)
        left, right = points
        # seen from −z the second pane is on the screen's right: towards −x, clear of the first
        assert right[:, 0].max() < left[:, 0].min()
        np.testing.assert_allclose(np.ptp(right, axis=0), 2 * np.ptp(left, axis=0))
        pictures.set_up(_scene(vertex=5))
        assert ps.has_curve_network(RING_CURVE) and ps.has_point_cloud(RING_CENTER)
        assert not ps.has_surface_mesh(pictures.SECOND)
        centre = ps.get_point_cloud(RING_CENTER)
        assert centre.n_points() == 1
        frames = pictures.draw(_scene(turns=(0.0, 90.0), size=(160, 120)))
        assert [f.shape for f in frames] == [(120, 160, 4)] * 2
        assert not ps.has_surface_mesh(MESH)  # the scene is removed after the frames
    finally:
        ps.clear_user_callback()
        ps.set_open_imgui_window_for_user_callback(True)
        ps.remove_all_structures()
        ps.set_window_size(*size)
        ps.set_right_gui_pane_width(pane)


def test_matplotlib_draws_the_colour_maps_colours_without_a_reason_when_asked():
    V, F = _grid()
    pic = ml.show(V, F, V[:, 0], renderer="matplotlib", size=(400, 300))
    assert pic.renderer == "matplotlib" and pic.reason == "" and pic.size == (400, 300)
    assert _caption_ink(pic.image) == 0


def test_the_fallback_says_why(monkeypatch):
    """EGL failing (here: the entry point's renderer raising): matplotlib draws, the picture
    carries the reason and writes it along the bottom; ``renderer="egl"`` raises instead."""

    def fails(scene):
        raise RuntimeError("polyscope's EGL backend did not render: no EGL device here")

    monkeypatch.setattr(picture_module, "_viewer_frames", fails)
    V, F = _grid()
    pic = ml.show(V, F, V[:, 0], size=(400, 300))
    assert pic.renderer == "matplotlib" and "no EGL device here" in pic.reason
    assert "no EGL device here" in repr(pic)
    assert _caption_ink(pic.image) > 50  # "drawn by matplotlib: polyscope's EGL …"
    t = ml.turntable(V, F, V[:, 0], frames=2, size=(96, 72))
    assert t.renderer == "matplotlib" and "no EGL device" in t._repr_html_()
    with pytest.raises(RuntimeError, match="no EGL device here"):
        ml.show(V, F, renderer="egl")


def test_without_the_viewer_the_picture_says_so(monkeypatch):
    import importlib.metadata

    real = importlib.metadata.entry_points
    monkeypatch.setattr(
        importlib.metadata,
        "entry_points",
        lambda **kw: [] if kw.get("group") == picture_module.PICTURES_GROUP else real(**kw),
    )
    pic = ml.show(V2, F2, size=(96, 72))
    assert pic.renderer == "matplotlib" and "not installed" in pic.reason


def _dies_at_once(conn, folder, progress=None):
    """Stands in for the picture process's body: it ends with exit code 3 before EGL starts
    (as a process whose EGL start-up aborted)."""
    import os

    os._exit(3)


def test_a_picture_process_that_dies_falls_back_once_and_is_not_started_again(monkeypatch):
    pictures = pytest.importorskip("meshlap_app.pictures")
    monkeypatch.setattr(pictures, "_serve", _dies_at_once)
    pictures.picture_process.cache_clear()
    try:
        pic = ml.show(V2, F2, size=(96, 72))
        assert pic.renderer == "matplotlib"
        assert "EGL backend did not render" in pic.reason and "exit code 3" in pic.reason
        process = pictures.picture_process()
        assert process.child is None and process.failed
        again = ml.show(V2, F2, size=(96, 72))  # at once: no second process
        assert again.reason == pic.reason and process.child is None
    finally:
        pictures.picture_process().end()
        pictures.picture_process.cache_clear()


def test_the_fallback_draws_the_colour_maps_ends():
    V, F = _grid()
    pic = ml.show(V, F, V[:, 0], cmap="viridis", clip=0, renderer="matplotlib", size=(500, 400))
    left, right = _mesh_row_ends(pic.image, 0, int(0.7 * 500))  # matplotlib's bar: right
    # seen from −z the screen's right is −x: x = 1 (yellow) on the left, x = 0 (purple) right
    assert left[0] > left[2] + 60 and left[1] > left[2] + 60
    assert right[2] > right[1] + 20 and right[0] > right[1]


def test_the_fallback_draws_the_one_ring_and_the_crosses():
    V, F = ml.icosphere(2)
    red = lambda img: int(((img[..., 0] > 200) & (img[..., 1] < 60) & (img[..., 2] < 60)).sum())  # noqa: E731
    ring = ml.show(V, F, "cotan", vertex=0, renderer="matplotlib", size=(400, 300))
    assert red(ring.image.astype(int)) > 20  # the selected vertex's red dot
    assert red(ml.show(V, F, renderer="matplotlib", size=(400, 300)).image.astype(int)) == 0
    Vt, Ft = ml.torus_mesh(24, 10)
    pc = ml.estimate_curvature(Vt, Ft, "rusinkiewicz")
    img = ml.show(Vt, Ft, vectors=pc, up="z", renderer="matplotlib", size=(400, 300)).image
    green = (img[..., 1].astype(int) - img[..., 2] > 50) & (img[..., 0] < 80)
    assert green.sum() > 20  # the green k2 crosses


def test_a_turntable_is_a_gif_of_its_frames(tmp_path):
    from PIL import Image

    V, F = ml.icosphere(1)
    t = ml.turntable(V, F, V[:, 0], frames=3, size=(96, 72), renderer="matplotlib")
    assert len(t.frames) == 3 and all(f.shape == (72, 96, 3) for f in t.frames)
    assert not np.array_equal(t.frames[0], t.frames[1])  # the camera turned
    gif = Image.open(io.BytesIO(t.gif))
    assert gif.format == "GIF" and gif.n_frames == 3
    assert t._repr_html_().startswith('<img src="data:image/gif;base64,')
    assert _rgb(t._repr_png_()).shape == (72, 96, 3)
    out = t.save(tmp_path / "turn.gif")
    assert out.read_bytes() == t.gif
    with pytest.raises(MeshError, match="png"):
        ml.show(V, F, renderer="matplotlib", size=(96, 72)).save(tmp_path / "x.jpg")
    assert ml.show(V, F, renderer="matplotlib", size=(96, 72)).save(tmp_path / "x.png").is_file()


# ---------------------------------------------------------------------- the window
def test_without_a_display_open_viewer_starts_nothing_and_says_why():
    w = ml.open_viewer(V2, F2, environ={}) if window.sys.platform.startswith("linux") else None
    if w is None:
        pytest.skip("the display rule is Linux's (DISPLAY / WAYLAND_DISPLAY)")
    assert w.process is None and not w.running and "no display here" in w.message
    assert "no display here" in repr(w)
    assert window.display_problem({"DISPLAY": ":0"}, "linux") == ""
    assert window.display_problem({"WAYLAND_DISPLAY": "wayland-0"}, "linux") == ""
    assert window.display_problem({}, "darwin") == ""


def test_open_viewer_without_the_viewer_says_so(monkeypatch):
    monkeypatch.setattr(window, "_viewer_installed", lambda: False)
    w = ml.open_viewer(V2, F2, environ={"DISPLAY": ":0"})
    assert w.process is None and "not installed" in w.message


def test_open_viewer_reports_a_window_that_fails_at_once(tmp_path):
    """A display that does not exist: ``meshlap view`` exits 2 at once, and its reason comes
    back as the error."""
    import os

    pytest.importorskip("meshlap_app")
    env = {k: v for k, v in os.environ.items() if k != "WAYLAND_DISPLAY"}
    env["DISPLAY"] = ":987654"
    try:
        w = ml.open_viewer(V2, F2, environ=env)
    except MeshError as exc:  # it failed within the first look (a quiet machine)
        assert "exit code 2" in str(exc) and "no display" in str(exc)
        return
    assert w.wait(120) == 2 and not w.running  # later (a loaded machine): said by its status
    assert "ended (exit code 2)" in w.status() and "no display" in w.status()
    assert "no display" in repr(w)


def test_the_docstring_examples_run():
    import doctest

    from meshlap_core.pictures import turntable_gif

    for module in (picture_module, turntable_gif):
        result = doctest.testmod(module, raise_on_error=False, report=True)
        assert result.attempted >= 2 and result.failed == 0, module.__name__


@pytest.mark.window
def test_open_viewer_opens_the_window_on_a_display():
    """Under Xvfb: the window appears titled after the mesh's file, the notebook's process
    goes on, and ``close`` ends the window."""
    from tests.support.xwindow import XServer, missing_tools

    missing = missing_tools()
    if missing:
        pytest.skip(f"real-window tests need {', '.join(missing)} (.ci/run installs them)")
    pytest.importorskip("meshlap_app")
    x = XServer(1280, 720).start()
    w = None
    try:
        mesh = ml.validate_mesh(*ml.icosphere(2), "ball.obj")
        w = ml.open_viewer(mesh, vertex=3, environ=x.env())
        assert w.process is not None and w.path.name == "ball.obj"
        assert w.command[-2:] == ["--vertex", "3"]
        found = x.run("xdotool", "search", "--sync", "--onlyvisible", "--name", "ball.obj",
                      timeout=180)  # fmt: skip
        assert found.split() and w.running and "running" in w.status()
        w.close()
        assert w.wait(30) is not None and not w.running
    finally:
        if w is not None:
            w.close()
        x.stop()
