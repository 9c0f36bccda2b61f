"""A child process's messages with their large arrays through shared memory (app/handover.py)."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
from meshlap_app import handover
from meshlap_app.handover import SHARED_MIN_BYTES, Packed, pack, unpack
from meshlap_app.jobs import Jobs, in_child


def test_large_arrays_travel_in_a_shared_file_small_ones_in_the_pickle():
    big = np.arange(SHARED_MIN_BYTES // 8 + 10, dtype=np.float64).reshape(-1, 2)
    faces = np.arange(3 * (SHARED_MIN_BYTES // 8), dtype=np.int64).reshape(-1, 3)
    small = np.linspace(0.0, 1.0, 7)
    value = {"V": big, "F": faces, "small": small, "name": "scan.obj", "fortran": big.T}
    packed = pack(value)
    assert packed.path and os.path.exists(packed.path)
    # the two large buffers (the transposed view shares V's and travels once more) in the file
    assert len(packed.sizes) == 3 and sum(packed.sizes) == 2 * big.nbytes + faces.nbytes
    assert len(packed.data) < 10_000  # the pickle holds no large array
    got = unpack(packed)
    assert not os.path.exists(packed.path)  # unlinked once mapped
    assert got["name"] == "scan.obj"
    for key in ("V", "F", "small", "fortran"):
        assert got[key].dtype == value[key].dtype and np.array_equal(got[key], value[key])
    assert got["fortran"].flags.f_contiguous
    got["V"][0, 0] = -1.0  # writable, and the sender's array is untouched
    assert big[0, 0] == 0.0


def test_a_message_without_large_arrays_needs_no_file():
    packed = pack(("progress", np.zeros(3), "phase"))
    assert packed.path == "" and packed.sizes == ()
    kind, arr, phase = unpack(packed)
    assert kind == "progress" and phase == "phase" and np.array_equal(arr, np.zeros(3))


def test_files_of_ended_processes_are_removed_and_others_kept(tmp_path):
    done = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        check=True,
        capture_output=True,
        text=True,
    )
    ended = int(done.stdout)
    stale = tmp_path / f"{handover.SHARED_PREFIX}{ended}-abc"
    alive = tmp_path / f"{handover.SHARED_PREFIX}{os.getpid()}-abc"
    other = tmp_path / "unrelated-file"
    for p in (stale, alive, other):
        p.write_bytes(b"x")
    handover.remove_stale(str(tmp_path))
    assert not stale.exists() and alive.exists() and other.exists()


def test_discard_removes_an_unopened_file():
    packed = pack(np.ones(SHARED_MIN_BYTES // 8))
    assert isinstance(packed, Packed) and os.path.exists(packed.path)
    handover.discard(packed)
    assert not os.path.exists(packed.path)
    handover.discard(Packed(b""))  # nothing to remove: no error


def _big_partial_work(n: int, progress=None) -> float:
    """A child's work: a large partial result (the preview's size class), then a result."""
    V = np.arange(3 * n, dtype=np.float64).reshape(n, 3)
    progress.partial({"V": V, "F": np.arange(3 * n, dtype=np.int64).reshape(n, 3)})
    return {"sum": float(V.sum()), "field": V[:, 0] * 2.0}


def test_in_child_hands_large_partial_results_and_results_over_shared_memory():
    n = SHARED_MIN_BYTES // 8  # 3 MB per array
    jobs = Jobs()
    jobs.processes = True
    done = []
    job = jobs.start("c", "child", in_child(_big_partial_work, n), done.append)
    assert jobs.wait("c", timeout=120)
    expected = np.arange(3 * n, dtype=np.float64).reshape(n, 3)
    partial = job.reporter.last_partial
    assert np.array_equal(partial["V"], expected)
    assert np.array_equal(partial["F"], np.arange(3 * n).reshape(n, 3))
    assert done[0]["sum"] == float(expected.sum())  # Σ 0..3n−1 = 3n(3n−1)/2
    assert done[0]["sum"] == 3 * n * (3 * n - 1) / 2
    assert np.array_equal(done[0]["field"], 2.0 * expected[:, 0])
