"""CLI: info, curvature, onering (through main() and once through the installed script)."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.cli import main
from meshlap_core.curvature import gaussian_curvature
from meshlap_core.io import save_mesh


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def cube_obj(tmp_path):
    path = tmp_path / "cube.obj"
    save_mesh(path, *primitives.cube())
    return path


@pytest.fixture
def grid_obj(tmp_path):
    path = tmp_path / "grid.obj"
    save_mesh(path, *primitives.grid(5, 5))
    return path


def test_info_json(capsys, tmp_path):
    path = tmp_path / "torus.obj"
    save_mesh(path, *primitives.torus_mesh(16, 8))
    code, out, _ = run_cli(capsys, "info", path, "--json")
    assert code == 0
    info = json.loads(out)
    assert info["n_vertices"] == 128 and info["n_faces"] == 256
    assert info["euler_characteristic"] == 0 and info["genus"] == 1
    assert info["n_boundary_loops"] == 0 and info["n_components"] == 1
    assert info["manifold"] is True and info["consistently_oriented"] is True
    assert info["bbox_diagonal"] == pytest.approx(np.linalg.norm([8, 8, 2]), rel=0.05)


def test_info_human(capsys, grid_obj):
    code, out, _ = run_cli(capsys, "info", grid_obj)
    assert code == 0 and "boundary loops    1" in out and "genus             0" in out


def test_curvature_json_matches_core(capsys, cube_obj):
    code, out, _ = run_cli(capsys, "curvature", cube_obj, "--method", "gaussian", "--json")
    assert code == 0
    stats = json.loads(out)
    K = gaussian_curvature(*primitives.cube())
    assert stats["max"] == pytest.approx(K.max()) and stats["min"] == pytest.approx(K.min())
    assert set(stats) >= {"min", "max", "mean", "median", "p01", "p99"}


@pytest.mark.parametrize("suffix", [".csv", ".npy", ".ply"])
def test_curvature_out_files(capsys, cube_obj, tmp_path, suffix):
    out_path = tmp_path / f"k{suffix}"
    code, _, _ = run_cli(capsys, "curvature", cube_obj, "--method", "gaussian", "--out", out_path)
    assert code == 0 and out_path.stat().st_size > 0
    if suffix == ".npy":
        np.testing.assert_allclose(np.load(out_path), gaussian_curvature(*primitives.cube()))


def test_onering_json(capsys, grid_obj):
    # vertex 0 is the corner (0,0): neighbours (1,0)=5, (1,1)=6, (0,1)=1 counter-clockwise
    code, out, _ = run_cli(capsys, "onering", grid_obj, "--vertex", 0, "--json")
    assert code == 0
    r = json.loads(out)
    assert r == {**r, "vertex": 0, "neighbors": [5, 6, 1], "boundary": True, "valence": 3}
    code, out, _ = run_cli(capsys, "onering", grid_obj, "--vertex", 0, "--reverse", "--json")
    assert json.loads(out)["neighbors"] == [1, 6, 5]


def test_bad_input_exit_2_one_line(capsys, tmp_path, cube_obj):
    empty = tmp_path / "empty.obj"
    empty.write_text("")
    for argv in (
        ["info", empty],
        ["info", tmp_path / "missing.obj"],
        ["info", tmp_path],
        ["onering", cube_obj, "--vertex", 99],
        ["curvature", cube_obj, "--out", tmp_path / "x.txt"],
    ):
        code, out, err = run_cli(capsys, *argv)
        assert code == 2, argv
        assert err.startswith("meshlap: error: ") and err.count("\n") == 1, err
        assert "Traceback" not in err and out == ""


def test_curvature_out_refuses_to_overwrite_input(capsys, tmp_path):
    path = tmp_path / "m.ply"
    save_mesh(path, *primitives.cube())
    before = path.read_bytes()
    code, _, _ = run_cli(capsys, "curvature", path, "--out", path)
    assert code == 2 and path.read_bytes() == before


def _console_script() -> str | None:
    beside = Path(sys.executable).parent / "meshlap"
    return str(beside) if beside.exists() else shutil.which("meshlap")


@pytest.mark.skipif(_console_script() is None, reason="console script `meshlap` not installed")
def test_console_script(cube_obj):
    exe = _console_script()
    res = subprocess.run(
        [exe, "info", str(cube_obj), "--json"], capture_output=True, text=True, timeout=120
    )
    assert res.returncode == 0 and json.loads(res.stdout)["n_faces"] == 12
    res = subprocess.run(
        [exe, "info", str(cube_obj) + ".nope"], capture_output=True, text=True, timeout=120
    )
    assert res.returncode == 2 and "Traceback" not in res.stderr


def test_smooth_inside_out_sphere_reports_the_volume_lost(capsys, tmp_path):
    """Uniform smoothing shrinks a sphere; an inside-out (inward-oriented) copy used to report
    +99.99 % volume change."""
    V, F = primitives.icosphere(2)
    pcts = []
    for name, G in (("out.obj", F), ("in.obj", F[:, ::-1])):
        path = tmp_path / name
        save_mesh(path, V, G)
        code, out, err = run_cli(capsys, "smooth", path, "--iters", "5", "--json")
        assert code == 0, err
        pcts.append(json.loads(out)["volume_change_pct"])
    assert pcts[1] < 0 and pcts[1] == pytest.approx(pcts[0], rel=1e-9)


@pytest.mark.parametrize("out", ["", "  "])
def test_curvature_empty_out_is_an_error_naming_the_flag(capsys, cube_obj, out):
    code, stdout, err = run_cli(capsys, "curvature", cube_obj, "--out", out)
    assert code == 2 and stdout == ""
    assert err.count("\n") == 1 and err.startswith("meshlap: error: --out:")
    assert "empty" in err


def _interrupt_during_startup(argv, trigger):
    """Start ``argv`` with ``-X importtime``, send SIGINT as soon as the module ``trigger`` has
    been imported (start-up still under way), and return ``(returncode, stderr lines that are
    not import timings)``."""
    import signal

    proc = subprocess.Popen(
        [sys.executable, "-X", "importtime", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # SIGINT as a terminal delivers it, also when the tests run with it ignored (a
        # background job of a shell: the child would inherit SIG_IGN and finish normally)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    lines = []
    for line in proc.stderr:
        lines.append(line)
        if line.startswith("import time:") and line.split("|")[-1].strip() == trigger:
            proc.send_signal(signal.SIGINT)
            break
    _, rest = proc.communicate(timeout=600)
    lines += rest.splitlines(keepends=True)
    return proc.returncode, [x for x in lines if not x.startswith("import time:")]


@pytest.mark.parametrize("trigger", ["meshlap_core.cli", "numpy", "scipy.sparse", "igl"])
@pytest.mark.parametrize("how", ["module", "script"])
def test_sigint_during_startup_exits_130_quietly(cube_obj, trigger, how):
    """SIGINT while numpy / scipy / libigl are being imported: exit 130, at most one line,
    no traceback (it printed a 52-line traceback)."""
    if how == "module":
        argv = ["-m", "meshlap_core.cli", "info", str(cube_obj)]
    else:
        if _console_script() is None:
            pytest.skip("console script `meshlap` not installed")
        argv = [_console_script(), "info", str(cube_obj)]
    code, err = _interrupt_during_startup(argv, trigger)
    assert code == 130, err
    assert len(err) <= 1 and not any("Traceback" in x for x in err), err
    assert err == [] or err[0] == "meshlap: interrupted\n"


def test_a_named_command_builds_its_parser_alone():
    """``meshlap curvature ...`` registers only that subcommand (start-up time), with the same
    arguments as the full parser; an unknown or absent command gets the full parser."""
    from meshlap_core.cli import _named_command, build_parser

    assert _named_command(["curvature", "x.obj"]) == "curvature"
    assert _named_command(["--version"]) is None
    assert _named_command(["view", "x.obj"]) is None  # the viewer's, from the entry points
    assert _named_command([]) is None
    argv = ["curvature", "m.obj", "--method", "k1", "--area", "voronoi", "--json"]
    alone, full = build_parser("curvature"), build_parser()
    assert vars(alone.parse_args(argv)) == vars(full.parse_args(argv))
    choices = alone._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    assert list(choices) == ["curvature"]
    full_choices = full._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    assert {"info", "curvature", "spectral", "view"} <= set(full_choices)
