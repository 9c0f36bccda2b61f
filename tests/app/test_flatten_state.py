"""The Flatten panel's state, headless (no polyscope): the clicked seam joined along edges,
what the panel draws of a map (checkerboard coordinates, layout in the screen plane,
distortion values, histograms, flips, the clicked face's ellipse), the jobs' work against the
core's maps, ARAP continued across processes, and the cache per ``(method, boundary)``."""

from __future__ import annotations

import itertools
import threading

import numpy as np
import pytest
from meshlap_app.jobs import Reporter
from meshlap_app.state.flatten import (
    SETTINGS,
    FlattenState,
    Request,
    boundary_for,
    check_mesh,
    check_seam,
    compute,
    describe,
    face_of,
    place_row,
    screen_axes,
    seam_path,
    without_repeats,
)

from meshlap_core import Flattener, grid, icosphere
from meshlap_core.errors import MeshError
from meshlap_core.flatten import UVMap, make_disk
from meshlap_core.options import FLATTEN_BOUNDARIES, FLATTEN_METHOD_BOUNDARIES, FLATTEN_METHODS


class Remote:
    """A progress reporter as a child process gives it (``remote``: the result crosses)."""

    remote = True
    cancel = None

    def __call__(self, fraction, message=""):
        pass


# ---------------------------------------------------------------- the seam
def test_clicks_are_joined_by_the_shortest_edge_path():
    V, F = grid(5, 5)  # vertex i*5 + j at (i/4, j/4)
    path = seam_path(V, F, [2, 22])  # (0, 1/2) to (1, 1/2): the straight row, length 1
    assert path.tolist() == [2, 7, 12, 17, 22]
    path = seam_path(V, F, [0, 0, 2, 12])  # a repeat is dropped; down the column, then across
    assert path.tolist() == [0, 1, 2, 7, 12]
    edges = {tuple(sorted(e)) for f in F for e in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0]))}
    assert all(tuple(sorted(p)) in edges for p in itertools.pairwise(path))
    assert seam_path(V, F, [7]).size == 0  # one click: no seam yet


def test_a_seam_across_two_pieces_is_refused():
    V, F = grid(3, 3)
    V2 = np.vstack([V, V + np.array([2.0, 0.0, 0.0])])
    F2 = np.vstack([F, F + len(V)])
    with pytest.raises(MeshError, match="no edge path joins vertices 0 and 9"):
        seam_path(V2, F2, [0, 9])
    with pytest.raises(MeshError, match="vertex 18 is out of range; the mesh has 18"):
        seam_path(V2, F2, [0, 18])


def test_seam_values_are_checked_and_kept_without_repeats():
    assert check_seam([0, 5, 5, 2]) is None and without_repeats([0, 5, 5, 2, 2]) == [0, 5, 2]
    for bad in ("3", [1.5], [-1], [True], [10**400], {"0": 1}):
        assert check_seam(bad) is not None
    mesh = type("M", (), {"V": np.zeros((10, 3))})()
    check_mesh({"seam": [0, 9]}, mesh, "s.json")
    with pytest.raises(MeshError, match=r'"flatten.seam" has 10; vertices are 0..9'):
        check_mesh({"seam": [3, 10]}, mesh, "s.json")


def test_the_state_adds_and_undoes_seam_vertices():
    st = FlattenState()
    assert st.add_seam_vertex(10, 3) and st.add_seam_vertex(10, 4)
    assert not st.add_seam_vertex(10, 4)  # the last one again: no edge
    assert not st.add_seam_vertex(10, 10) and not st.add_seam_vertex(10, -1)
    assert st.seam == [3, 4] and st.disk_wanted(7) == (7, (3, 4))
    assert st.undo_seam() and st.seam == [3] and st.disk_wanted(7) == (7, ())  # one: no seam
    assert st.undo_seam() and not st.undo_seam()
    st.seam = [1, 2]
    st.clear()  # a new mesh: the seam was the old one's
    assert st.seam == [] and st.shown is None and st.disk_key is None


