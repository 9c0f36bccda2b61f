"""The exercises checker, checked: wrong student files fail with the named diagnosis, right
ones written unlike the reference pass, hostile ones are stopped while the checker survives.

The student files live in ``tests/exercises/``; each runs sandboxed (the grading harness, under
bubblewrap where it works) once per module (``checked``), and every test reads its verdicts.
"""

from __future__ import annotations

import ast
import os

import numpy as np
import pytest

from meshlap_core import curvature as cv
from meshlap_core import laplacian as lap
from meshlap_core import primitives
from meshlap_core.diffusion import mean_edge_length
from meshlap_core.errors import MeshError
from meshlap_core.exercises import check_file, guard, template
from meshlap_core.exercises import deform_tasks as dt
from meshlap_core.exercises import flatten_tasks as ft
from meshlap_core.exercises import geodesic_task as geo
from meshlap_core.exercises.compare import COMPARE, degenerate_vertices
from meshlap_core.exercises.diagnose import DIAGNOSES, candidates, constant_factor, diagnose
from meshlap_core.exercises.meshes import Case, battery, case_named
from meshlap_core.exercises.sandbox import TaskRun
from meshlap_core.exercises.tasks import EXERCISE_TASKS, TASKS
from meshlap_core.exercises.verdict import evaluate
from meshlap_core.topology.rings import one_ring
from tests.support.students import STUDENTS

WRONG = [  # (student file, task, the diagnosis it must get)
    ("wrong_uniform_sign", "uniform_laplacian", "sign_flip"),
    ("wrong_uniform_transposed", "uniform_laplacian", "transposed"),
    ("wrong_uniform_graph", "uniform_laplacian", "graph_not_normalised"),
    ("wrong_uniform_fmax", "uniform_laplacian", "sized_by_faces"),
    ("wrong_cotan_full", "cotan_laplacian", "cot_not_half"),
    ("wrong_cotan_quarter", "cotan_laplacian", "factor_half"),
    ("wrong_cotan_abs", "cotan_laplacian", "clamped_weights"),
    ("wrong_cotan_rownorm", "cotan_laplacian", "row_normalised"),
    ("wrong_areas", "barycentric_areas", "not_divided_by_3"),
    ("wrong_areas", "voronoi_areas", "barycentric_not_voronoi"),
    ("wrong_areas", "mass_matrix", "barycentric_not_voronoi"),
    ("wrong_voronoi_no_obtuse", "voronoi_areas", "no_obtuse_rule"),
    ("wrong_curvature", "mean_curvature_normal", "sign_flip"),
    ("wrong_curvature", "mean_curvature", "factor_2"),
    ("wrong_defect", "angle_defect", "missing_boundary_term"),
    ("wrong_defect_degrees", "angle_defect", "degrees"),
    ("wrong_ring_cw", "one_ring", "wrong_orientation"),
    ("wrong_spectral", "eigenbasis", "ordinary_eigenproblem"),
    ("wrong_spectral", "spectral_reconstruction", "projection_without_mass"),
    ("wrong_eigen_euclid", "eigenbasis", "not_m_orthonormal"),
    ("wrong_steps", "explicit_step", "sign_flip"),
    ("wrong_steps", "taubin_step", "mu_sign"),
    ("wrong_implicit", "implicit_step", "missing_mass"),
    ("wrong_implicit_explicit", "implicit_step", "explicit_not_implicit"),
    ("wrong_cotan_lb", "cotan_laplacian", "divided_by_area"),
    ("wrong_bary_voronoi", "barycentric_areas", "voronoi_not_barycentric"),
    ("wrong_hn_uniform", "mean_curvature_normal", "uniform_not_cotan"),
    ("wrong_defect_rule", "angle_defect", "wrong_boundary_rule"),
    ("wrong_ring_sorted", "one_ring", "unordered"),
    ("wrong_taubin_parallel", "taubin_step", "not_sequential"),
    ("wrong_eigen_negative", "eigenbasis", "sign_flip"),
    ("wrong_heat_unnormalised", "heat_geodesic", "gradient_not_normalised"),
    ("wrong_heat_sign", "heat_geodesic", "divergence_sign"),
    ("wrong_heat_time", "heat_geodesic", "time_not_scaled"),
    ("wrong_heat_shift", "heat_geodesic", "not_shifted"),
    # the battery of degenerate, thin and big meshes, and the answers that are not values
    ("wrong_hn_no_half", "mean_curvature_normal", "constant_factor"),
    ("wrong_float32", "cotan_laplacian", "single_precision"),
    ("wrong_cotan_clamped", "cotan_laplacian", "clamped_weights"),
    ("wrong_shape", "mean_curvature_normal", "wrong_shape"),
    ("wrong_shape", "barycentric_areas", "wrong_shape"),
    ("wrong_cotan_nan", "cotan_laplacian", "nan_on_degenerate"),
    ("wrong_cotan_dense", "cotan_laplacian", "dense_at_size"),
    ("wrong_dense", "cotan_laplacian", "dense_at_size"),
    ("wrong_dense", "heat_geodesic", "dense_at_size"),
    ("wrong_complex", "barycentric_areas", "complex_values"),
    ("wrong_complex", "eigenbasis", "complex_values"),
    ("wrong_dependency", "mean_curvature_normal", "failed_dependency"),
    # deforming (biharmonic displacement, an ARAP step) and flattening (Tutte, LSCM)
    ("wrong_biharmonic_positions", "biharmonic_displacement", "positions_not_displacement"),
    ("wrong_biharmonic_uniform", "biharmonic_displacement", "uniform_not_cotan"),
    ("wrong_biharmonic_no_mass", "biharmonic_displacement", "biharmonic_without_mass"),
    ("wrong_biharmonic_harmonic", "biharmonic_displacement", "harmonic_not_biharmonic"),
    ("wrong_arap_reflection", "arap_step", "no_reflection_fix"),
    ("wrong_arap_uniform", "arap_step", "uniform_not_cotan"),
    ("wrong_arap_transposed", "arap_step", "rotation_transposed"),
    ("wrong_arap_not_averaged", "arap_step", "rotation_not_averaged"),
    ("wrong_arap_handles", "arap_step", "handles_not_placed"),
    ("wrong_tutte_uniform", "tutte_map", "uniform_not_cotan"),
    ("wrong_tutte_index", "tutte_map", "boundary_by_index"),
    ("wrong_tutte_turned", "tutte_map", "boundary_turned"),
    ("wrong_tutte_off_circle", "tutte_map", "boundary_not_on_circle"),
    ("wrong_lscm_no_area", "lscm", "no_area_term"),
    ("wrong_lscm_area_sign", "lscm", "area_sign"),
    ("wrong_lscm_uniform", "lscm", "uniform_not_cotan"),
    ("wrong_lscm_unpinned", "lscm", "unpinned"),
]
STOPPED = {"dense_at_size": "memory"}
"""Diagnoses of a task the sandbox stopped (not a compared value)."""
RIGHT = ["right_vectorized", "right_loops", "right_other_order", "right_igl", "right_helper_module"]
"""(right_helper_module.py keeps its work in mesh_helpers.py beside it: copied with it.)"""
HOSTILE_TIMEOUT = 4.0


