"""Shared fixtures.

Meshes from ``../shared/meshes`` (beside the checkout) are used only through ``shared_mesh``,
which skips the test with a clear reason when that folder is absent, so a fresh clone alone
passes the suite.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from tests.support.egl import EGL_SKIP, egl_available

ROOT = Path(__file__).resolve().parents[1]  # the checkout (tests/ is a package in it)

SHARED_MESHES = ROOT.parent / "shared" / "meshes"


@pytest.fixture
def shared_mesh() -> Callable[[str], Path]:
    """Return a function mapping a file name in ``../shared/meshes`` to its path (or skip)."""

    def get(name: str) -> Path:
        path = SHARED_MESHES / name
        if not path.is_file():
            pytest.skip(
                f"../shared/meshes/{name} not present (real meshes live beside the checkout)"
            )
        return path

    return get


@pytest.fixture(params=["cholmod", "fallback"])
def spd_backend(request, monkeypatch) -> str:
    """Run a solver-sensitive test on both sparse Cholesky back ends: CHOLMOD through
    scikit-sparse (skipped when not installed, README "Fast solver") and the bundled fallback
    (``MESHLAP_SOLVER=fallback``). Returns the active back end's name."""
    from meshlap_core.linalg import spd
    from meshlap_core.linalg.spd import SOLVER_ENV, solver_backend

    # a window run earlier in this process (viewer.run) keeps its eigensolver GIL-free:
    # each test starts from the core's default
    monkeypatch.setattr(spd, "_GIL_FREE", {"eigen": False})

    if request.param == "fallback":
        monkeypatch.setenv(SOLVER_ENV, "fallback")
    else:
        monkeypatch.setenv(SOLVER_ENV, "cholmod")  # at every size (the test meshes are small)
        if solver_backend() != "cholmod":
            pytest.skip("scikit-sparse is not installed (README: Fast solver)")
    return solver_backend()


@pytest.fixture(params=[1, 2], ids=["one-slice-worker", "two-slice-workers"])
def slice_plan(request, monkeypatch) -> int:
    """Run a test under each plan the eigensolver can choose by itself: one slice worker
    (what a busy machine gets) and two (an idle one). The choice is made from the machine's
    load (:func:`meshlap_core.linalg.slicing.default_workers`), so without this fixture the
    load would pick which plan a test sees. Returns the forced number of workers."""
    from meshlap_core.linalg import eigsolve

    monkeypatch.setattr(eigsolve, "default_workers", lambda n, slice_size: request.param)
    return request.param


@pytest.fixture(scope="module")
def polyscope_mock(tmp_path_factory):
    """polyscope on its ``openGL_mock`` backend for one test module, every frame running the
    callback; shut down afterwards so a later module may start another backend (EGL)."""
    import os

    import polyscope as ps

    old = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("polyscope"))  # polyscope writes .ini files here
    ps.set_allow_headless_backends(True)
    ps.init("openGL_mock")
    ps.set_max_fps(-1)
    ps.set_frame_tick_limit_fps_mode("ignore_limits")
    yield ps
    ps.clear_user_callback()
    ps.remove_all_structures()
    ps.shutdown()
    os.chdir(old)


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    """polyscope on ``openGL_mock`` for the module (the widget tests' name for it)."""
    return polyscope_mock


@pytest.fixture
def sphere(tmp_path: Path) -> Path:
    """An icosphere (level 2, 162 vertices) written to ``tmp_path/sphere.obj``."""
    from meshlap_core import primitives
    from meshlap_core.io import save_mesh

    path = tmp_path / "sphere.obj"
    save_mesh(path, *primitives.icosphere(2))
    return path


@pytest.fixture
def viewer(polyscope_mock, sphere, tmp_path, monkeypatch):
    """A viewer on ``sphere`` drawing through the scriptable UI adapter on ``openGL_mock``
    (every ``frame_tick`` runs its callback), exporting to ``tmp_path``, with a private
    eigenbasis cache."""
    from meshlap_app.state import AppState, MeshState
    from meshlap_app.viewer import Viewer

    from tests.support.scripted_ui import ScriptedUI

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    polyscope_mock.remove_all_structures()
    mesh = MeshState()
    assert mesh.load(sphere)
    v = Viewer(AppState(mesh=mesh, folder=tmp_path), ui=ScriptedUI())
    v.set_ui_scale(v.state.ui_scale)  # polyscope's UI scale is global: not the last module's
    v.sync_mesh()
    polyscope_mock.set_user_callback(v.callback)
    yield v
    polyscope_mock.clear_user_callback()


@pytest.fixture
def python_ok(tmp_path: Path) -> Callable[..., subprocess.CompletedProcess]:
    """Run ``python ARGS...`` (a ``-c`` script or ``-m meshlap_core.cli ...``) in ``tmp_path``
    with a private eigenbasis cache, assert it exits 0 (showing its stderr otherwise) and
    return the completed process (text output). The child imports the test helpers
    (``tests.support.scripted_ui``, ...) as the tests do: the checkout is on its
    ``PYTHONPATH``, as pytest puts it on the tests' path."""
    helpers = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)

    def run(*args: object, timeout: float = 600) -> subprocess.CompletedProcess:
        env = dict(os.environ, MESHLAP_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=helpers)
        res = subprocess.run(
            [sys.executable, *map(str, args)],
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=tmp_path,
            env=env,
        )
        assert res.returncode == 0, res.stderr
        return res

    return run


def pytest_runtest_setup(item: pytest.Item) -> None:
    """Tests marked ``egl`` skip, saying why, where the EGL backend cannot start; only a test
    marked ``window`` may start an X server (so ``-m "not window"`` leaves every real window
    out: :class:`tests.support.xwindow.XServer` refuses to start otherwise)."""
    from tests.support import xwindow

    xwindow.WINDOW_TEST = item.get_closest_marker("window") is not None
    if item.get_closest_marker("egl") is not None and not egl_available():
        pytest.skip(EGL_SKIP)
