"""The sandbox's fences (:class:`meshlap_core.exercises.harness.Fence`): a student file that
opens a window, starts a process, opens a file outside its folder, or never finishes importing
is stopped and reported with its diagnosis, and the checker (and the file's other tasks) go on.
Each case has its hostile student file in ``tests/exercises/``."""

from __future__ import annotations

import glob
import os
from pathlib import Path

import numpy as np
import pytest

from meshlap_core.exercises import check_file
from meshlap_core.exercises.diagnose import DIAGNOSES
from tests.support.students import STUDENTS

FENCED = [  # (student file, task, status, diagnosis, the line of the file named in its traceback)
    ("hostile_window", "uniform_laplacian", "import_error", "opens_window", "import polyscope"),
    ("hostile_window", "one_ring", "import_error", "opens_window", "import polyscope"),
    ("hostile_spawn", "uniform_laplacian", "refused", "spawns_process", "subprocess.run"),
    ("hostile_spawn", "barycentric_areas", "refused", "spawns_process", ".Pool(2)"),
    ("hostile_read_outside", "barycentric_areas", "refused", "outside_folder", "conftest.py"),
]


@pytest.fixture(scope="module", params=["auto", "process"])
def fenced(request):
    """Each hostile file checked once on the tasks it defines, under bubblewrap where it works
    and forced without it: the fence names the same attempts either way."""
    tasks = {
        "hostile_window": ["uniform_laplacian", "one_ring"],
        "hostile_spawn": ["uniform_laplacian", "barycentric_areas", "one_ring"],
        "hostile_read_outside": ["barycentric_areas", "mean_curvature_normal"],
    }
    return {
        name: check_file(STUDENTS / f"{name}.py", t, sandbox=request.param, speed=False)
        for name, t in tasks.items()
    }


@pytest.mark.parametrize(("name", "task", "status", "diagnosis", "line"), FENCED)
def test_a_fenced_action_is_stopped_and_diagnosed(fenced, name, task, status, diagnosis, line):
    result = fenced[name][task]
    assert result.status == status, result.lines()
    assert result.diagnosis == diagnosis, result.lines()
    text = "\n".join(result.lines())
    assert DIAGNOSES[diagnosis].split(":")[0] in text
    assert f"{name}.py" in result.traceback and line in result.traceback
    frames = [ln for ln in result.traceback.splitlines() if ln.strip().startswith("File ")]
    assert frames and all(f"{name}.py" in ln for ln in frames)  # the student's frames only


def test_the_fences_stop_only_what_they_must(fenced):
    """The same files' other tasks pass: a right answer beside a refused one (one_ring), and a
    task reading a file inside its own folder (its source) is not refused."""
    assert fenced["hostile_spawn"]["one_ring"].passed
    assert fenced["hostile_read_outside"]["mean_curvature_normal"].passed


def test_a_caught_refusal_is_still_refused(fenced):
    """hostile_spawn's barycentric_areas catches the PermissionError and returns right areas:
    the attempt was made, the task is refused all the same."""
    r = fenced["hostile_spawn"]["barycentric_areas"]
    assert r.status == "refused" and r.n_calls == 0


def _children() -> list[int]:
    out = []
    for f in glob.glob(f"/proc/{os.getpid()}/task/*/children"):
        with open(f) as fh:
            out += [int(p) for p in fh.read().split()]
    return out


def test_a_file_that_hangs_at_import_is_stopped_and_diagnosed():
    before = set(_children())  # a fork server an earlier test started stays: not this check's
    result = check_file(
        STUDENTS / "hostile_import_hang.py", ["uniform_laplacian", "one_ring"], timeout=4.0
    )
    for t in result.tasks:
        assert t.status == "timeout" and t.diagnosis == "hangs_at_import", t.lines()
        assert "while importing your file" in t.message
    assert not set(_children()) - before


def test_a_right_file_is_not_fenced(tmp_path):
    """A right file in a student's folder that reads a data file beside it, imports scipy's
    submodules lazily inside the call and writes a scratch file in its folder: nothing is
    refused, and what it writes stays in its copy (the submitted folder is left as it was)."""
    (tmp_path / "factor.txt").write_text("1.0\n")
    (tmp_path / "mine.py").write_text(
        "import os\nimport numpy as np\n\n"
        "HERE = os.path.dirname(os.path.abspath(__file__))\n\n"
        "def barycentric_areas(V, F):\n"
        "    import scipy.sparse.csgraph  # a lazy import: the library's own files\n"
        "    with open(os.path.join(HERE, 'factor.txt')) as f:\n"
        "        s = float(f.read())\n"
        "    np.save(os.path.join(HERE, 'scratch.npy'), V)\n"
        "    P = V[F]\n"
        "    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)\n"
        "    return s * np.bincount(F.ravel(), np.repeat(A / 3.0, 3), minlength=len(V))\n"
    )
    result = check_file(tmp_path / "mine.py", ["barycentric_areas"], folder=tmp_path)
    assert result.passed, result.format_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["factor.txt", "mine.py"]


# ---- time limits in proportion to the reference on the same mesh ---------------------------