def _tasks_in(name: str) -> list[str]:
    tree = ast.parse((STUDENTS / f"{name}.py").read_text())
    defined = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    return [t for t in EXERCISE_TASKS if t in defined]


@pytest.fixture(scope="module")
def checked():
    """File name -> CheckResult, each student file checked once (on the tasks it defines)."""
    cache = {}

    def get(name: str, **kw):
        if name not in cache:
            cache[name] = check_file(STUDENTS / f"{name}.py", _tasks_in(name), **kw)
        return cache[name]

    return get


# ---- the wrong-solution suite --------------------------------------------------------------


def test_the_suites_are_as_large_as_the_issue_asks():
    assert len(WRONG) >= 10 and len(RIGHT) >= 5
    assert {d for _, _, d in WRONG} >= {
        "sign_flip", "factor_2", "factor_half", "barycentric_not_voronoi", "cot_not_half",
        "missing_boundary_term", "transposed", "row_normalised", "wrong_orientation",
        "ordinary_eigenproblem", "projection_without_mass", "constant_factor",
        "single_precision", "clamped_weights", "wrong_shape", "failed_dependency",
        "dense_at_size", "nan_on_degenerate", "complex_values", "positions_not_displacement",
        "uniform_not_cotan", "no_reflection_fix", "unpinned", "boundary_not_on_circle",
    }  # fmt: skip


@pytest.mark.parametrize(("name", "task", "diagnosis"), WRONG, ids=lambda x: str(x))
def test_a_wrong_solution_fails_with_its_diagnosis(checked, name, task, diagnosis):
    result = checked(name)[task]
    assert result.status == STOPPED.get(diagnosis, "failed"), result.lines()
    assert result.diagnosis == diagnosis, result.lines()
    assert DIAGNOSES[diagnosis].split(":")[0].split("{")[0] in "\n".join(result.lines())


@pytest.mark.parametrize("name", RIGHT)
def test_a_right_solution_written_differently_passes(checked, name):
    result = checked(name)
    assert len(result.tasks) >= 4
    assert result.passed, result.format_text()


