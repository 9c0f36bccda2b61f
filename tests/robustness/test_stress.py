"""Stress (issue 8): the viewer's state objects under long use, and a 2 M-face mesh.

Headless: the viewer's panels keep their state in plain objects (``meshlap_app.state``:
``MeshState``, ``SmoothingState``, ``SpectralState``) that these tests drive without polyscope.
Memory is measured, never time: ``tracemalloc`` counts what Python and NumPy allocate (and
still hold), ``/proc/self/statm`` / ``getrusage`` the resident size.
"""

from __future__ import annotations

import faulthandler
import gc
import json
import os
import subprocess
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.io import save_mesh
from tests.support import hostile

MB = 2**20


@pytest.fixture(autouse=True)
def watchdog():
    faulthandler.dump_traceback_later(600, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def rss_mb() -> float:
    """Resident set size of this process now (Linux), else the peak so far."""
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
        return pages * os.sysconf("SC_PAGE_SIZE") / MB
    except (OSError, ValueError, IndexError):
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def held_mb(run) -> tuple[float, float]:
    """Memory still held after ``run()`` (tracemalloc, after a collection) and RSS growth."""
    gc.collect()
    tracemalloc.start()
    before, rss0 = tracemalloc.get_traced_memory()[0], rss_mb()
    run()
    gc.collect()
    after = tracemalloc.get_traced_memory()[0]
    tracemalloc.stop()
    return (after - before) / MB, rss_mb() - rss0


# ------------------------------------------------------------------------ the Mesh panel


def test_mesh_panel_keeps_the_previous_mesh_on_every_bad_file(tmp_path):
    """``MeshState.load`` of each hostile file fails, names the file, keeps the mesh shown."""
    from meshlap_app.state import MeshState

    good = tmp_path / "good.obj"
    save_mesh(good, *primitives.torus_mesh(12, 6))
    state = MeshState()
    assert state.load(good)
    V, F, version, info = state.V, state.F, state.version, state.info
    for case in (*hostile.ERRORS, *hostile.SPECIAL):
        bad = case.build(tmp_path)
        assert state.load(bad) is False, case.name
        assert bad.name in state.error, (case.name, state.error)
        assert any(w in state.error.lower() for w in case.words), (case.name, state.error)
        assert state.V is V and state.F is F and state.info is info
        assert state.version == version
    assert state.load(good) and state.version == version + 1 and state.error == ""


def test_mesh_panel_loads_every_hostile_but_valid_file(tmp_path):
    from meshlap_app.state import CurvatureState, MeshState

    state, curv = MeshState(), CurvatureState()
    for case in hostile.LOADABLE:
        path = case.build(tmp_path)
        assert state.load(path), (case.name, state.error)
        assert (len(state.V), len(state.F)) == (case.n_vertices, case.n_faces)
        assert curv.update(state)
        for name, values in curv.fields.items():
            assert np.isfinite(values).all(), (case.name, name)
            lo, hi = curv.color_range(name)
            assert np.isfinite([lo, hi]).all() and lo < hi


# ------------------------------------------------------------------------ smoothing panel


def _panel(method: str, laplacian: str, lam: float):
    from meshlap_app.state.smoothing import SmoothingState

    V, F = primitives.bumpy_sphere(3)
    state = SmoothingState(method=method, laplacian=laplacian, lam=lam)
    assert state.rebuild(V, F), state.error
    for _ in range(200):  # warm-up: caches, the factorization, the first history entries
        assert state.step()
    return state


@pytest.mark.slow
@pytest.mark.parametrize(
    ("method", "laplacian", "lam"),
    [("explicit", "uniform", 0.5), ("implicit", "cotan", 1e-3), ("taubin", "uniform", 0.5)],
)
def test_smoothing_panel_steps_10000_times(method, laplacian, lam):
    """10,000 live steps: the positions stay finite, the resident size stays put (RSS, a
    generous bound; the exact per-step account is the next test)."""
    state = _panel(method, laplacian, lam)
    gc.collect()
    rss0 = rss_mb()
    for _ in range(10_000):
        state.step()
    gc.collect()
    assert rss_mb() - rss0 < 50
    assert state.smoother.iteration == 10_200
    assert np.isfinite(state.V).all()
    assert state.figures()["iteration"] == 10_200


def test_smoothing_panel_memory_does_not_grow_with_the_step_count():
    """What the stepping holds on to, counted exactly (tracemalloc): nothing per step.

    A bounded history replaces its entries, so the memory traced after N steps includes the
    live entries made during the run; the leak test compares two equal windows instead."""
    state = _panel("taubin", "uniform", 0.5)
    for _ in range(1000):  # fill a bounded history, if there is one
        state.step()
    steps = 2000
    gc.collect()
    tracemalloc.start()
    for _ in range(steps):
        state.step()
    gc.collect()
    first = tracemalloc.get_traced_memory()[0]
    for _ in range(steps):
        state.step()
    gc.collect()
    second = tracemalloc.get_traced_memory()[0]
    tracemalloc.stop()
    grown = (second - first) / steps
    assert grown < 20, f"{grown:.0f} bytes held per step"


def test_smoother_history_limit_bounds_memory():
    """The core stepper's ``history_limit`` keeps the input entry and the latest ones."""
    from meshlap_core.smoothing import Smoother

    V, F = primitives.bumpy_sphere(2)
    s = Smoother(V, F, "implicit", "uniform", 1.0, history_limit=50)
    s.run(500)
    assert len(s.history) == 50
    assert s.history[0]["iteration"] == 0 and s.history[-1]["iteration"] == 500
    assert [h["iteration"] for h in s.history[1:]] == list(range(452, 501))
    held, _ = held_mb(lambda: s.run(1500))
    assert held * MB / 1500 < 20 and len(s.history) == 50
    unbounded = Smoother(V, F, "implicit", "uniform", 1.0)
    held, _ = held_mb(lambda: unbounded.run(1500))
    assert held * MB / 1500 > 200  # each kept entry costs: what the limit is for


# ------------------------------------------------------------------------ spectral panel


@pytest.mark.slow
def test_spectral_panel_k_slider_through_its_range_without_leaks(tmp_path, monkeypatch):
    """Slide k from 1 to k_max and back, then at random, 6 times: nothing accumulates, and
    the reconstruction at each k does not depend on the path the slider took."""
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path))
    from meshlap_app.state.spectral import SpectralState

    V, F = primitives.bumpy_sphere(3)
    state = SpectralState(k_request=60)
    state.start(V, F, background=False)
    assert state.error == "" and state.basis is not None
    k_max = state.basis.k_max
    rng = np.random.default_rng(0)

    def sweep():
        for k in [
            *range(1, k_max + 1),
            *range(k_max, 0, -1),
            *rng.integers(1, k_max + 1, 200).tolist(),
        ]:
            state.set_k(int(k))

    sweep()
    state.set_k(k_max // 2)
    first = state.reconstruction.copy()
    held, grew = held_mb(lambda: [sweep() for _ in range(5)])
    state.set_k(k_max // 2)
    np.testing.assert_allclose(state.reconstruction, first, atol=1e-12)
    assert held < 1.0 and grew < 50
    state.set_k(10**9)  # beyond the range: clamped
    assert state.k == k_max
    state.set_k(-5)
    assert state.k == 1


# ------------------------------------------------------------------------ a 2 M-face mesh

# The child's own peak: /proc/self/status's VmHWM (its memory since exec). ru_maxrss is not
# that on Linux: it keeps the peak of the process it was started from (the test process, which
# may have held gigabytes for an earlier test), so it is only the fallback.
PEAK_SCRIPT = """
import json, resource, sys, time
from meshlap_core.cli import main
t = time.perf_counter()
code = main(sys.argv[1:])
seconds = time.perf_counter() - t
try:
    with open("/proc/self/status") as fh:
        peak = next(int(s.split()[1]) for s in fh if s.startswith("VmHWM:")) / 1024
except (OSError, StopIteration, ValueError):
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
sys.stderr.write(json.dumps({"code": code, "peak_mb": peak, "seconds": seconds}) + "\\n")
"""


@pytest.mark.slow
def test_info_on_two_million_faces_has_bounded_memory(tmp_path):
    """A 1001 x 1001 grid (1,002,001 vertices, 2,000,000 faces) as binary PLY (50 MB):
    ``meshlap info`` reads, validates and describes it below 1.5 GB peak (measured about
    0.63 GB); a run that loaded it naively with per-line Python objects would need several."""
    path = tmp_path / "grid2m.ply"
    save_mesh(path, *primitives.grid(1001, 1001))
    res = subprocess.run(
        [sys.executable, "-c", PEAK_SCRIPT, "info", str(path), "--json"],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    stats = json.loads(res.stderr.strip().splitlines()[-1])
    assert res.returncode == 0 and stats["code"] == 0, res.stderr
    info = json.loads(res.stdout)
    assert (info["n_vertices"], info["n_faces"]) == (1_002_001, 2_000_000)
    assert info["n_edges"] == 3_002_000 and info["euler_characteristic"] == 1
    assert info["n_boundary_loops"] == 1 and info["boundary_loop_lengths"] == [4000]
    assert info["genus"] == 0 and info["repairs"] == [] and info["warnings"] == []
    print(f"info on 2M faces: peak RSS {stats['peak_mb']:.0f} MB, {stats['seconds']:.1f} s")
    assert stats["peak_mb"] < 1536