# ---------------------------------------------------------------- settings
def test_each_method_uses_the_boundary_it_takes():
    for method in FLATTEN_METHODS:
        allowed = FLATTEN_METHOD_BOUNDARIES[method]
        for boundary in FLATTEN_BOUNDARIES:
            want = boundary if boundary in allowed else allowed[0]
            assert boundary_for(method, boundary) == want
    assert boundary_for("lscm", "circle") == "free" and boundary_for("tutte", "free") == "circle"
    assert boundary_for("arap", "square") == "square"


def test_the_checker_size_is_clamped_and_a_non_number_refused():
    st = FlattenState()
    st.set_checker(10.0)
    assert st.checker == SETTINGS["checker"].hi
    for bad in (float("nan"), float("inf"), "0.1"):
        with pytest.raises(MeshError, match="checker size"):
            st.set_checker(bad)
    assert st.checker == SETTINGS["checker"].hi
    with pytest.raises(MeshError, match="map"):
        st.set_choice("method", "mercator")
    with pytest.raises(MeshError, match="ARAP iterations"):
        st.set_iters(0)


# ---------------------------------------------------------------- what the panel draws
def _stretched(nx: int = 5):
    """A flat grid mapped by ``(x, y) -> (2x, y)``: every face has σ₁/σ₂ = 2 and keeps its
    area after the map is normalized (by hand: J = diag(2, 1) · 1/√2)."""
    V, F = grid(nx, nx)
    disk = make_disk(V, F)
    return UVMap("lscm", "free", V[:, :2] * [2.0, 1.0], disk, 0.0)


def test_describe_by_hand_on_a_stretched_grid():
    view = describe(_stretched())
    F = view.uvmap.disk.F
    np.testing.assert_allclose(view.values["angle"], 2.0)
    np.testing.assert_allclose(view.values["area"], 0.0, atol=1e-12)
    # into [0, 1]²: the long side (u, 2 long) spans [0, 1], the short one is centred
    np.testing.assert_allclose(view.uv01.min(axis=0), [0.0, 0.25], atol=1e-12)
    np.testing.assert_allclose(view.uv01.max(axis=0), [1.0, 0.75], atol=1e-12)
    assert view.corners.dtype == np.float32  # (polyscope keeps single precision)
    np.testing.assert_array_equal(view.corners, view.uv01[F].reshape(-1, 2).astype(np.float32))
    for kind in ("angle", "area"):
        centers, counts, width = view.histograms[kind]
        assert counts.sum() == len(F) and width > 0 and len(centers) == len(counts)
    assert view.ranges["angle"][0] == 1.0 and view.ranges["angle"][1] == pytest.approx(2.0)
    assert view.ranges["area"][0] == -view.ranges["area"][1]
    assert len(view.flipped) == 0 and view.row["flipped"] == 0 and view.key == ("lscm", "free")


def test_flipped_faces_are_those_with_negative_signed_area():
    V, F = grid(5, 5)
    uv = V[:, :2].copy()
    uv[12] = [2.0, 2.0]  # the centre vertex thrown far outside: some of its faces turn over
    view = describe(UVMap("tutte", "circle", uv, make_disk(V, F), 0.0))
    d1, d2 = uv[F[:, 1]] - uv[F[:, 0]], uv[F[:, 2]] - uv[F[:, 0]]
    by_hand = np.flatnonzero(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] < 0)
    assert len(by_hand) > 0 and all(12 in F[f] for f in by_hand)
    np.testing.assert_array_equal(view.flipped, by_hand)
    assert view.row["flipped"] == len(by_hand)