def test_the_right_solutions_cover_every_task():
    covered = {t for name in RIGHT for t in _tasks_in(name)}
    assert covered == set(EXERCISE_TASKS)


def test_a_right_but_slow_answer_passes_with_its_speed_line_unless_speed_is_required():
    """wrong_cotan_slow.py writes a sparse matrix entry by entry: right, and hundreds of times
    the reference's CPU time. It passes, its speed line says SLOW and names the loop; with
    ``require_speed`` it fails (``slow_loop``). Before, it failed in 5 of 5 runs alone and
    passed inside a folder run (wall time, one ratio)."""
    path = STUDENTS / "wrong_cotan_slow.py"
    free = check_file(path, ["cotan_laplacian"])["cotan_laplacian"]
    assert free.passed and free.speed is not None and free.speed.slow, free.lines()
    text = "\n".join(free.lines())
    assert "SLOW" in text and "the loop at line" in text and "wrong_cotan_slow.py" in text
    strict = check_file(path, ["cotan_laplacian"], require_speed=True)["cotan_laplacian"]
    assert strict.status == "failed" and strict.diagnosis == "slow_loop", strict.lines()


def test_every_task_gets_the_same_speed_line(checked):
    """Every right task is timed on its speed mesh (the large sphere; the large disk for the
    maps of a disk) in the same runs, with the same rule (before, one task had no speed check
    at all)."""
    result = checked("right_vectorized")
    for t in result.tasks:
        assert t.speed is not None and t.speed.runs == 3, t.lines()
        assert t.speed.vertices == len(case_named(TASKS[t.task].speed_case).V)
        assert t.lines()[1].startswith("  speed: ")
    assert {TASKS[t.task].speed_case for t in result.tasks} == {"large", "large_disk"}


def test_a_wrong_value_names_the_mesh_the_vertex_expected_and_got(checked):
    r = checked("wrong_cotan_abs")["cotan_laplacian"]
    # the negative weights of the obtuse fan, the non-Delaunay pair and the cap (slivers), and
    # the zero-area triangle its unguarded cot divides by (said in the note): nowhere else
    assert r.case in ("obtuse_fan", "non_delaunay_pair") and r.n_failed == 4
    assert "also on mesh degenerate: NaN or inf" in r.note
    got, expected = dict(r.got), dict(r.expected)
    assert got.keys() == expected.keys()
    assert any(
        e < 0 and np.isclose(g, -e) for g, e in zip(got.values(), expected.values(), strict=True)
    )


# ---- every mistake in the table is recognised from its own wrong answer (no sandbox) -------


def _mistake_cases():
    for task in TASKS.values():
        for mistake in candidates(task):
            yield pytest.param(task.name, mistake, id=f"{task.name}-{mistake.key}")


@pytest.mark.parametrize(("name", "mistake"), list(_mistake_cases()))
def test_each_mistake_is_diagnosed_from_its_wrong_answer(name, mistake):
    task = TASKS[name]
    failures = []
    for case in (case_named(c) for c in task.cases):
        for label, args in task.calls(case):
            wrong = mistake.wrong(case, args)
            if wrong is None:
                continue
            cmp = COMPARE[task.kind](wrong, task.reference(case, args), case, task.power)
            if not cmp.ok:
                failures.append((case, label, args, wrong))
    assert failures, "the battery cannot tell this mistake from the right answer"
    key = diagnose(task, failures)
    # a mistake equal to an earlier one on every mesh gets the earlier (same-meaning) name
    assert key is not None
    assert (
        key == mistake.key or DIAGNOSES[key] == DIAGNOSES[mistake.key] or _same(task, key, mistake)
    )


def _same(task, key, mistake) -> bool:
    first = next(m for m in candidates(task) if m.key == key)
    for case in (case_named(c) for c in task.cases):
        for _, args in task.calls(case):
            a, b = first.wrong(case, args), mistake.wrong(case, args)
            if a is None or b is None:
                continue
            if not COMPARE[task.kind](a, b, case, task.power).ok:
                return False
    return True


def test_the_heat_steps_without_a_mistake_are_the_reference():
    """The mistakes of heat_geodesic are written with heat_steps: with no switch it must give
    the lab's HeatGeodesic answer, and the distance must scale with the mesh (t = m·h²)."""
    task = TASKS["heat_geodesic"]
    answers = {}
    for name in task.cases:
        case = case_named(name)
        ((_, args),) = task.calls(case)
        ref = task.reference(case, args)
        t = args[3] * mean_edge_length(case.V, case.F) ** 2
        mine = geo.heat_steps(case.V, case.F, args[2], t)
        np.testing.assert_allclose(mine, ref, rtol=0, atol=1e-10 * ref.max())
        assert ref[args[2]] == 0 and ref.min() == 0 and ref.max() > 0
        answers[name] = ref
    np.testing.assert_allclose(answers["scaled"], 250.0 * answers["small_sphere"], rtol=1e-9)


