"""CLI: ``meshlap flatten`` (through main(): the written OBJ, the one JSON object, and the error
rules: bad combinations refused by flag, hostile files one error line, outputs untouched)."""

import json

import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.cli import main
from meshlap_core.flatten import Flattener, unit_square_uv
from meshlap_core.io import load_mesh, save_mesh
from tests.support import hostile

SENTINEL = b"an existing file that a failed run must not touch\n"


def run_cli(capsys, *argv):
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # (argparse's own errors: one line, exit 2)
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_error_line(code, out, err, *names):
    assert code == 2, err
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("meshlap: error: "), err
    assert any(n in err for n in names), (names, err)
    return err.strip()


def read_texture(path):
    """``(vt (t,2), f (m,3,2))`` of an OBJ, by hand (1-based ``v/vt`` pairs)."""
    vt, faces = [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "vt":
            vt.append([float(x) for x in parts[1:]])
        elif parts and parts[0] == "f":
            faces.append([[int(i) for i in c.split("/")] for c in parts[1:]])
    return np.array(vt), np.array(faces)


@pytest.fixture
def grid_obj(tmp_path):
    path = tmp_path / "grid.obj"
    save_mesh(path, *primitives.grid(9, 9))
    return path


@pytest.fixture
def torus_obj(tmp_path):
    path = tmp_path / "torus.obj"
    save_mesh(path, *primitives.torus_mesh(16, 8))
    return path


def test_tutte_writes_the_map_as_texture_coordinates(capsys, grid_obj, tmp_path):
    out = tmp_path / "flat.obj"
    code, text, err = run_cli(
        capsys, "flatten", grid_obj, "--method", "tutte", "--out", out, "--json"
    )
    assert code == 0, err
    assert text.count("\n") == 1  # exactly one JSON object
    r = json.loads(text)
    mesh = load_mesh(grid_obj)
    want = unit_square_uv(Flattener(mesh.V, mesh.F).map("tutte").uv)
    vt, faces = read_texture(out)
    np.testing.assert_allclose(vt, want, atol=1e-15)
    np.testing.assert_array_equal(faces[:, :, 0] - 1, mesh.F)
    assert r["distortion"]["method"] == "tutte" and r["distortion"]["boundary"] == "circle"
    assert r["distortion"]["flipped"] == 0 and r["disk"]["how"] == "disk"
    assert r["out"] == str(out) and r["n_faces"] == len(mesh.F)


def test_a_torus_is_cut_and_its_seams_get_two_texture_coordinates(capsys, torus_obj, tmp_path):
    out = tmp_path / "flat.obj"
    code, text, err = run_cli(
        capsys, "flatten", torus_obj, "--method", "scp", "--out", out, "--json"
    )
    assert code == 0, err
    r = json.loads(text)
    assert r["disk"]["how"] == "genus-cut" and "genus 1" in r["disk"]["messages"][0]
    vt, _ = read_texture(out)
    mesh = load_mesh(out)
    original = load_mesh(torus_obj)
    np.testing.assert_array_equal(mesh.V, original.V)
    np.testing.assert_array_equal(mesh.F, original.F)
    assert len(vt) == r["disk"]["vertices"] > len(mesh.V)
    assert vt.min() >= 0 and vt.max() <= 1
    assert r["distortion"]["angle_mean"] < 1.2


def test_arap_reports_its_iterations_and_energy_in_text(capsys, grid_obj, tmp_path):
    out = tmp_path / "flat.obj"
    code, text, err = run_cli(
        capsys,
        "flatten",
        grid_obj,
        "--method",
        "arap",
        "--iters",
        4,
        "--boundary",
        "circle",
        "--out",
        out,
    )
    assert code == 0, err
    assert "arap map (circle boundary)" in text and "4 iterations" in text
    assert "angle distortion" in text and f"wrote {out}" in text


def test_a_seam_is_cut_first(capsys, grid_obj, tmp_path):
    out = tmp_path / "flat.obj"
    code, text, err = run_cli(
        capsys, "flatten", grid_obj, "--method", "lscm", "--seam", "0,10,20", "--out", out, "--json"
    )
    assert code == 0, err
    r = json.loads(text)
    assert r["disk"]["how"] == "seam" and r["disk"]["cut_edges"] == 2
    assert r["disk"]["vertices"] == 81 + 2


@pytest.mark.parametrize(
    "extra, flag, words",
    [
        (["--method", "lscm", "--boundary", "circle"], "--boundary", "free"),
        (["--method", "scp", "--boundary", "square"], "--boundary", "free"),
        (["--method", "tutte", "--boundary", "free"], "--boundary", "circle or square"),
        (["--method", "harmonic", "--iters", "5"], "--iters", "arap only"),
        (["--method", "arap", "--iters", "-1"], "--iters", "between"),
        (["--method", "arap", "--iters", "1e3"], "--iters", "integer"),
        (["--method", "arap", "--iters", "9" * 5000], "--iters", "at most"),
        (["--method", "arap", "--iters", str(10**6)], "--iters", "between"),
        (["--method", "tutte", "--seam", "0,x"], "--seam", "comma-separated"),
        (["--method", "tutte", "--seam", "0,999"], "--seam", "out of range"),
        (["--method", "tutte", "--seam", "0,40"], "--seam", "not joined by an edge"),
        (["--method", "tutte", "--seam", "0"], "--seam", "two vertices"),
        (["--method", "tutte", "--seam", "0,10,20,30,40,50,60,70,80"], "--seam", "pieces"),
        (["--method", "tutte", "--out", "x.ply"], "x.ply", "obj"),
        (["--method", "tutte", "--out", ""], "--out", "empty"),
        (["--method", "conformal"], "--method", "invalid choice"),
        ([], "--method", "required"),
    ],
)
def test_bad_options_are_refused_by_flag_and_the_output_kept(
    capsys, grid_obj, tmp_path, extra, flag, words
):
    out = tmp_path / "flat.obj"
    out.write_bytes(SENTINEL)
    argv = ["flatten", grid_obj, *extra]
    if "--out" not in extra:
        argv += ["--out", out]
    code, text, err = run_cli(capsys, *argv)
    line = assert_one_error_line(code, text, err, flag)
    assert words in line.lower()
    assert out.read_bytes() == SENTINEL
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flat.obj", "grid.obj"]


def test_the_input_is_never_overwritten(capsys, grid_obj):
    before = grid_obj.read_bytes()
    code, text, err = run_cli(capsys, "flatten", grid_obj, "--method", "tutte", "--out", grid_obj)
    assert_one_error_line(code, text, err, str(grid_obj))
    assert grid_obj.read_bytes() == before


def test_a_mesh_of_two_pieces_is_refused_naming_the_file(capsys, tmp_path):
    V, F = primitives.grid(4, 4)
    path = tmp_path / "two.obj"
    save_mesh(path, np.vstack([V, V + np.array([3.0, 0, 0])]), np.vstack([F, F + len(V)]))
    code, text, err = run_cli(
        capsys, "flatten", path, "--method", "tutte", "--out", tmp_path / "o.obj"
    )
    line = assert_one_error_line(code, text, err, str(path))
    assert "2 connected components" in line
    assert not (tmp_path / "o.obj").exists()


@pytest.mark.parametrize("case", hostile.ERRORS, ids=lambda h: h.name)
def test_hostile_files_give_one_error_line(capsys, tmp_path, case):
    src = tmp_path / "in"
    src.mkdir()
    mesh = case.build(src)
    out = tmp_path / "flat.obj"
    out.write_bytes(SENTINEL)
    code, text, err = run_cli(capsys, "flatten", mesh, "--method", "harmonic", "--out", out)
    line = assert_one_error_line(code, text, err, str(mesh))
    assert any(w in line.lower() for w in case.words), line
    assert out.read_bytes() == SENTINEL
    assert not [p for p in tmp_path.rglob("*.tmp")]


@pytest.mark.parametrize("case", hostile.LOADABLE, ids=lambda h: h.name)
def test_loadable_hostile_files_flatten_or_say_why(capsys, tmp_path, case):
    """A file that loads is flattened (its OBJ reads back with the same faces) or refused in
    one line naming it (non-manifold, several pieces): never a traceback."""
    src = tmp_path / "in"
    src.mkdir()
    mesh = case.build(src)
    out = tmp_path / "flat.obj"
    code, text, err = run_cli(capsys, "flatten", mesh, "--method", "lscm", "--out", out, "--json")
    if code == 0:
        r = json.loads(text)
        assert load_mesh(out).n_faces == r["n_faces"]
        assert len(read_texture(out)[0]) == r["disk"]["vertices"]
    else:
        line = assert_one_error_line(code, text, err, str(mesh))
        assert any(
            w in line for w in ("manifold", "oriented", "components", "pieces", "definite")
        ), line
        assert not out.exists()