def test_the_layout_lies_in_the_screen_plane_beside_the_mesh_facing_the_camera():
    V, F = icosphere(2)
    P = V * [1.0, 2.0, 1.0]  # taller than wide
    toward = (0.0, 0.15, -1.0)
    view = describe(Flattener(V, F).map("tutte"))
    origin, axes, offset = place_row(P, toward)
    layout = origin + view.uv01 @ axes
    right, up = screen_axes(toward)
    back = np.asarray(toward) / np.linalg.norm(toward)
    assert abs(right @ back) < 1e-12 and abs(up @ back) < 1e-12 and up[1] > 0.9
    depth = layout @ back
    assert np.ptp(depth) < 1e-12  # flat, in the screen plane
    x, y = layout @ right, layout @ up
    size = max(np.ptp(P @ right), np.ptp(P @ up))
    assert np.ptp(x) == pytest.approx(size) or np.ptp(y) == pytest.approx(size)
    assert x.min() > (P @ right).max()  # right of the mesh, with a gap
    assert ((P + offset) @ right).min() > x.max()  # the copy right of the layout
    Fd = view.uvmap.disk.F
    n = np.cross(layout[Fd[:, 1]] - layout[Fd[:, 0]], layout[Fd[:, 2]] - layout[Fd[:, 0]])
    assert np.all(n @ back > 0)  # every face of the layout faces the camera


def test_a_pick_names_the_face_hit():
    V, F = grid(3, 3)
    assert face_of("face", 5, np.zeros(3), V, F) == 5
    # vertex 4 (the centre) picked near the centroid of face 3 (4, 7, 8): that face
    c = V[F[3]].mean(axis=0)
    assert face_of("vertex", 4, c, V, F) == 3
    assert face_of("edge", 0, V[F[6]].mean(axis=0), V, F) == 6  # any other element: nearest


def test_the_clicked_face_maps_a_circle_to_its_ellipse():
    """By hand on the stretched grid: the face's Jacobian is diag(2, 1) up to the face's
    frame (singular values √2 and 1/√2 once the map's area is normalized), so a circle of
    radius r maps to the ellipse of semi-axes 2r along u and r along v; in the layout's
    coordinates (the map's 2 units of u are 1) r and r/2."""
    st = FlattenState()
    st.shown, st.face = describe(_stretched()), 3
    e, circle, image = st.ellipse()
    assert e.sigma1 == pytest.approx(np.sqrt(2)) and e.sigma2 == pytest.approx(1 / np.sqrt(2))
    r = np.linalg.norm(circle - circle.mean(axis=0), axis=1)
    np.testing.assert_allclose(r, r[0], rtol=1e-12)  # a circle on the face
    half = np.abs(image - image.mean(axis=0)).max(axis=0)
    np.testing.assert_allclose(half, [r[0], r[0] / 2], rtol=1e-9)
    st.face = -1
    assert st.ellipse() is None


# ---------------------------------------------------------------- the jobs' work
@pytest.mark.parametrize(
    ("method", "boundary"),
    [(m, b) for m in FLATTEN_METHODS if m != "arap" for b in FLATTEN_METHOD_BOUNDARIES[m]],
)
def test_compute_gives_the_cores_map_and_reuses_the_disk(method, boundary):
    V, F = icosphere(2)
    req = Request(V, F, (0, ()), method, boundary)
    flat, arap, view, rate = compute(req)
    ref = Flattener(V, F).map(method, boundary)
    np.testing.assert_allclose(view.uvmap.uv, ref.uv, atol=1e-12)
    assert arap is None and rate == 0.0 and view.row["method"] == method
    again = compute(req, flat)
    assert again[0] is flat  # the disk's flattener reused, not remade


def test_compute_cuts_along_the_clicked_seam():
    V, F = icosphere(2)
    clicks = (0, 20, 40)
    flat, _, view, _ = compute(Request(V, F, (0, clicks), "tutte", "circle"))
    ref = Flattener(V, F, seam_path(V, F, list(clicks))).map("tutte")
    np.testing.assert_allclose(view.uvmap.uv, ref.uv, atol=1e-12)
    assert flat.disk.how.startswith("seam")


