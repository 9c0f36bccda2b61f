"""CLI: geodesic, heat and filter (through main(), the error rules of every command)."""

import json

import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.cli import main
from meshlap_core.diffusion import HeatDiffusion, HeatGeodesic, unit_heat
from meshlap_core.io import load_mesh, save_mesh


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def grid_obj(tmp_path):
    path = tmp_path / "grid.obj"
    save_mesh(path, *primitives.grid(11, 11))
    return path


@pytest.fixture
def sphere_obj(tmp_path):
    path = tmp_path / "sphere.obj"
    save_mesh(path, *primitives.bumpy_sphere(2))
    return path


def test_geodesic_exact_on_a_grid_is_euclidean_and_written(capsys, grid_obj, tmp_path):
    out = tmp_path / "d.csv"
    code, text, err = run_cli(
        capsys, "geodesic", grid_obj, "--vertex", 60, "--method", "exact", "--out", out, "--json"
    )
    assert code == 0, err
    r = json.loads(text)
    V = load_mesh(grid_obj).V
    d = np.loadtxt(out, skiprows=1)
    np.testing.assert_allclose(d, np.linalg.norm(V - V[60], axis=1), atol=1e-12)
    assert r["sources"] == [60] and r["unreachable"] == 0
    assert r["max"] == pytest.approx(d.max())


def test_geodesic_heat_matches_the_library_and_reports_its_error(capsys, sphere_obj, tmp_path):
    out = tmp_path / "d.npy"
    curves = tmp_path / "curves.obj"
    code, text, err = run_cli(
        capsys, "geodesic", sphere_obj, "--vertex", 3, "--vertex", 70, "--exact",
        "--out", out, "--isolines", 4, "--curves", curves, "--json",
    )  # fmt: skip
    assert code == 0, err
    r = json.loads(text)
    mesh = load_mesh(sphere_obj)
    np.testing.assert_allclose(np.load(out), HeatGeodesic(mesh.V, mesh.F).distance([3, 70]))
    assert 0 < r["relative_error_mean"] < 0.1
    assert r["curve_segments"] == sum(x.startswith("l ") for x in curves.read_text().split("\n"))


def test_heat_euler_and_spectral(capsys, sphere_obj):
    code, text, err = run_cli(
        capsys, "heat", sphere_obj, "--vertex", 5, "--t", "0.02", "--steps", 2, "--json"
    )
    assert code == 0, err
    r = json.loads(text)
    mesh = load_mesh(sphere_obj)
    hd = HeatDiffusion(mesh.V, mesh.F)
    u = hd.euler(unit_heat(np.array([5]), hd.mass), 0.02, 2)
    assert r["max"] == pytest.approx(u.max()) and r["total_heat"] == pytest.approx(1.0)
    n = len(mesh.V)
    code, text, err = run_cli(
        capsys, "heat", sphere_obj, "--vertex", 5, "--t", "0.02", "--method", "spectral",
        "--k", n, "--no-cache", "--json",
    )  # fmt: skip
    assert code == 0, err
    r = json.loads(text)
    assert r["total_heat"] == pytest.approx(1.0) and 0 < r["truncation_bound"] < 1


def test_heat_writes_the_level_curves_of_u(capsys, tmp_path):
    """``meshlap heat --isolines N --curves FILE``: N levels evenly spaced inside u's range
    (u − min)/(max − min) = i/(N+1), every curve point on its level (u linear on each edge)."""
    path = tmp_path / "grid.obj"
    V, F = primitives.grid(21, 21)
    save_mesh(path, V, F)
    curves = tmp_path / "u_curves.obj"
    out = tmp_path / "u.npy"
    code, text, err = run_cli(
        capsys, "heat", path, "--vertex", 220, "--t", "0.01", "--out", out,
        "--isolines", 3, "--curves", curves, "--json",
    )  # fmt: skip
    assert code == 0, err
    r = json.loads(text)
    u = np.load(out)
    lines = curves.read_text().splitlines()
    P = np.array([[float(x) for x in ln.split()[1:]] for ln in lines if ln.startswith("v ")])
    assert r["curves"] == str(curves) and r["curve_segments"] == sum(
        ln.startswith("l ") for ln in lines
    )
    assert r["curve_segments"] > 0
    # u at each curve point, interpolated on the mesh (barycentric in its face)
    import igl

    _, face, _ = igl.point_mesh_squared_distance(P, V, F)
    B = igl.barycentric_coordinates(P, *(V[F[face, i]] for i in range(3)))
    at = np.einsum("pi,pi->p", B, u[F[face]])
    levels = u.min() + (u.max() - u.min()) * np.arange(1, 4) / 4
    assert np.all(np.min(np.abs(at[:, None] - levels[None, :]), axis=1) < 1e-9 * u.max())


