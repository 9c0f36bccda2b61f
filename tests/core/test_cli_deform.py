"""CLI: meshlap deform (through main(): the written shape, the report, every flag's errors)."""

import json

import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.cli import main
from meshlap_core.deform import (
    ArapDeformer,
    grow_handles,
    make_deformer,
    rigid_targets,
    rotation_matrix,
)
from meshlap_core.io import load_mesh, save_mesh
from tests.support import hostile


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def sphere_obj(tmp_path):
    path = tmp_path / "sphere.obj"
    save_mesh(path, *primitives.bumpy_sphere(2))
    return path


def test_biharmonic_writes_the_core_solution_and_one_json_object(capsys, sphere_obj, tmp_path):
    out = tmp_path / "bent.obj"
    code, text, err = run_cli(
        capsys, "deform", sphere_obj, "--handle", "3,40", "--fixed", "100,101",
        "--rotate", "0,0,1,30", "--move", "0.1,0,0.2", "--method", "biharmonic",
        "--out", out, "--json",
    )  # fmt: skip
    assert code == 0, err
    assert len(text.strip().splitlines()) == 1
    r = json.loads(text)
    mesh = load_mesh(sphere_obj)
    V, F = mesh.V, mesh.F
    solver = make_deformer("biharmonic", V, F, [3, 40], [100, 101])
    expected = solver.update(
        rigid_targets(V, np.array([3, 40]), rotation_matrix([0, 0, 1], 30), [0.1, 0, 0.2])
    )
    np.testing.assert_allclose(load_mesh(out).V, expected, atol=1e-6)  # OBJ text precision
    assert r["handles"] == [3, 40] and r["n_handle_vertices"] == 2 and r["n_fixed"] == 2
    assert r["energy"] == pytest.approx(solver.energy(), rel=1e-9)
    assert r["system"]["n_unknowns"] == len(V) - 4 and r["out"] == str(out)
    assert r["handle_error"] == 0.0 and r["rotation_error"]["max"] > 0


def test_arap_runs_the_iterations_asked_and_grows_the_handles(capsys, sphere_obj, tmp_path):
    out = tmp_path / "arap.ply"
    code, text, err = run_cli(
        capsys, "deform", sphere_obj, "--handle", 7, "--handle", 60, "--radius", "0.3",
        "--move", "0,0.2,0", "--method", "arap", "--iters", 4, "--out", out, "--json",
    )  # fmt: skip
    assert code == 0, err
    r = json.loads(text)
    V, F = load_mesh(sphere_obj).V, load_mesh(sphere_obj).F
    handles = grow_handles(V, F, [7, 60], 0.3).vertices
    assert r["n_handle_vertices"] == len(handles) > 2 and r["iters"] == 4
    arap = ArapDeformer(V, F, handles)
    arap.set_targets(V[handles] + [0, 0.2, 0])
    arap.run(4)
    np.testing.assert_allclose(r["energies"], arap.energies, rtol=1e-9)
    np.testing.assert_allclose(load_mesh(out).V, arap.positions, atol=1e-6)


def test_negative_first_numbers_are_given_with_an_equals_sign(capsys, sphere_obj, tmp_path):
    out = tmp_path / "o.obj"
    code, text, err = run_cli(
        capsys, "deform", sphere_obj, "--handle", 3, "--rotate=-1,0,0,-30", "--move=-0.1,0,0",
        "--method", "harmonic", "--out", out, "--json",
    )  # fmt: skip
    assert code == 0, err
    r = json.loads(text)
    assert r["rotate"] == [-1.0, 0.0, 0.0, -30.0] and r["move"] == [-0.1, 0.0, 0.0]
    V = load_mesh(sphere_obj).V
    np.testing.assert_allclose(load_mesh(out).V[3], V[3] + [-0.1, 0, 0], atol=1e-6)


@pytest.mark.parametrize("method", ["laplacian", "harmonic", "triharmonic"])
def test_text_report_names_the_energy_and_the_system(capsys, sphere_obj, tmp_path, method):
    out = tmp_path / "o.off"
    code, text, err = run_cli(
        capsys, "deform", sphere_obj, "--handle", 3, "--move", "0,0,0.1", "--method", method,
        "--out", out,
    )  # fmt: skip
    assert code == 0, err
    assert text.startswith(f"{method} deformation") and "unknowns" in text
    assert f"wrote {out}" in text and out.is_file()