STEPS = {
    "biharmonic_displacement": dt.biharmonic_steps,
    "arap_step": dt.arap_steps,
    "tutte_map": ft.tutte_steps,
    "lscm": ft.lscm_steps,
}


@pytest.mark.parametrize("name", list(STEPS))
def test_the_deform_and_flatten_steps_without_a_mistake_are_the_reference(name):
    """The mistakes of the four tasks are written with their ``*_steps`` (the template's
    formulas with a switch per mistake): with no switch they give the lab's answer on every
    call of the battery."""
    task = TASKS[name]
    for case in (case_named(c) for c in task.cases):
        for label, args in task.calls(case):
            cmp = COMPARE["array"](STEPS[name](*args), task.reference(case, args), case, task.power)
            assert cmp.ok, (case.name, label, cmp.error, cmp.tol)


def _signed_areas(T: np.ndarray) -> np.ndarray:
    """Twice the signed area of each triangle ``T`` ``(m,3,2)`` in the plane."""
    a, b = T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def test_tutte_on_the_obtuse_fan_by_hand():
    """Five boundary vertices on the unit circle by arc length from loop[0] (at (1, 0),
    counter-clockwise), the one interior vertex at their average (uniform weights)."""
    case = case_named("obtuse_fan")
    (label, args), _ = TASKS["tutte_map"].calls(case)
    loop = args[2]
    assert label == "weights=uniform" and sorted(loop.tolist()) == [1, 2, 3, 4, 5]
    P = case.V[loop]
    edges = [float(np.linalg.norm(P[(k + 1) % 5] - P[k])) for k in range(5)]
    s = [sum(edges[:k]) / sum(edges) for k in range(5)]
    ring = np.array([[np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)] for t in s])
    uv = TASKS["tutte_map"].reference(case, args)
    np.testing.assert_allclose(uv[loop], ring, atol=1e-15)
    np.testing.assert_allclose(uv[0], ring.mean(axis=0), atol=1e-15)
    # the loop runs counter-clockwise: the fan's faces keep their orientation
    assert (_signed_areas(uv[case.F]) > 0).all()


def test_the_flatten_battery_is_disks_and_tutte_never_flips_on_them():
    """Each flattening mesh is a disk of its own vertices; Tutte's map (convex boundary,
    positive weights) flips no face there (Floater 2003); its pins and units are as stated."""
    from meshlap_core.flatten import make_disk

    for name in ft.FLATTEN_CASES:
        case = case_named(name)
        disk = make_disk(case.V, case.F, cut=False)
        assert disk.how == "disk" and disk.n_vertices == len(case.V), name
        (_, args), _ = TASKS["tutte_map"].calls(case)
        assert (_signed_areas(TASKS["tutte_map"].reference(case, args)[case.F]) > 0).all(), name
        ((_, (V, F, pins, pin_uv)),) = TASKS["lscm"].calls(case)
        uv = TASKS["lscm"].reference(case, (V, F, pins, pin_uv))
        assert np.array_equal(uv[pins], pin_uv) and pin_uv[1, 0] > 0
    ref = {c: TASKS["lscm"].reference(case_named(c), TASKS["lscm"].calls(case_named(c))[0][1])
           for c in ("cap", "scaled_cap")}  # fmt: skip
    np.testing.assert_allclose(ref["scaled_cap"], 250.0 * ref["cap"], rtol=0, atol=1e-9 * 250)
    jittered = case_named("jittered_disk")
    (_, args), _ = TASKS["tutte_map"].calls(jittered)
    by_index = ft.tutte_by_index(jittered, args)
    assert not COMPARE["array"](
        by_index, TASKS["tutte_map"].reference(jittered, args), jittered, 0
    ).ok


def test_the_flatten_references_are_libigls():
    """An independent reference: libigl's harmonic map on libigl's circle, and its LSCM."""
    import igl

    case = case_named("cap")
    _, (_, cotan) = TASKS["tutte_map"].calls(case)
    V, F, loop, _ = cotan
    at = igl.map_vertices_to_circle(np.asfortranarray(V), loop.astype(np.int32))
    harmonic = igl.harmonic(V, F, loop, at, 1)
    np.testing.assert_allclose(TASKS["tutte_map"].reference(case, cotan), harmonic, atol=1e-10)
    ((_, args),) = TASKS["lscm"].calls(case)
    uv, _ = igl.lscm(*args)
    np.testing.assert_allclose(TASKS["lscm"].reference(case, args), uv, atol=1e-10)


