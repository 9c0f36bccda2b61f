"""The one way across processes (app/ipc.py): messages with their large arrays through files in
shared memory, a block two processes map, and child processes from one fork server (results,
errors, a child that dies, Cancel, a time limit)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from meshlap_app import ipc
from meshlap_app.ipc import SHARED_MIN_BYTES, Packed, pack, unpack
from meshlap_app.jobs import Jobs, in_child

from meshlap_core.errors import Cancelled, MeshError


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
    stale = tmp_path / f"{ipc.SHARED_PREFIX}{ended}-abc"
    alive = tmp_path / f"{ipc.SHARED_PREFIX}{os.getpid()}-abc"
    other = tmp_path / "unrelated-file"
    for p in (stale, alive, other):
        p.write_bytes(b"x")
    ipc.remove_stale(str(tmp_path))
    assert not stale.exists() and alive.exists() and other.exists()


def test_discard_removes_an_unopened_file():
    packed = pack(np.ones(SHARED_MIN_BYTES // 8))
    assert isinstance(packed, Packed) and os.path.exists(packed.path)
    ipc.discard(packed)
    assert not os.path.exists(packed.path)
    ipc.discard(Packed(b""))  # nothing to remove: no error


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


# ---------------------------------------------------------------------- round trips
def _ended_pid() -> int:
    """The pid of a process that has ended."""
    done = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        check=True,
        capture_output=True,
        text=True,
    )
    return int(done.stdout)


def _files_of(pid: int) -> list[str]:
    """The shared-memory files made by process ``pid``."""
    prefix = f"{ipc.SHARED_PREFIX}{pid}-"
    return [n for n in os.listdir(ipc.shared_folder()) if n.startswith(prefix)]


def test_a_nested_result_comes_back_equal_with_dtypes_shapes_and_order():
    """Big arrays of several dtypes (through the file), small ones, a 0-d array, an empty
    one, a strided view, a Fortran-ordered one and a repeated one, nested in dicts, lists
    and tuples: each back with its dtype, shape, values and memory order; the file gone."""
    rng = np.random.default_rng(7)
    big = SHARED_MIN_BYTES  # bytes
    U = np.asfortranarray(rng.standard_normal((big // 80 + 3, 10)))
    value = {
        "basis": {"U": U, "lam": np.linspace(0.0, 2.0, 10), "name": "bumpy"},
        "mesh": [
            rng.standard_normal((big // 24 + 5, 3)),  # float64, big
            rng.integers(0, 9, size=(big // 24 + 1, 3), dtype=np.int64),  # int64, big
            rng.standard_normal(big // 4 + 7).astype(np.float32),  # float32, big
        ],
        "flags": rng.random(big + 1) < 0.5,  # bool, big (one byte each)
        "small": (np.arange(5, dtype=np.int16), np.float64(3.5), np.array(2.0), np.empty((0, 3))),
        "strided": rng.standard_normal((big // 8, 2))[::2, 1],  # not contiguous: in band
        "complex": (1 + 2j) * np.ones((big // 16 + 1,), dtype=np.complex128),
    }
    value["again"] = value["mesh"][0]  # one array referenced twice
    packed = pack(value)
    assert packed.path and os.path.exists(packed.path)
    # the six big contiguous arrays in the file (the repeated one once); in the pickle only
    # the small ones and the strided view's copy
    assert len(packed.sizes) == 6 and len(packed.data) < 20_000 + value["strided"].nbytes
    got = unpack(packed)
    assert not os.path.exists(packed.path)

    def same(a, b):
        assert type(a) is type(b)
        if isinstance(a, dict):
            assert a.keys() == b.keys()
            for key in a:
                same(a[key], b[key])
        elif isinstance(a, (list, tuple)):
            assert len(a) == len(b)
            for x, y in zip(a, b, strict=True):
                same(x, y)
        elif isinstance(a, np.ndarray):
            assert a.dtype == b.dtype and a.shape == b.shape
            assert np.array_equal(a, b)
            if a.flags.c_contiguous or a.flags.f_contiguous:  # (a strided view: a copy)
                assert a.flags.f_contiguous == b.flags.f_contiguous
        else:
            assert a == b

    same(value, got)
    assert got["again"] is got["mesh"][0]  # the pickle's memo: one array, not two copies
    assert got["basis"]["U"].flags.f_contiguous and not got["basis"]["U"].flags.c_contiguous


def test_the_stale_sweep_removes_the_files_of_ended_makers_in_shared_memory():
    """pack() sweeps the shared folder: a file left by an ended process goes, one of a
    running process stays; given a pid, only that process's files go."""
    folder = ipc.shared_folder()
    ended, other = _ended_pid(), _ended_pid()
    stale = os.path.join(folder, f"{ipc.SHARED_PREFIX}{ended}-left")
    mine = os.path.join(folder, f"{ipc.SHARED_PREFIX}{os.getpid()}-kept")
    try:
        for path in (stale, mine):
            with open(path, "wb") as f:
                f.write(b"x")
        ipc.discard(pack(np.ones(SHARED_MIN_BYTES // 8)))
        assert not os.path.exists(stale) and os.path.exists(mine)
        theirs = os.path.join(folder, f"{ipc.SHARED_PREFIX}{other}-left")
        with open(theirs, "wb") as f:
            f.write(b"x")
        ipc.remove_stale(folder, pid=os.getpid())  # (the caller says this one ended)
        assert not os.path.exists(mine) and os.path.exists(theirs)
    finally:
        for name in (stale, mine, os.path.join(folder, f"{ipc.SHARED_PREFIX}{other}-left")):
            if os.path.exists(name):
                os.unlink(name)


# ---------------------------------------------------------------------- the shared block
def _write_block(conn, path: str, n: int) -> None:
    """A child writes 0, 1, ..., n−1 into the block, then says so."""
    block = ipc.SharedBlock.attach(path)
    block.array((n,), np.float64)[:] = np.arange(n)
    conn.send(("written",))
    block.close()
    conn.close()


def test_a_shared_block_is_written_by_the_child_and_read_here_after_its_file_is_gone():
    n = 1000
    block = ipc.SharedBlock.create(8 * n + 24)
    assert os.path.basename(block.path).startswith(f"{ipc.SHARED_PREFIX}{os.getpid()}-")
    child = ipc.Child(_write_block, block.path, n, name="test")
    try:
        assert child.receive(timeout=120) == ("written",)
    finally:
        child.end()
    block.unlink()  # both mapped it: the file goes, the memory stays
    assert not os.path.exists(block.path)
    view = block.array((n,), np.float64)
    assert np.array_equal(view, np.arange(n))
    tail = block.array((3,), np.float64, offset=8 * n)
    assert np.array_equal(tail, np.zeros(3))  # a new block is zero-filled
    del view, tail
    block.close()
    assert block.buf.closed


# ---------------------------------------------------------------------- child processes
class Recorder:
    """A reporter recording what a child sends; ``stop`` set: Cancel."""

    def __init__(self) -> None:
        self.reports: list[tuple] = []
        self.partials: list = []
        self.stop = threading.Event()

    def __call__(self, fraction, message=""):
        self.reports.append((fraction, message))

    def partial(self, value):
        self.partials.append(value)

    def check(self):
        if self.stop.is_set():
            raise Cancelled("cancelled")

    def pid(self) -> int:
        return int(self.reports[0][1])


def _dies_holding_a_file(code: int, progress=None) -> None:
    """Says its pid, leaves a shared-memory file (a message it never sends), then dies."""
    progress(0.0, str(os.getpid()))
    pack(np.ones(SHARED_MIN_BYTES // 8))
    if code < 0:
        os.kill(os.getpid(), -code)
    os._exit(code)


def _sleeps_holding_a_file(seconds: float, progress=None) -> None:
    progress(0.0, str(os.getpid()))
    pack(np.ones(SHARED_MIN_BYTES // 8))
    progress(0.5, "sleeping")
    time.sleep(seconds)


def _fails(kind: str, progress=None) -> None:
    if kind == "mesh":
        raise MeshError("no faces", "bad.obj")
    if kind == "os":
        raise FileNotFoundError(2, "No such file or directory", "gone.obj")
    raise ZeroDivisionError("division by zero")


def _environment(name: str, progress=None) -> str | None:
    return os.environ.get(name)


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


@pytest.mark.parametrize("code", [3, -signal.SIGKILL])
def test_a_child_that_dies_mid_run_is_a_clear_error_and_leaves_no_file(code):
    r = Recorder()
    with pytest.raises(MeshError, match=rf"^the worker process ended \(exit code {code}\)$"):
        ipc.call(_dies_holding_a_file, code, reporter=r)
    pid = r.pid()
    assert _gone(pid) and _files_of(pid) == []


def test_cancel_ends_the_child_at_once_and_leaves_no_file():
    r = Recorder()
    done: list[BaseException] = []

    def run():
        try:
            ipc.call(_sleeps_holding_a_file, 60.0, reporter=r)
        except BaseException as exc:
            done.append(exc)

    thread = threading.Thread(target=run)
    thread.start()
    for _ in range(3000):  # until the child said it sleeps
        if len(r.reports) >= 2:
            break
        time.sleep(0.01)
    assert r.reports[-1] == (0.5, "sleeping")
    r.stop.set()
    thread.join(30)  # not the child's 60 s
    assert not thread.is_alive() and isinstance(done[0], Cancelled)
    pid = r.pid()
    assert _gone(pid) and _files_of(pid) == []


def test_a_child_over_its_time_limit_is_ended():
    r = Recorder()
    with pytest.raises(MeshError, match=r"the picture process took over 0.5 s"):
        ipc.call(_sleeps_holding_a_file, 60.0, reporter=r, timeout=0.5, name="picture")
    pid = r.pid()
    assert _gone(pid) and _files_of(pid) == []


def test_a_childs_errors_come_back_as_one_line():
    with pytest.raises(MeshError, match=r"^bad.obj: no faces$"):
        ipc.call(_fails, "mesh")
    with pytest.raises(MeshError, match=r"^gone.obj: No such file or directory$"):
        ipc.call(_fails, "os")
    with pytest.raises(MeshError, match=r"^ZeroDivisionError: division by zero$"):
        ipc.call(_fails, "zero")


def test_a_child_sees_the_environment_of_now_not_the_fork_servers(monkeypatch):
    """The fork server keeps the environment it started with; a child takes its parent's
    current one (a setting changed after the server started reaches it)."""
    ipc.start_server()
    monkeypatch.setenv("MESHLAP_IPC_TEST_SETTING", "now")
    assert ipc.call(_environment, "MESHLAP_IPC_TEST_SETTING") == "now"
    monkeypatch.delenv("MESHLAP_IPC_TEST_SETTING")
    assert ipc.call(_environment, "MESHLAP_IPC_TEST_SETTING") is None


def test_without_a_child_process_the_caller_is_told_and_a_job_runs_in_its_thread():
    """A function that does not pickle (a lambda) cannot go to a child: NoChildProcess, and
    a job's work then runs in its own thread."""
    with pytest.raises(ipc.NoChildProcess):
        ipc.call(lambda progress=None: 1)
    jobs = Jobs()
    done: list[int] = []
    jobs.start("t", "thread", in_child(lambda progress=None: os.getpid()), done.append)
    assert jobs.wait("t", timeout=60) and done == [os.getpid()]