def test_arap_continued_from_its_map_is_the_same_run():
    """Six iterations in one run, or three in a child process and three more from the map
    it sent back: the same map and energies (the local step depends on the map alone)."""
    V, F = icosphere(2)
    one = compute(Request(V, F, (0, ()), "arap", "free", iters=6))
    first = compute(Request(V, F, (0, ()), "arap", "free", iters=3), progress=Remote())
    assert first[0] is None and first[1] is None  # nothing of the child's process comes back
    m = first[2].uvmap
    assert m.flattener is None and m.disk.table is None and m.iterations == 3
    req = Request(V, F, (0, ()), "arap", "free", 3, m.uv, list(m.energies), m.seconds)
    two = compute(req, progress=Remote())
    np.testing.assert_allclose(two[2].uvmap.uv, one[2].uvmap.uv, atol=1e-10)
    np.testing.assert_allclose(two[2].uvmap.energies, one[2].uvmap.energies, rtol=1e-10)
    assert two[2].uvmap.iterations == 6
    e = np.asarray(one[2].uvmap.energies)
    assert np.all(np.diff(e) <= 1e-12 * e[0])  # never rises


def test_arap_hands_its_maps_over_live_and_stops_on_cancel():
    V, F = icosphere(2)
    seen: list = []
    rep = Reporter(threading.Event())
    rep.partial = lambda value: seen.append(value)  # type: ignore[method-assign]
    flat, arap, view, rate = compute(
        Request(V, F, (0, ()), "arap", "circle", iters=30), progress=rep
    )
    assert rate > 0 and arap.iterations == 30 and view.uvmap.iterations == 30
    iterations = [v[2].uvmap.iterations for v in seen]
    assert iterations[:1] == [1]  # the first iteration is shown at once
    assert iterations == sorted(iterations) and all(0 < i < 30 for i in iterations)
    rep.cancel.set()
    from meshlap_core.errors import Cancelled

    with pytest.raises(Cancelled):
        compute(Request(V, F, (0, ()), "arap", "circle", iters=5), flat, arap, progress=rep)
    assert arap.iterations == 30  # cancelled before its first step


def test_the_child_process_path_returns_the_same_map():
    from meshlap_app import ipc

    V, F = icosphere(2)
    req = Request(V, F, (0, ()), "lscm", "free")
    rep = Reporter(threading.Event())
    try:
        flat, arap, view, _ = ipc.call(compute, req, reporter=rep)
    except ipc.NoChildProcess as exc:
        pytest.skip(f"no child process here: {exc}")
    assert flat is None and arap is None
    np.testing.assert_allclose(view.uvmap.uv, Flattener(V, F).map("lscm").uv, atol=1e-12)
    e = view.uvmap.distortion().ellipse(0)  # measured in the child, usable here
    assert e.sigma1 >= e.sigma2 > 0


# ---------------------------------------------------------------- adopting results
def test_results_are_kept_per_map_and_shown_when_asked_for():
    V, F = icosphere(2)
    st = FlattenState()
    st.new_disk((0, ()))
    tutte = compute(Request(V, F, (0, ()), "tutte", "circle"))
    st.adopt(tutte, (0, ()))
    assert st.shown is tutte[2] and st.flattener is tutte[0]
    lscm = compute(Request(V, F, (0, ()), "lscm", "free"), tutte[0])
    st.adopt(lscm, (0, ()))  # computed, but not what the settings ask for: kept, not shown
    assert st.shown is tutte[2] and set(st.maps) == {("tutte", "circle"), ("lscm", "free")}
    assert [r["method"] for r in st.rows()] == ["tutte", "lscm"]
    st.adopt(compute(Request(V, F, (1, ()), "harmonic", "circle")), (1, ()))  # another disk
    assert ("harmonic", "circle") not in st.maps
    st.face = 10**6
    st.method = "lscm"
    st.adopt(lscm, (0, ()))
    assert st.shown is lscm[2] and st.face == -1  # a face the map does not have is dropped
    st.new_disk((0, (1, 2)))
    assert st.maps == {} and st.shown is lscm[2]  # the last good map stays on screen
    assert st.request(V, F, 0).disk == (0, ())  # one click: no seam