def test_the_deform_calls_and_references():
    """Biharmonic: libigl's ``harmonic(..., k=2)`` on the displacement, and no move gives the
    rest pose exactly; ARAP: from the rest pose with the handles at rest nothing moves; the
    ARAP call's current positions hold one-rings whose best fit is a reflection."""
    import igl

    bi, arap = TASKS["biharmonic_displacement"], TASKS["arap_step"]
    for case in (case_named(c) for c in dt.DEFORM_CASES if c != "huge"):
        ((_, (V, F, h, d)),) = bi.calls(case)
        U = bi.reference(case, (V, F, h, d))
        np.testing.assert_allclose(U, V + igl.harmonic(V, F, h, d, 2), atol=1e-8 * case.scale)
        assert np.array_equal(U[h], V[h] + d)
        assert np.array_equal(bi.reference(case, (V, F, h, 0.0 * d)), V)
        ((_, (V, F, U0, h, targets)),) = arap.calls(case)
        rest = arap.reference(case, (V, F, V.copy(), h, V[h].copy()))
        assert np.abs(rest - V).max() <= 1e-9 * case.scale, case.name
        i, j, w = (lambda K: (K.row, K.col, K.data))((-lap.cotan_stiffness(V, F)).tocoo())
        off = i != j
        X = U0.copy()
        X[h] = targets
        S = np.zeros((len(V), 3, 3))
        e, e2 = V[i[off]] - V[j[off]], X[i[off]] - X[j[off]]
        np.add.at(S, i[off], -w[off, None, None] * e[:, :, None] * e2[:, None, :])
        assert (np.linalg.det(S) < 0).sum() >= 2, case.name


def test_a_map_task_on_a_mesh_that_is_not_a_disk_says_so():
    """The Check panel's mesh may be closed: the flattening tasks refuse it with a sentence,
    before any student code runs; a deformation task runs on any mesh."""
    from meshlap_core.exercises.check import check_on_mesh

    V, F = primitives.icosphere(1)
    with pytest.raises(MeshError, match="they need a disk"):
        check_on_mesh(STUDENTS / "right_vectorized.py", "tutte_map", V, F)
    V, F = primitives.grid(6, 5)
    V[:, 2] = 0.2 * np.sin(3 * V[:, 0]) * V[:, 1]
    shown = check_on_mesh(STUDENTS / "right_vectorized.py", "arap_step", V, F)
    assert shown.result.passed, shown.result.format_text()
    assert shown.difference is not None and len(shown.difference) == len(V)


def test_heat_reference_on_an_open_mesh_is_the_templates_neumann_step():
    V, F = primitives.grid(9, 7, 2.0)
    V[:, 2] = 0.1 * np.sin(3 * V[:, 0]) * V[:, 1]
    case = Case("grid", V, F, "an open mesh like the viewer's")
    ((_, args),) = geo.heat_calls(case)
    ref = geo.heat_reference(case, args)
    t = args[3] * mean_edge_length(V, F) ** 2
    np.testing.assert_allclose(geo.heat_steps(V, F, args[2], t), ref, atol=1e-10 * ref.max())


def test_an_unreachable_vertex_must_be_inf_in_the_answer_too():
    """A distance of inf (a component without the source) never widens the tolerance: a
    finite answer there fails, inf there passes, and the other vertices are still compared."""
    case = case_named("one_triangle")
    ref = np.array([0.0, 1.0, np.inf])
    assert COMPARE["array"](ref.copy(), ref, case, 1).ok
    assert not COMPARE["array"](np.array([0.0, 1.0, 5.0]), ref, case, 1).ok
    assert not COMPARE["array"](np.array([0.0, 1.5, np.inf]), ref, case, 1).ok


def test_every_diagnosis_has_a_sentence():
    keys = {m.key for t in TASKS.values() for m in candidates(t)}
    assert keys | {"slow_loop", "sized_by_faces"} <= set(DIAGNOSES)


def test_a_constant_factor_is_named_with_its_value():
    """An answer −2 × the expected on every mesh (no named mistake is −2): the factor is found
    and written as the report writes it."""
    task = TASKS["mean_curvature_normal"]
    failures = []
    for name in ("one_triangle", "obtuse_fan", "scaled"):
        case = case_named(name)
        ((label, args),) = task.calls(case)
        failures.append((case, label, args, -2.0 * task.reference(case, args)))
    assert diagnose(task, failures) is None
    assert constant_factor(task, failures) == -2.0


