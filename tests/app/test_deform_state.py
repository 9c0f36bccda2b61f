"""The Deform panel's state as plain objects (no polyscope): handles and their discs, the fixed
region, moves from gizmo transforms, undo / redo, method switching, the session checks and the
solves against the core's deformers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from meshlap_app.state.deform import SETTINGS, SPEC, DeformState, check_section
from meshlap_app.state.handle_sets import build_set
from meshlap_app.state.moves import diagonal, move_matrix, move_of, move_problem

from meshlap_core import grid
from meshlap_core.deform import make_deformer, rigid_targets, rotation_matrix
from meshlap_core.errors import MeshError
from meshlap_core.primitives import icosphere


def built_state(V, F, handles, **settings) -> DeformState:
    """A state with ``handles`` selected and its handle set built (as the panel's job does)."""
    st = DeformState(**settings)
    for k, v in enumerate(handles):
        assert st.select(len(V), v, add=k > 0)
    st.adopt(build_set(V, F, st.setup_key(0)))
    return st


def test_a_click_makes_a_handle_shift_adds_one_and_out_of_range_changes_nothing():
    st = DeformState()
    assert st.select(10, 3) and st.handles == [3] and st.active == 0
    assert st.select(10, 5, add=True) and st.handles == [3, 5] and st.active == 1
    assert st.select(10, 3, add=True) and st.handles == [3, 5] and st.active == 0  # again: active
    assert not st.select(10, 10) and not st.select(10, -1)
    assert st.select(10, 7) and st.handles == [7]  # a plain click: that one alone
    assert len(st.moves) == len(st.handles) == 1
    assert st.add_fixed(10, 2) and st.fixed == [2] and st.fixed_region == "clicked"
    assert not st.add_fixed(10, 7)  # a handle is not held
    assert st.add_fixed(10, 2) and st.fixed == []  # again: let go


def test_region_growth_is_the_geodesic_disc_and_the_fixed_region_the_farthest():
    """A grid of spacing 1/8: the disc of radius 0.2 (in % of the diagonal sqrt 2) around the
    centre holds exactly the vertices within that distance (flat: geodesic = Euclidean); the
    farthest 10 % are held, none of them near the handle."""
    V, F = grid(9, 9)
    centre = 40
    r_pct = 100 * 0.2 / math.sqrt(2)
    st = built_state(V, F, [centre], radius=r_pct)
    b = st.built
    want = np.flatnonzero(np.linalg.norm(V - V[centre], axis=1) <= 0.2 + 1e-12)
    np.testing.assert_array_equal(b.regions.vertices, want)
    assert len(b.fixed) > 0 and np.intersect1d(b.fixed, b.regions.vertices).size == 0
    d = np.linalg.norm(V[b.fixed] - V[centre], axis=1)
    assert d.min() > 0.5  # the corners, far from the centre
    st.radius = 0.0  # radius 0: the seed alone
    st.adopt(build_set(V, F, st.setup_key(0)))
    assert st.built.regions.vertices.tolist() == [centre]


def test_move_and_gizmo_transform_round_trip():
    """A move (axis, degrees, translation) read back from its rotation matrix, including a
    half turn and no turn at all."""
    for axis, deg in (([0, 0, 1], 30.0), ([1, 2, -1], 170.0), ([0, 1, 0], 180.0), ([1, 0, 0], 0.0)):
        m = {"rotate": [float(a) for a in axis] + [deg], "move": [0.5, -1.0, 2.0]}
        R, t = move_matrix(m)
        back = move_of(R, t)
        R2, t2 = move_matrix(back)
        np.testing.assert_allclose(R2, R, atol=1e-12)
        np.testing.assert_allclose(t2, t)
        assert abs(back["rotate"][3]) == pytest.approx(deg, abs=1e-9)


def test_targets_are_each_disc_rotated_about_its_centroid_then_moved():
    V, F = icosphere(3)
    st = built_state(V, F, [0, 300], radius=8.0, fixed_region="none")
    m = {"rotate": [0.0, 1.0, 0.0, 45.0], "move": [0.1, 0.2, 0.3]}
    st.set_move(1, m)
    b = st.built
    d = b.deformers["arap"]
    T = st.targets("arap")
    for i, seed in enumerate(b.regions.seeds):
        mask = b.region_of["arap"] == i
        moved = st.moves[st.handles.index(int(seed))]
        R, t = move_matrix(moved)
        np.testing.assert_allclose(T[mask], rigid_targets(V, d.handles[mask], R, t))
    first = b.region_of["arap"] == list(b.regions.seeds).index(0)
    np.testing.assert_allclose(T[first], V[d.handles[first]])  # handle 0 not moved
    # hand check: the disc's centroid goes exactly by the move
    second = ~first
    c = V[d.handles[second]].mean(axis=0)
    np.testing.assert_allclose(T[second].mean(axis=0), c + np.array([0.1, 0.2, 0.3]), atol=1e-12)


def test_undo_redo_of_moves_and_reset():
    st = DeformState()
    st.select(100, 4)
    st.select(100, 9, add=True)
    a = {"rotate": [0.0, 0.0, 1.0, 10.0], "move": [1.0, 0.0, 0.0]}
    b = {"rotate": [0.0, 0.0, 1.0, 20.0], "move": [2.0, 0.0, 0.0]}
    st.checkpoint()
    st.set_move(0, a)
    st.checkpoint()
    st.set_move(1, b)
    assert st.moves == [a, b]
    assert st.undo() and st.moves[1]["move"] == [0.0, 0.0, 0.0] and st.moves[0] == a
    assert st.undo() and st.moves[0]["move"] == [0.0, 0.0, 0.0]
    assert st.redo() and st.moves[0] == a
    assert st.redo() and st.moves == [a, b]
    assert not st.redo()
    st.reset_moves()
    assert all(m["rotate"][3] == 0 and m["move"] == [0.0, 0.0, 0.0] for m in st.moves)
    assert st.undo() and st.moves == [a, b]  # reset is one undo step
    while st.undo():  # back through the clicks too: the first handle alone, then none
        pass
    assert st.handles == []
    with pytest.raises(MeshError):
        st.set_move(0, {"rotate": [0, 0, 0, 10], "move": [0, 0, 0]})  # the zero axis


def test_switching_the_method_keeps_handles_and_moves_and_rebuilds_the_set():
    V, F = icosphere(3)
    st = built_state(V, F, [0, 500], radius=6.0)
    m = {"rotate": [0.0, 0.0, 1.0, 25.0], "move": [0.0, 0.3, 0.0]}
    st.set_move(0, m)
    key = st.setup_key(0)
    st.method = "biharmonic"
    assert not st.ready(0) and st.setup_key(0) != key  # a new set to build
    assert st.handles == [0, 500] and st.moves[0] == m
    st.adopt(build_set(V, F, st.setup_key(0)))
    assert st.due() == ["biharmonic"]
    assert st.solve("biharmonic") and st.due() == []
    ref = make_deformer("biharmonic", V, F, st.built.regions.vertices, st.built.fixed)
    U = ref.update(st.targets("biharmonic"))
    np.testing.assert_allclose(st.shown["biharmonic"].positions, U, atol=1e-12)
    st.compare = "laplacian"
    assert st.methods == ("biharmonic", "laplacian")
    st.compare = "biharmonic"  # the method itself: one copy
    assert st.methods == ("biharmonic",)


def test_arap_iterates_frame_by_frame_until_converged_and_its_energy_never_rises():
    V, F = icosphere(3)
    st = built_state(V, F, [0], radius=10.0, arap_per_frame=3, arap_max=60)
    st.set_move(0, {"rotate": [1.0, 0.0, 0.0, 60.0], "move": [0.0, 0.4, 0.0]})
    frames = 0
    while st.due():
        st.solve("arap")
        frames += 1
        assert frames < 100
    d = st.built.deformers["arap"]
    E = np.asarray(d.energies)
    assert np.all(np.diff(E) <= 1e-12 * E[0])  # never increases while the targets stay
    assert d.iteration <= 60 and frames >= math.ceil(d.iteration / 3)
    assert st.converged["arap"]
    f = st.figures("arap")
    assert f["iteration"] == d.iteration and f["energy"] == pytest.approx(E[-1])
    assert f["n_unknowns"] == len(V) - len(d.handles) - len(d.fixed) > 0


def test_zero_move_is_the_rest_pose_and_the_field_is_zero():
    V, F = icosphere(2)
    for method in ("laplacian", "harmonic", "biharmonic", "arap"):
        st = built_state(V, F, [3], method=method, radius=10.0)
        while st.due():
            st.solve(method)
        np.testing.assert_allclose(st.shown[method].positions, V, atol=1e-9)
        assert float(np.max(st.field(method))) < 1e-9
        st.colour = "rotation error"
        assert float(np.max(st.field(method))) < 1e-6


def test_the_session_checks_tie_moves_to_handles():
    ok = {**SETTINGS.defaults(), "handles": [1, 2], "moves": []}
    check_section(ok, "s.json")
    assert len(ok["moves"]) == 2  # an older list without moves: every handle at rest
    bad = {**SETTINGS.defaults(), "handles": [1], "moves": SETTINGS["moves"].sample()}
    with pytest.raises(MeshError, match="2 moves for 1 handle"):
        check_section(bad, "s.json")
    both = {**SETTINGS.defaults(), "handles": [1], "fixed": [1], "moves": []}
    with pytest.raises(MeshError, match="a handle seed too"):
        check_section(both, "s.json")
    assert move_problem({"rotate": [0, 0, 1, 0], "move": [0, 0, 0]}) is None
    assert "zero axis" in move_problem({"rotate": [0, 0, 0, 5], "move": [0, 0, 0]})

    class Mesh:
        V = np.zeros((5, 3))

    with pytest.raises(MeshError, match=r"deform\.handles.*0\.\.4"):
        SPEC.check_mesh({**SETTINGS.defaults(), "handles": [7], "moves": []}, Mesh(), "s.json")


def test_rotation_of_every_handle_by_one_motion_is_kept_by_arap_not_by_laplacian():
    """Three handles and nothing fixed, all turned 90° about z: ARAP reproduces the rigid turn
    (libigl's tutorial result), Laplacian coordinates keep the details' orientation (a large
    error); the panel's rotation error says the same."""
    V, F = icosphere(3)
    seeds = [0, 200, 400]
    R = rotation_matrix([0, 0, 1], 90)
    out = {}
    for method in ("arap", "laplacian"):
        st = built_state(V, F, seeds, method=method, radius=0.0, fixed_region="none",
                         arap_per_frame=100, arap_max=500)  # fmt: skip
        c = V[seeds].mean(axis=0)
        for i, s in enumerate(seeds):  # each seed to where the one rigid turn takes it
            st.set_move(
                i, {"rotate": [0.0, 0.0, 1.0, 0.0], "move": list((V[s] - c) @ R.T + c - V[s])}
            )
        while st.due():
            st.solve(method)
        want = (V - c) @ R.T + c
        out[method] = float(np.abs(st.shown[method].positions - want).max())
    assert out["arap"] < 1e-3 < 0.05 < out["laplacian"]


def test_diagonal():
    assert diagonal(np.zeros((0, 3))) == 1.0
    assert diagonal(np.array([[0.0, 0, 0], [3.0, 4.0, 0]])) == 5.0
