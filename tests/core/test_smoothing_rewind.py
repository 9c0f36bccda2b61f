"""Going back in a smoothing run: :meth:`meshlap_core.smoothing.Smoother.rewind` (positions
the caller kept) and the window's kept positions (:class:`meshlap_app.state.kept_steps.
KeptSteps`, bounded in bytes)."""

from __future__ import annotations

import numpy as np
import pytest
from meshlap_app.state.kept_steps import KEPT_BYTES, MAX_KEPT, KeptSteps, kept_for

from meshlap_core import smoothing as S
from meshlap_core.errors import MeshError
from meshlap_core.primitives import bumpy_sphere, grid


@pytest.mark.parametrize(
    ("method", "laplacian", "lam", "extra"),
    [
        ("implicit", "cotan", 1e-3, {"mass_update": "recompute"}),
        ("implicit", "uniform", 0.5, {"fix_boundary": True}),
        ("explicit", "uniform", 0.5, {}),
        ("taubin", "cotan", 1e-4, {}),
    ],
)
def test_a_run_rewound_then_stepped_again_retraces_the_same_steps(method, laplacian, lam, extra):
    """Invariant: the steps after a rewind to iteration k are the steps the uninterrupted run
    took from k (the same positions, the same figures), also with the mass recomputed each
    step and with pinned boundary vertices."""
    V, F = grid(8, 7) if extra.get("fix_boundary") else bumpy_sphere(2)
    if extra.get("fix_boundary"):
        V = V + 0.02 * np.sin(9 * V[:, [1, 0, 2]])  # a wavy sheet
    s = S.Smoother(V, F, method, laplacian, lam, warn=False, **extra)
    path = [np.array(s.V)]
    for _ in range(5):
        s.step()
        path.append(np.array(s.V))
    figures = [dict(h) for h in s.history]
    s.rewind(path[2], 2)
    assert s.iteration == 2 and np.array_equal(s.V, path[2])
    assert [h["iteration"] for h in s.history] == [0, 1, 2]
    for k in (3, 4, 5):
        s.step()
        np.testing.assert_allclose(s.V, path[k], rtol=0, atol=1e-12)
        assert s.history[-1]["step_rms"] == pytest.approx(figures[k]["step_rms"], abs=1e-14)
    s.rewind(s.V0, 0)  # the input: as reset
    assert s.iteration == 0 and np.array_equal(s.V, V) and len(s.history) == 1


def test_rewind_forgets_a_divergence_and_keeps_lambda():
    V, F = bumpy_sphere(2)
    s = S.Smoother(V, F, "explicit", "uniform", 1.9, warn=False)
    good = [np.array(s.V)]
    while not s.diverged and s.iteration < 500:
        s.step()
        good.append(np.array(s.V))
    assert s.diverged
    k = s.iteration - 1
    s.rewind(good[k], k)
    assert not s.diverged and s.iteration == k and s.lam == 1.9


@pytest.mark.parametrize(
    ("V", "iteration", "named"),
    [
        ("shape", 1, "V"),
        ("nan", 1, "V"),
        ("ok", 3, "iteration"),  # not reached yet
        ("ok", -1, "iteration"),
        ("ok", 1.0, "iteration"),
        ("ok", True, "iteration"),
    ],
)
def test_rewind_refuses_bad_positions_and_iterations_changing_nothing(V, iteration, named):
    W, F = bumpy_sphere(1)
    s = S.Smoother(W, F, "implicit", "uniform", 0.5)
    s.run(2)
    before = np.array(s.V)
    P = {"shape": W[:-1], "nan": np.where(W == W[0, 0], np.nan, W), "ok": W}[V]
    with pytest.raises(MeshError) as exc:
        s.rewind(P, iteration)
    assert exc.value.source == named
    assert s.iteration == 2 and np.array_equal(s.V, before)


def test_rewind_does_not_keep_the_callers_array():
    V, F = bumpy_sphere(1)
    s = S.Smoother(V, F, "implicit", "uniform", 0.5)
    s.step()
    P = np.array(s.V)
    s.step()
    s.rewind(P, 1)
    P[:] = 0.0
    assert np.abs(s.V).max() > 0


# ----------------------------------------------------------------------------- kept steps
def test_kept_steps_are_bounded_by_bytes_and_count():
    assert kept_for(10) == MAX_KEPT  # a tiny mesh: the count bounds it
    n = 691_858  # the scan: 16.6 MB a step
    assert kept_for(n) == KEPT_BYTES // (24 * n) == 8
    assert kept_for(10**9) == 2  # never fewer than the two a step back and a pause need


def test_kept_steps_step_back_and_forget_what_follows():
    V, F = bumpy_sphere(1)
    s = S.Smoother(V, F, "implicit", "uniform", 0.5)
    kept = KeptSteps(len(V))
    kept.capacity = 3  # keep three steps
    path = {0: np.array(s.V)}
    for _ in range(5):
        s.step()
        kept.record(s.iteration, s.V)
        path[s.iteration] = np.array(s.V)
    assert kept.oldest == 3  # iterations 3, 4, 5 kept
    assert kept.rewind(s, 4) == 4 and np.array_equal(s.V, path[4])
    with pytest.raises(MeshError, match="not reached yet"):
        kept.rewind(s, 5)  # forgotten with the step back: not the current run's any more
    with pytest.raises(MeshError, match="last 3 steps are kept"):
        kept.rewind(s, 2)
    assert s.iteration == 4  # a refused rewind changes nothing
    assert kept.rewind(s, 0) == 0 and np.array_equal(s.V, V)  # the input: always there
    s.step()
    kept.record(s.iteration, s.V)  # a new run from the input: iteration 1 again
    assert kept.oldest == 1 and np.array_equal(s.V, path[1])