def test_an_answer_right_to_a_few_digits_only_is_named_so():
    """Values 1e-5 off (relative): no mistake, no constant factor, a few digits."""
    from meshlap_core.exercises.diagnose import few_digits

    task = TASKS["barycentric_areas"]
    failures = []
    for name in ("one_triangle", "scaled"):
        case = case_named(name)
        ((label, args),) = task.calls(case)
        ref = task.reference(case, args)
        wobble = 1.0 + 1e-5 * np.cos(np.arange(len(ref)))
        failures.append((case, label, args, ref * wobble))
    assert diagnose(task, failures) is None and constant_factor(task, failures) is None
    assert few_digits(task, failures)


def test_a_task_without_its_answers_has_failed():
    """A task whose calls were never answered (a forged "finished", a worker that stopped
    replying) fails with ``no_answer``: before, a task with 0 calls counted as passed."""
    task = TASKS["uniform_laplacian"]
    cases = {c.name: c for c in battery()}
    planned = [(c, "") for c in task.cases]
    result = evaluate(task, TaskRun(planned=planned), cases)
    assert result.status == "failed" and result.diagnosis == "no_answer", result.lines()


# ---- the battery is what it says (hand-computed) ---------------------------------------------


def test_battery_hand_values():
    tri = case_named("one_triangle")
    # area ½·1·0.8 = 0.4, a third to each vertex
    assert np.allclose(lap.vertex_areas(tri.V, tri.F, "barycentric"), 0.4 / 3)
    L = lap.uniform_laplacian(tri.F, 3).toarray()
    assert np.allclose(L, [[-1, 0.5, 0.5], [0.5, -1, 0.5], [0.5, 0.5, -1]])
    tet = case_named("tetrahedron")
    assert np.allclose(cv.angle_deficit(tet.V, tet.F), np.pi)  # 3 angles of π/3 each
    corner = case_named("cube_corner")
    assert np.isclose(cv.angle_deficit(corner.V, corner.F)[0], np.pi / 2)
    pair = case_named("non_delaunay_pair")
    assert lap.cotan_stiffness(pair.V, pair.F)[0, 1] < 0  # the edge's weight is negative
    fan = case_named("obtuse_fan")
    assert (cv.corner_angles(fan.V, fan.F) > np.pi / 2).any()
    assert not np.allclose(
        lap.vertex_areas(fan.V, fan.F, "voronoi"), lap.vertex_areas(fan.V, fan.F)
    )
    unref = case_named("unreferenced")
    assert unref.F.max() + 1 < len(unref.V)
    assert set(range(len(unref.V))) - set(unref.F.ravel()) == {3, len(unref.V) - 1}
    assert one_ring(case_named("boundary_fan").F, 6).boundary[0]


def test_the_battery_has_degenerate_thin_and_big_meshes():
    """A triangle of exactly zero area, a needle and a cap, and a mesh of 20,000 vertices or
    more (a dense n×n array there needs gigabytes); the reference is finite on all of them."""
    deg = case_named("degenerate")
    P = deg.V[deg.F]
    area = np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    assert (area == 0).sum() == 1 and set(degenerate_vertices(deg)) == {0, 1, 2}
    thin = np.degrees(cv.corner_angles(*(lambda c: (c.V, c.F))(case_named("slivers"))))
    assert thin.min() < 0.1 and thin.max() > 179.8
    assert len(case_named("huge").V) >= 20_000
    for name in ("degenerate", "slivers"):
        case = case_named(name)
        for task in TASKS.values():
            if name in task.cases:
                for _, args in task.calls(case):
                    ref = task.reference(case, args)
                    parts = ref if isinstance(ref, (list, tuple)) else [ref]
                    for part in parts:
                        values = part.data if hasattr(part, "nnz") else np.asarray(part, float)
                        assert np.isfinite(values).all(), (task.name, name)


def test_every_battery_mesh_is_oriented_outwards():
    for case in battery():
        if case.closed:
            P = case.V[case.F]
            vol = np.einsum("ij,ij->i", P[:, 0], np.cross(P[:, 1], P[:, 2])).sum() / 6
            assert vol > 0, case.name


# ---- scale-aware tolerances ----------------------------------------------------------------


@pytest.mark.parametrize("name", ["small_sphere", "scaled"])
def test_tolerance_follows_the_scale(name):
    case = case_named(name)
    ref = lap.vertex_areas(case.V, case.F, "voronoi")
    assert COMPARE["array"](ref * (1 + 1e-10), ref, case, 2).ok
    assert not COMPARE["array"](ref * (1 + 1e-5), ref, case, 2).ok


def test_an_all_zero_answer_is_compared_at_the_natural_unit():
    case = case_named("scaled")
    ref = np.zeros(len(case.V))
    assert COMPARE["array"](ref + 1e-12, ref, case, 0).ok
    assert not COMPARE["array"](ref + 1e-3, ref, case, 0).ok