RIGHT_HEAT = (STUDENTS / "right_igl.py").read_text()


def _slow_student(tmp_path: Path, body: str) -> Path:
    """right_igl.py with its heat_geodesic wrapped: ``body`` runs first on meshes of 1000
    vertices or more (the battery's large sphere)."""
    path = tmp_path / "slow.py"
    path.write_text(
        RIGHT_HEAT.replace("def heat_geodesic(", "def _heat(")
        + "\n\ndef heat_geodesic(V, F, source, m):\n"
        + "    import time\n\n"
        + "    if len(V) >= 1000:\n"
        + "".join(f"        {line}\n" for line in body.splitlines())
        + "    return _heat(V, F, source, m)\n"
    )
    return path


def test_a_right_answer_slower_than_the_time_limit_on_a_big_mesh_passes(tmp_path):
    """The call on the large sphere takes longer than the task's time limit (here 4 s): it is
    given TIME_FACTOR × the reference's time on that mesh, measured in the checker, and passes
    (the former right_dense.py's dense heat method took 82 s there with the machine's
    load at 14 and was stopped as an infinite loop at 60 s)."""
    path = _slow_student(tmp_path, "time.sleep(6.0)")
    result = check_file(path, ["heat_geodesic"], timeout=4.0, speed=False)
    assert result.passed, result.format_text()


def test_an_endless_call_on_a_big_mesh_is_stopped_at_its_budget(tmp_path, monkeypatch):
    """An endless call on the large sphere is stopped when it passes its budget (TIME_FACTOR
    lowered to 100 here, to keep the test short) and diagnosed as far slower than the
    reference on that mesh; the budget's mesh and reference time are in the message."""
    from meshlap_core.exercises import sandbox

    monkeypatch.setattr(sandbox, "TIME_FACTOR", 100.0)
    path = _slow_student(tmp_path, "while True:\n    time.sleep(0.01)")
    t = check_file(path, ["heat_geodesic"], timeout=4.0, speed=False)["heat_geodesic"]
    assert t.status == "timeout", t.lines()
    if t.diagnosis is None:  # the reference took under 40 ms: the 4 s limit came first
        assert "infinite loop" in t.message
    else:
        assert t.diagnosis == "too_slow" and "on mesh large" in t.message
        assert "100× the reference's" in t.message


def _tube(rings: int, around: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """A closed tube (capped), rings 0.87 apart with unit edges around: ``rings`` long."""
    k, j = np.meshgrid(np.arange(rings), np.arange(around), indexing="ij")
    angle = 2 * np.pi * (j + 0.5 * k) / around
    r = 1.0 / (2 * np.sin(np.pi / around))
    ring = np.stack([r * np.cos(angle), r * np.sin(angle), 0.87 * k], axis=-1).reshape(-1, 3)
    top = 0.87 * (rings - 1)
    V = np.vstack([ring, [[0.0, 0.0, -0.5], [0.0, 0.0, top + 0.5]]])
    a = (k[:-1] * around + j[:-1]).ravel()
    b = (k[:-1] * around + (j[:-1] + 1) % around).ravel()
    quads = np.concatenate(
        [np.stack([a, b, a + around], 1), np.stack([b, b + around, a + around], 1)]
    )
    s, e, last = len(V) - 2, len(V) - 1, (rings - 1) * around
    jj = np.arange(around)
    caps = np.concatenate([
        np.stack([np.full(around, s), (jj + 1) % around, jj], 1),
        np.stack([np.full(around, e), last + jj, last + (jj + 1) % around], 1),
    ])  # fmt: skip
    return V, np.concatenate([quads, caps]).astype(np.int64)


def test_a_mesh_where_the_heat_underflows_does_not_judge_the_heat_method():
    """On a tube 2400 rings long the heat of t = h² underflows to 0 far from the source (it
    decays like exp(−d/√t)): a right heat file written from the template (right_igl.py) is NaN
    there (−∇u/|∇u| = 0/0), through no mistake of its own. That mesh is not held against it: it
    passes on the battery, with a note naming the mesh and the share of faces; a wrong file
    still fails on the battery."""
    from meshlap_core.diffusion import HeatGeodesic
    from meshlap_core.exercises import geodesic_task as geo
    from meshlap_core.exercises.check import check_on_mesh
    from meshlap_core.exercises.meshes import Case

    V, F = _tube(2400)
    case = Case("tube", V, F, "")
    (_, args), *_ = geo.heat_calls(case)
    u = HeatGeodesic(V, F, m=1.0, boundary="neumann").heat([args[2]])
    assert np.min(np.abs(u)) == 0.0  # the heat underflowed: the premise of the test
    right = check_on_mesh(STUDENTS / "right_igl.py", "heat_geodesic", V, F)
    t = right.result.tasks[0]
    assert t.passed, t.lines()
    assert "not judged on mesh your_mesh" in t.note and "underflows" in "\n".join(t.lines())
    wrong = check_on_mesh(STUDENTS / "wrong_heat_time.py", "heat_geodesic", V, F)
    assert wrong.result.tasks[0].diagnosis == "time_not_scaled"
