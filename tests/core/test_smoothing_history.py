"""The smoothing stepper's history figures (:mod:`meshlap_core.smoothing.history`): the
displacement sums of one blocked pass against plain numpy, entries kept within a limit or
sampled."""

from __future__ import annotations

import numpy as np
import pytest

from meshlap_core.primitives import bumpy_sphere
from meshlap_core.smoothing import Smoother
from meshlap_core.smoothing import history as H


@pytest.mark.parametrize("chunk", [1, 5, 16384])
def test_displacement_sums_are_plain_numpys(monkeypatch, chunk):
    monkeypatch.setattr(H, "ROWS_CHUNK", chunk)
    rng = np.random.default_rng(3)
    x, x0, old, ref = rng.standard_normal((4, 23, 3))
    d2 = np.sum((x - old) ** 2, axis=1)
    want = (np.sum((x - x0) ** 2), d2.sum(), d2.max(), np.sum((x - ref) ** 2))
    np.testing.assert_allclose(H.displacement_sums(x, x0, old, ref), want, rtol=1e-13)
    assert H.displacement_sums(x, x0, None, None)[1:] == (0.0, 0.0, 0.0)


def test_hand_computed_entry_of_a_unit_move():
    """Two vertices, each moved by (0, 0, 1) from the start and by (0, 0, 2) from the input:
    step RMS = max = 1, drift RMS = 2."""
    x0 = np.array([[0.0, 0, 0], [1, 0, 0]])
    old = np.array([[0.0, 0, 1], [1, 0, 1]])
    x = np.array([[0.0, 0, 2], [1, 0, 2]])
    sums = H.displacement_sums(x, x0, old, None)
    e = H.step_entry(3, 0.002, x, sums, stepped=True, faces=None, volume0=None, reference=False)
    assert (e["iteration"], e["time_ms"], e["step_rms"], e["step_max"]) == (3, 2.0, 1.0, 1.0)
    assert e["drift_rms"] == 2.0 and e["volume"] is None and "rmse" not in e


def test_kept_entries_within_a_limit_and_sampled():
    h: list[dict] = [{"iteration": 0}]
    for i in range(1, 10):
        H.keep(h, {"iteration": i}, 4, None, 1)
    assert [e["iteration"] for e in h] == [0, 7, 8, 9]
    h, stride = [{"iteration": 0}], 1
    for i in range(1, 20):
        stride = H.keep(h, {"iteration": i}, None, 5, stride)
    assert stride == 8 and [e["iteration"] for e in h] == [0, 8, 16, 19]


def test_stepper_history_matches_its_positions():
    V, F = bumpy_sphere(2)
    s = Smoother(V, F, "explicit", "uniform", 0.3, reference=V)
    before = s.V.copy()
    s.step()
    e = s.history[-1]
    d = np.linalg.norm(s.V - before, axis=1)
    assert e["step_rms"] == pytest.approx(np.sqrt(np.mean(d**2)), rel=1e-13)
    assert e["step_max"] == pytest.approx(d.max(), rel=1e-13)
    assert e["rmse"] == pytest.approx(np.sqrt(np.mean(np.sum((s.V - V) ** 2, axis=1))), rel=1e-13)