def test_filter_unit_gain_band_returns_the_mesh(capsys, sphere_obj, tmp_path):
    out = tmp_path / "f.obj"
    n = len(load_mesh(sphere_obj).V)
    code, text, err = run_cli(
        capsys, "filter", sphere_obj, "--k", n, "--band", "1:5", "--gain", "1", "--no-cache",
        "--out", out, "--json",
    )  # fmt: skip
    assert code == 0, err
    np.testing.assert_allclose(load_mesh(out).V, load_mesh(sphere_obj).V, atol=1e-9)
    code, text, err = run_cli(
        capsys, "filter", sphere_obj, "--k", 30, "--low-pass", 5, "--no-cache", "--out", out
    )
    assert code == 0 and "low-pass" in text


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["geodesic", "{m}", "--vertex", "9999"], "--vertex"),
        (["geodesic", "{m}", "--vertex", "1", "--m", "-2"], "--m"),
        (["geodesic", "{m}", "--vertex", "1", "--isolines", "3"], "--isolines"),
        (["geodesic", "{m}", "--vertex", "1", "--out", "{m}"], "refusing to overwrite"),
        (["geodesic", "{m}", "--vertex", "1", "--out", "d.txt"], "unsupported output"),
        (["heat", "{m}", "--vertex", "1", "--t", "nan"], "--t"),
        (["heat", "{m}", "--vertex", "1", "--t", "1", "--curves", "c.obj"], "--isolines"),
        (["heat", "{m}", "--vertex", "1", "--t", "1", "--isolines", "-1"], "--isolines"),
        (
            ["heat", "{m}", "--vertex", "1", "--t", "1", "--isolines", "2", "--curves", "c.ply"],
            "unsupported output",
        ),
        (["heat", "{m}", "--vertex", "1", "--t", "1", "--method", "spectral"], "--k"),
        (["filter", "{m}", "--k", "10", "--band", "x", "--out", "f.obj"], "--band"),
        (["filter", "{m}", "--k", "10", "--taubin", "1", "a", "2", "--out", "f.obj"], "--taubin"),
        (["filter", "{m}", "--k", "10", "--low-pass", "11", "--out", "f.obj"], "--low-pass"),
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, sphere_obj, tmp_path, monkeypatch, argv, flag):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, *[a.replace("{m}", str(sphere_obj)) for a in argv])
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("meshlap: error:") and flag in err
    assert out == ""


def test_several_components_are_unreachable_and_null_in_json(capsys, tmp_path):
    V, F = primitives.icosphere(1)
    path = tmp_path / "two.obj"
    save_mesh(path, np.vstack([V, V + 4.0]), np.vstack([F, F + len(V)]))
    code, text, err = run_cli(capsys, "geodesic", path, "--vertex", 0, "--json", "--out",
                              tmp_path / "d.npy")  # fmt: skip
    assert code == 0, err
    assert json.loads(text)["unreachable"] == len(V)
    assert np.all(np.isinf(np.load(tmp_path / "d.npy")[len(V) :]))


# ------------------------------------------------------- hostile inputs (tests/support/hostile.py)
from tests.support import hostile  # noqa: E402

DIFFUSION_ARGV = {
    "geodesic": lambda m, out: ["geodesic", m, "--vertex", 0, "--json", "--out", out / "d.npy"],
    "heat": lambda m, out: ["heat", m, "--vertex", 0, "--t", "1e-3", "--json",
                            "--out", out / "u.npy"],
    "filter": lambda m, out: ["filter", m, "--k", 3, "--low-pass", 2, "--no-cache", "--json",
                              "--out", out / "f.obj"],
}  # fmt: skip


@pytest.mark.parametrize("command", list(DIFFUSION_ARGV))
@pytest.mark.parametrize("case", hostile.ERRORS, ids=lambda h: h.name)
def test_bad_files_one_error_line_nothing_written(capsys, tmp_path, command, case):
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    out.mkdir()
    mesh = case.build(src)
    code, stdout, err = run_cli(capsys, *DIFFUSION_ARGV[command](mesh, out))
    assert code == 2 and stdout == "" and err.count("\n") == 1, err
    assert err.startswith("meshlap: error:") and "Traceback" not in err
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("command", list(DIFFUSION_ARGV))
@pytest.mark.parametrize("case", hostile.LOADABLE, ids=lambda h: h.name)
def test_loadable_hostile_files_succeed_or_fail_cleanly(capsys, tmp_path, command, case):
    """Repaired, non-manifold, degenerate or multi-component files: a result (finite where a
    path exists) or one clear error line, never an internal error."""
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    out.mkdir()
    mesh = case.build(src)
    code, stdout, err = run_cli(capsys, *DIFFUSION_ARGV[command](mesh, out))
    assert "internal error" not in err and "Traceback" not in err, err
    if code == 2:
        assert stdout == "" and err.strip().splitlines()[-1].startswith("meshlap: error:")
        return
    assert code == 0, err
    r = json.loads(stdout)
    if command == "geodesic":
        d = np.load(out / "d.npy")
        assert d[0] == 0.0 or r["unreachable"] == len(d) - 1
        assert np.isfinite(d).sum() + r["unreachable"] == len(d)
    elif command == "heat":
        assert np.isfinite(np.load(out / "u.npy")).all()
        assert r["total_heat"] == pytest.approx(1.0, rel=1e-4)  # two scales: τλ up to 1e10
    else:  # (a low-pass may flatten a tiny mesh: read the numbers, not a validated mesh)
        rows = [x.split()[1:] for x in (out / "f.obj").read_text().splitlines() if x[:2] == "v "]
        assert len(rows) == r["n_vertices"] if "n_vertices" in r else len(rows) > 0
        assert np.isfinite(np.array(rows, dtype=float)).all()
