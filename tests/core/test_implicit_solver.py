"""The implicit step's solves: CHOLMOD (or the bundled back end) answers first, a cholespy
factorization in a helper process takes over (:mod:`meshlap_core.smoothing.implicit_solver`,
:mod:`meshlap_core.linalg.remote_cholesky`). Whichever factorization answers, the steps are the
same; the hand-over mid-run is seamless; the reported choice is the right one; a helper that is
closed, refused or killed never changes the result."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp

from meshlap_core import smoothing as S
from meshlap_core.linalg.remote_cholesky import HelperError, RemoteCholesky
from meshlap_core.primitives import bumpy_sphere, grid
from meshlap_core.smoothing import implicit_solver as IS

TOL = 1e-12  # same steps, relative to the mesh's size


def _bent_grid():
    V, F = grid(9, 7)
    return V + 0.02 * np.sin(5 * V[:, [1, 2, 0]]), F


def _pair(V, F, **kw):
    """The same smoother twice: one factorization in this process, and one handing over."""
    direct = S.Smoother(V, F, "implicit", "cotan", 0.01, implicit_solver="direct", **kw)
    helped = S.Smoother(V, F, "implicit", "cotan", 0.01, implicit_solver="handover", **kw)
    return direct, helped


def _close(a, b, scale):
    assert np.abs(a - b).max() <= TOL * scale


# ---------------------------------------------------------------------- the helper process
def test_helper_solves_a_hand_computed_scaled_system():
    """``D A D z = y + c``: A = [[2, -1], [-1, 2]], D = diag(1, 2), y = (1, 0), c = (0, 1):
    D A D = [[2, -2], [-2, 8]], right side (1, 1): z = (5/6, 1/3) (by hand)."""
    A = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    helper = RemoteCholesky(A, 1, shift=np.array([[0.0], [1.0]]), scale=np.array([1.0, 2.0]))
    try:
        assert helper.wait_ready(60)
        helper.submit(np.array([[1.0], [0.0]]), add=True)
        np.testing.assert_allclose(helper.result()[:, 0], [5 / 6, 1 / 3], rtol=1e-14)
        helper.submit(None)  # from its own answer, no shift: D A D z' = (5/6, 1/3)
        want = np.linalg.solve([[2.0, -2.0], [-2.0, 8.0]], [5 / 6, 1 / 3])
        np.testing.assert_allclose(helper.result()[:, 0], want, rtol=1e-14)
        assert len(helper.solve_s) == 2 and helper.factor_s is not None
    finally:
        helper.close()


def test_helper_refuses_an_indefinite_matrix_and_says_why():
    A = sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]]))  # eigenvalues 3 and -1
    helper = RemoteCholesky(A, 3)
    try:
        assert not helper.wait_ready(60)
        assert helper.state == "failed" and "positive definite" in helper.error
        with pytest.raises(HelperError, match="positive definite"):
            helper.submit(np.zeros((2, 3)))
    finally:
        helper.close()


def test_closing_a_helper_while_it_factorizes_ends_it_at_once():
    n = 20000
    A = sp.diags([np.full(n - 1, -1.0), np.full(n, 4.0), np.full(n - 1, -1.0)], [-1, 0, 1])
    helper = RemoteCholesky(A.tocsr(), 3)
    process = helper.process
    helper.close()  # (it is still starting or factorizing: it never said ready)
    assert process.wait(timeout=10) is not None
    assert helper.state == "closed" and not helper.alive
    with pytest.raises(HelperError):
        helper.submit(np.zeros((n, 3)))


def test_helper_never_imports_a_module_from_the_working_folder(tmp_path, monkeypatch):
    """A folder named ``meshlap_core`` where the command runs is not imported by the helper
    (``python -P``): it starts and factorizes as anywhere else."""
    fake = tmp_path / "meshlap_core"
    (fake / "linalg").mkdir(parents=True)
    (fake / "__init__.py").write_text("raise SystemExit(3)\n")
    (fake / "linalg" / "__init__.py").write_text("")
    (fake / "linalg" / "remote_cholesky.py").write_text("raise SystemExit(3)\n")
    monkeypatch.chdir(tmp_path)
    helper = RemoteCholesky(sp.identity(4, format="csr") * 2.0, 3)
    try:
        assert helper.wait_ready(60), helper.error
    finally:
        helper.close()


# ---------------------------------------------------------------------- the choice
def test_plan_hand_computed_choices():
    assert IS.plan("cholmod", 700_000, None)[0] is True  # open-ended: hand over
    assert IS.plan("cholmod", 700_000, 50)[0] is None  # decided once the times are known
    assert IS.plan("cholmod", 700_000, 1)[0] is False  # one step: CHOLMOD's factor answers
    assert IS.plan("cholmod", 1000, None)[0] is False  # CHOLMOD forced on a small system
    assert IS.plan("cholespy", 700_000, None)[0] is False
    assert IS.plan("superlu", 700_000, None)[0] is False
    assert IS.plan("cholmod", 700_000, None, "direct")[0] is False
    assert IS.plan("cholespy", 10, 3, "handover")[0] is True


def test_worth_handover_compares_the_steps_left_with_the_helpers_factorization():
    # 40 steps of 0.27 s = 10.8 s against 2.5 x 4 s = 10 s: worth it; 30 steps (8.1 s): not
    ok, why = IS.worth_handover(40, factor_s=4.0, solve_s=0.27)
    assert ok and "40 more steps" in why
    ok, why = IS.worth_handover(30, factor_s=4.0, solve_s=0.27)
    assert not ok and "CHOLMOD answers all" in why


def test_the_measured_times_decide_a_run_of_known_length(spd_backend, monkeypatch):
    V, F = _bent_grid()
    monkeypatch.setattr(IS, "CHOLMOD_MIN_N", 0)  # (the test mesh is small)
    backend = S.Smoother(V, F, "implicit", "cotan", 0.01, steps=5)
    backend.step()
    first = backend.solver_report()["first"]
    if first != "cholmod":  # the bundled back end: its own factorization answers
        assert backend.solver_report()["helper"] is None
        return
    monkeypatch.setattr(IS, "HANDOVER_RATIO", 1e9)  # the helper would never be ready in time
    short = S.Smoother(V, F, "implicit", "cotan", 0.01, steps=5)
    short.step()
    rep = short.solver_report()
    assert rep["helper"] is None and "CHOLMOD answers all" in rep["reason"]
    monkeypatch.setattr(IS, "HANDOVER_RATIO", 0.0)  # it is always worth it
    long = S.Smoother(V, F, "implicit", "cotan", 0.01, steps=5)
    long.step()
    assert long.solver_report()["helper"] in ("factorizing", "ready")
    assert "takes over once ready" in long.solver_report()["reason"]
    long.close()


# ---------------------------------------------------------------------- the same steps
@pytest.mark.parametrize("options", [{}, {"preserve_volume": True}])
def test_steps_are_the_same_whichever_factorization_answers(spd_backend, options):
    V, F = bumpy_sphere(3)
    V = V + 0.01 * np.sin(9 * V[:, [1, 2, 0]])
    direct, helped = _pair(V, F, **options)
    scale = np.abs(V).max()
    try:
        for _ in range(3):  # the helper is starting: the in-process factor answers
            _close(direct.step(), helped.step(), scale)
        assert helped.wait_handover(60)
        for _ in range(6):  # the hand-over, then the helper's answers (each started ahead)
            _close(direct.step(), helped.step(), scale)
        rep = helped.solver_report()
        assert rep["answering"] == "cholespy (helper)"
        assert rep["handover_iteration"] == 4  # the first step after it was ready
        assert rep["first"] == spd_backend
        assert direct.solver_report()["helper"] is None
        for h_d, h_h in zip(direct.history, helped.history, strict=True):
            assert h_d["iteration"] == h_h["iteration"]
            assert abs(h_d["drift_rms"] - h_h["drift_rms"]) <= TOL * scale
    finally:
        helped.close()


def test_pinned_vertices_hand_over_with_their_pull(spd_backend):
    V, F = _bent_grid()
    direct, helped = _pair(V, F, fix_boundary=True)
    try:
        helped.prepare()  # the helper starts with the factorization (the window's way)
        assert helped.solver_report()["helper"] in ("factorizing", "ready")
        assert helped.wait_handover(60)
        for _ in range(5):
            _close(direct.step(), helped.step(), 1.0)
        assert helped.solver_report()["handover_iteration"] == 1
        pinned = direct.pinned
        assert pinned.any()
        np.testing.assert_array_equal(helped.V[pinned], V[pinned])  # the pinned stay exactly
    finally:
        helped.close()


def test_reset_and_a_new_lambda_mid_run_after_the_hand_over(spd_backend):
    V, F = _bent_grid()
    direct, helped = _pair(V, F)
    try:
        helped.step()
        direct.step()
        assert helped.wait_handover(60)
        for _ in range(3):
            _close(direct.step(), helped.step(), 1.0)
        # a solve was started ahead from step 4: a reset must not hand it out
        direct.reset()
        helped.reset()
        for _ in range(2):
            _close(direct.step(), helped.step(), 1.0)
        direct.set_lam(0.05)
        helped.set_lam(0.05)  # a new system: the old helper ends, a new one starts
        for _ in range(2):
            _close(direct.step(), helped.step(), 1.0)
        assert helped.n_factorizations == direct.n_factorizations == 2
        assert helped.wait_handover(60)
        for _ in range(2):
            _close(direct.step(), helped.step(), 1.0)
        assert helped.solver_report()["answering"] == "cholespy (helper)"
    finally:
        helped.close()


def test_a_helper_killed_after_taking_over_is_replaced_by_a_factorization_here(spd_backend):
    V, F = _bent_grid()
    direct, helped = _pair(V, F)
    try:
        helped.step()
        direct.step()
        assert helped.wait_handover(60)
        _close(direct.step(), helped.step(), 1.0)  # answered by the helper
        helped._solver.helper.process.kill()
        helped._solver.helper.process.wait(timeout=10)
        for _ in range(3):
            _close(direct.step(), helped.step(), 1.0)
        rep = helped.solver_report()
        assert rep["answering"] == spd_backend and "factorized again" in rep["reason"]
    finally:
        helped.close()


def test_close_during_the_background_factorization_keeps_stepping_right(spd_backend):
    V, F = _bent_grid()
    direct, helped = _pair(V, F)
    helped.prepare()
    process = helped._solver.helper.process
    helped.close()  # (still starting: the factorization never finished)
    assert process.wait(timeout=10) is not None
    for _ in range(3):  # factorized again in this process
        _close(direct.step(), helped.step(), 1.0)
    assert helped.solver_report()["helper"] in (None, "factorizing", "ready")
    helped.close()


def test_recomputed_mass_never_hands_over(spd_backend):
    V, F = bumpy_sphere(2)
    s = S.Smoother(
        V, F, "implicit", "cotan", 0.01, mass_update="recompute", implicit_solver="handover"
    )
    s.run(2)
    rep = s.solver_report()
    assert rep["helper"] is None and "asked for" in rep["reason"]
    assert s.n_factorizations == 2


def test_explicit_steps_report_no_linear_system():
    s = S.Smoother(*bumpy_sphere(1), "explicit", "uniform", 0.5)
    s.step()
    assert s.solver_report()["answering"] is None
    assert s.solver_line() == "no linear system"


# ---------------------------------------------------------------------- where it shows
def test_meshlap_smooth_json_reports_the_choice_and_why(tmp_path, spd_backend):
    V, F = bumpy_sphere(2)
    path = tmp_path / "m.obj"
    from meshlap_core.io import save_mesh

    save_mesh(path, V, F)
    out = subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", "smooth", str(path), "--method", "implicit",
         "--iters", "3", "--json"],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    solver = json.loads(out.stdout)["solver"]
    assert solver["answering"] == solver["first"] == spd_backend
    assert solver["helper"] is None and solver["handover_iteration"] is None
    want = IS.plan(spd_backend, len(V), 3)[1]  # small: no helper, said why
    assert solver["reason"] == want
    text = subprocess.run(
        [sys.executable, "-m", "meshlap_core.cli", "smooth", str(path), "--method", "implicit",
         "--iters", "3"],
        capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    assert f"solver      {spd_backend}: {want}" in text


def test_the_smoothing_panels_solver_line():
    from meshlap_app.state.smoothing import SmoothingState

    V, F = bumpy_sphere(2)
    st = SmoothingState(method="implicit", laplacian="cotan", lam=0.01)
    st.rebuild(V, F)
    st.step()
    line = st.figures()["solver"]
    assert line == st.smoother.solver_line() and line.startswith(("cholespy", "CHOLMOD"))
    st.configure(V, F, method="explicit")
    assert st.figures()["solver"] is None