def test_a_ring_may_start_anywhere_only_when_closed():
    case = case_named("obtuse_fan")  # vertex 0 interior, the others on the boundary
    ref = TASKS["one_ring"].reference(case, ())
    rolled = [np.roll(r, 1) for r in ref]
    result = COMPARE["ring"](rolled, ref, case, 0)
    assert not result.ok and result.vertex != 0
    rolled_center = [np.roll(ref[0], 2), *ref[1:]]
    assert COMPARE["ring"](rolled_center, ref, case, 0).ok


# ---- the template ----------------------------------------------------------------------------


def test_template_has_one_stub_per_task_and_no_solution(tmp_path):
    text = template()
    tree = ast.parse(text)
    funcs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert list(funcs) == list(EXERCISE_TASKS)
    for f in funcs.values():
        doc = ast.get_docstring(f)
        assert doc and ("Returns" in doc or "returns" in doc.lower()), f.name
        body = [s for s in f.body if not isinstance(s, ast.Expr)]
        assert len(body) == 1 and isinstance(body[0], ast.Raise), f.name
    path = tmp_path / "exercises.py"
    path.write_text(text)
    result = check_file(path, ["uniform_laplacian", "eigenbasis"])
    assert [t.status for t in result.tasks] == ["not_implemented", "not_implemented"]


def test_adding_a_task_is_one_declaration():
    """Everything the checker offers comes from the task table: the names, the template's
    stubs, the tasks each one uses."""
    assert tuple(TASKS) == EXERCISE_TASKS
    text = template()
    for task in TASKS.values():
        assert task.stub.strip() in text and task.speed_case in task.cases
        assert set(task.uses) <= set(TASKS)


# ---- hostile files: stopped and reported, the checker survives --------------------------------


@pytest.mark.parametrize("sandbox", ["auto", "process"])
@pytest.mark.parametrize(
    ("name", "status"),
    [("hostile_loop", "timeout"), ("hostile_memory", "memory"), ("hostile_crash", "crashed")],
)
def test_a_hostile_task_is_stopped_and_the_next_one_still_runs(name, status, sandbox):
    result = check_file(
        STUDENTS / f"{name}.py", ["uniform_laplacian", "barycentric_areas"],
        timeout=HOSTILE_TIMEOUT, sandbox=sandbox, speed=False,
    )  # fmt: skip
    assert result["uniform_laplacian"].status == status
    assert result["barycentric_areas"].passed


HOSTILE_MAPS = """
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def lscm(V, F, pins, pin_uv):
    while True:
        pass


def arap_step(V, F, U, handles, targets):
    return np.ones((10**6, 10**4))  # 80 GB


def tutte_map(V, F, loop, weights):
    n = len(V)
    if weights == "uniform":
        e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        e = np.unique(e, axis=0)
        i, j, w = e[:, 0], e[:, 1], np.ones(len(e))
    else:  # corner c's half cotangent weighs the edge opposite it
        i, j = F[:, [1, 2, 0]].T.ravel(), F[:, [2, 0, 1]].T.ravel()
        a, b = V[i] - V[F.T.ravel()], V[j] - V[F.T.ravel()]
        w = 0.5 * np.einsum("ij,ij->i", a, b) / np.linalg.norm(np.cross(a, b), axis=1)
    W = sp.coo_matrix((w, (i, j)), shape=(n, n)).tocsr()
    W = W + W.T
    K = (sp.diags(np.asarray(W.sum(axis=1)).ravel()) - W).tocsr()
    seg = np.linalg.norm(V[np.roll(loop, -1)] - V[loop], axis=1)
    t = 2 * np.pi * np.concatenate([[0.0], np.cumsum(seg[:-1])]) / seg.sum()
    uv = np.zeros((n, 2))
    uv[loop] = np.stack([np.cos(t), np.sin(t)], axis=1)
    free = np.setdiff1d(np.arange(n), loop)
    uv[free] = spla.spsolve(K[free][:, free].tocsc(), -(K[free][:, loop] @ uv[loop]))
    return uv
"""


@pytest.mark.parametrize("sandbox", ["auto", "process"])
def test_a_hostile_deform_or_map_task_is_stopped_and_the_next_one_still_runs(tmp_path, sandbox):
    """The harness's limits hold for the new tasks as for the others: an endless LSCM is
    stopped at the time limit, an 80 GB ARAP step at the memory limit, and the file's right
    Tutte map still passes."""
    path = tmp_path / "maps.py"
    path.write_text(HOSTILE_MAPS)
    result = check_file(path, ["lscm", "arap_step", "tutte_map"], timeout=HOSTILE_TIMEOUT,
                        sandbox=sandbox, speed=False)  # fmt: skip
    assert result["lscm"].status == "timeout"
    assert result["arap_step"].status == "memory"
    assert result["tutte_map"].passed, result["tutte_map"].lines()