BAD = [
    (["--handle", "a"], "--handle"),
    (["--handle", "1.5"], "--handle"),
    (["--handle", ""], "--handle"),
    (["--handle", "99999"], "--handle"),
    (["--handle", "-3"], "--handle"),
    (["--handle", ",".join(["1"] * 20000)], "--handle"),
    (["--fixed", "3"], "--fixed"),
    (["--fixed", "x"], "--fixed"),
    (["--fixed", "100000"], "--fixed"),
    (["--radius", "-1"], "--radius"),
    (["--radius", "nan"], "--radius"),
    (["--radius", "big"], "--radius"),
    (["--rotate", "0,0,1"], "--rotate"),
    (["--rotate", "0,0,0,30"], "--rotate"),
    (["--rotate", "0,0,1,inf"], "--rotate"),
    (["--rotate", "a,b,c,d"], "--rotate"),
    (["--move", "1,2"], "--move"),
    (["--move", "0,nan,0"], "--move"),
    (["--move", "1e300,0,0"], "--move"),
    (["--iters", "5"], "--iters"),  # not ARAP
]


@pytest.mark.parametrize(("extra", "flag"), BAD)
def test_bad_flags_exit_2_with_one_line_naming_the_flag(capsys, sphere_obj, tmp_path, extra, flag):
    out = tmp_path / "o.obj"
    args = ["deform", sphere_obj, "--handle", 3, "--method", "biharmonic", "--out", out]
    code, text, err = run_cli(capsys, *args, *extra)
    assert code == 2
    assert err.startswith(f"meshlap: error: {flag}:") and err.count("\n") == 1, err
    assert text == "" and not out.exists()


@pytest.mark.parametrize("bad", ["-1", "1.5", "1e3", "100001", "9" * 5000])
def test_bad_arap_iterations_are_refused(capsys, sphere_obj, tmp_path, bad):
    code, _, err = run_cli(
        capsys, "deform", sphere_obj, "--handle", 3, "--method", "arap", "--iters", bad,
        "--out", tmp_path / "o.obj",
    )  # fmt: skip
    assert code == 2 and err.startswith("meshlap: error: --iters:") and err.count("\n") == 1


def test_outputs_are_checked_before_the_work_and_the_input_never_overwritten(
    capsys, sphere_obj, tmp_path
):
    before = sphere_obj.read_bytes()
    for out, words in (
        (sphere_obj, "input"),
        (tmp_path / "o.xyz", "unsupported output type"),
        (tmp_path / "missing" / "o.obj", "missing"),
    ):
        code, _, err = run_cli(
            capsys, "deform", sphere_obj, "--handle", 3, "--method", "arap", "--out", out
        )
        assert code == 2 and words in err and err.count("\n") == 1, err
    assert sphere_obj.read_bytes() == before


def test_a_mesh_that_cannot_be_read_is_one_line(capsys, tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    code, _, err = run_cli(
        capsys, "deform", bad, "--handle", 0, "--method", "arap", "--out", tmp_path / "o.obj"
    )
    assert code == 2 and err.startswith("meshlap: error:") and err.count("\n") == 1


@pytest.mark.parametrize("method", ["laplacian", "triharmonic", "arap"])
@pytest.mark.parametrize("case", hostile.CORPUS, ids=lambda h: h.name)
def test_hostile_files_deform_or_fail_with_one_line(capsys, tmp_path, case, method):
    """Every file of the robustness corpus: one error line (and no output) for the broken
    ones; a finite mesh for those that load, whatever their repairs (a handle on vertex 0
    moved by a tenth of the mesh's size)."""
    src = tmp_path / "in"
    src.mkdir()
    mesh = case.build(src)
    out = tmp_path / "o.obj"
    iters = ["--iters", 2] if method == "arap" else []
    size = 1.0 if case.expect == "error" else float(np.ptp(load_mesh(mesh).V, axis=0).max())
    code, text, err = run_cli(
        capsys, "deform", mesh, "--handle", 0, "--rotate", "1,0,0,40", "--move",
        f"{0.1 * size!r},0,0", "--method", method, *iters, "--out", out, "--json",
    )  # fmt: skip
    if case.expect == "error":
        assert code == 2 and text == "" and err.count("\n") == 1 and not out.exists(), err
        assert err.startswith("meshlap: error: ") and "Traceback" not in err
        return
    assert code == 0, err
    r = json.loads(text)
    assert np.isfinite(load_mesh(out).V).all() and np.isfinite(r["energy"])