def test_the_workers_own_start_up_is_not_the_students_time():
    """A spawned worker takes about a second (several on a loaded machine) to import numpy,
    scipy and meshlap before the student's file: with a task limit shorter than that, a right
    file still passes (the limit starts at the worker's ``ready``), while an infinite loop is
    still stopped at that limit."""
    limit = 0.3  # below any worker's start-up (spawn, numpy, scipy, meshlap, the battery)
    result = check_file(STUDENTS / "right_vectorized.py", ["uniform_laplacian"], timeout=limit)
    assert result["uniform_laplacian"].passed, result["uniform_laplacian"].message
    looped = check_file(STUDENTS / "hostile_loop.py", ["uniform_laplacian"], timeout=limit)
    assert looped["uniform_laplacian"].status == "timeout"


def test_a_students_exception_shows_their_frames_only():
    result = check_file(STUDENTS / "hostile_raise.py", ["uniform_laplacian"])
    tb = result["uniform_laplacian"].traceback
    assert result["uniform_laplacian"].status == "error"
    assert "hostile_raise.py" in tb and "_degrees" in tb and "IndexError" in tb
    assert (
        "meshlap_core" not in tb
        and "multiprocessing" not in tb
        and "numpy" not in tb.split("IndexError")[0].replace("np.", "")
    )


def test_a_file_importing_meshlap_is_refused_not_passed(checked):
    """Returning meshlap's own answer must not pass: an import of meshlap is refused before
    the file runs (every task, with the line), and a name built at run time is refused when
    imported (that task's error, the student's line); the file's other tasks still run."""
    r = checked("cheat_import")
    assert [t.status for t in r.tasks] == ["import_error"] * 2 and not r.passed
    for t in r.tasks:
        assert t.message.startswith("line 3:") and "may not import meshlap" in t.message
    r = checked("cheat_import_hidden")
    for task in ("cotan_laplacian", "barycentric_areas"):
        assert r[task].status == "error" and "may not import meshlap" in r[task].traceback
        assert "cheat_import_hidden.py" in r[task].traceback
    assert r["voronoi_areas"].status == "failed"  # numpy still works: only meshlap is refused


def test_the_import_scan_reads_every_form_and_nothing_else(tmp_path):
    cases = {
        "import meshlap_core\n": 1,
        "x = 1\ndef f():\n    from meshlap_app.state import check\n": 3,
        "import importlib\nm = importlib.import_module('meshlap_core.laplacian')\n": 2,
        "import meshlap\n": 1,
        "import numpy as np\nimport meshlapx\nfrom . import meshlap_core\n": None,
        "def broken(:\n": None,  # importing it reports the syntax error
    }
    for i, (text, line) in enumerate(cases.items()):
        path = tmp_path / f"f{i}.py"
        path.write_text(text)
        got = guard.scan(str(path))
        assert (got is None) if line is None else got.startswith(f"line {line}:"), text


def test_a_file_that_does_not_parse_is_reported_for_every_task(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("def uniform_laplacian(V, F)\n    return None\n")
    result = check_file(bad, ["uniform_laplacian", "one_ring"])
    assert [t.status for t in result.tasks] == ["import_error", "import_error"]
    assert "SyntaxError" in result.tasks[0].traceback


# ---- notebook rendering ----------------------------------------------------------------------


def test_result_renders_in_a_notebook(checked):
    result = checked("wrong_cotan_full")
    page = result._repr_html_()
    assert "<table" in page and "cotan_laplacian" in page and "cot instead of cot/2" in page
    png = result._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    import io

    from PIL import Image

    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)
    red = (img[..., 0] > 150) & (img[..., 1] < 90) & (img[..., 2] < 90)
    assert red.sum() > 100  # the failed task's cell and the difference bars are drawn in red


def _children() -> list[int]:
    """This process's live children (from /proc)."""
    import glob

    out = []
    for f in glob.glob(f"/proc/{os.getpid()}/task/*/children"):
        with open(f) as fh:
            out += [int(p) for p in fh.read().split()]
    return out


def test_cancel_stops_a_running_check_and_its_worker():
    import threading

    from meshlap_core.errors import Cancelled
    from meshlap_core.exercises.check import check_on_mesh

    case = case_named("small_sphere")
    before = set(_children())  # a fork server an earlier test started stays: not this check's
    stop = threading.Event()
    timer = threading.Timer(2.0, stop.set)
    timer.start()
    with pytest.raises(Cancelled):
        check_on_mesh(
            STUDENTS / "hostile_loop.py", "uniform_laplacian", case.V, case.F, cancel=stop
        )
    timer.cancel()
    assert not set(_children()) - before
