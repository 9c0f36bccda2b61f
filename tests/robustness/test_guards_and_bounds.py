"""Hostile round 4 on the commands added in wave 3 (``geodesic``, ``heat``, ``filter``,
``curvature --estimator``, ``curvature-study``, ``exercises init``, ``animate``): every case
that crashed, hung, blew up or said something misleading, each with the fix's promise.

Commands run in process (``main``) unless a native library could crash the interpreter:
those run in a subprocess, so that a segfault fails the test instead of killing pytest.
Counts and radii a user types are bounded by what can be shown or stored, checked before
any work: those tests assert the refusal and that no work was started (a spy on the work).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from meshlap_core import primitives, save_mesh
from meshlap_core.cli import main
from meshlap_core.errors import MeshError


def _error(capsys) -> str:
    """The last line on stderr (the command's one error line)."""
    err = capsys.readouterr().err.strip()
    return err.splitlines()[-1] if err else ""


def _refused(argv: list[str], capsys, flag: str, *words: str) -> str:
    """``main(argv)`` exits 2 with one line naming ``flag`` and saying ``words``."""
    code = main(argv)
    line = _error(capsys)
    assert code == 2, line
    assert line.startswith(f"meshlap: error: {flag}:"), line
    for w in words:
        assert w in line, line
    assert "internal error" not in line
    return line


@pytest.fixture
def sphere(tmp_path: Path) -> Path:
    path = tmp_path / "sphere.obj"
    save_mesh(path, *primitives.icosphere(2))
    return path


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))


def _in_subprocess(code: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    """Run ``code`` in a fresh interpreter (a segfault there is a return code of -11 here)."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )


# ------------------------------------------------------------------ 2. native crashes

# Each: the mesh built in the child, the call, and what it must print. libigl's MMP crashed
# (exit 139) on a non-manifold edge, a face listed twice and a repeated-vertex face, and on a
# source at an unreferenced vertex; its heat method on an unreferenced source.
SEGFAULT_CASES = {
    "exact, non-manifold edge": (
        "V = np.vstack([V, [[2.0, 2.0, 2.0]]]); F = np.vstack([F, [[F[0, 0], F[0, 1], 42]]])",
        "exact_distance(V, F, [0])",
        "shared by 3 faces",
    ),
    "exact, a face listed twice": (
        "F = np.vstack([F, F[:1]])",
        "exact_distance(V, F, [0])",
        "shared by 3 faces",
    ),
    "exact, a repeated-vertex face": (
        "F = np.vstack([F, [[0, 0, 1]]])",
        "exact_distance(V, F, [0])",
        "repeats a vertex",
    ),
    "exact, an unreferenced source": (
        "V = np.vstack([[[5.0, 5.0, 5.0]], V]); F = F + 1",
        "exact_distance(V, F, [0])",
        "ok 0.0 inf 1",
    ),
    "igl-heat, an unreferenced source": (
        "V = np.vstack([V, [[5.0, 5.0, 5.0]]])",
        "igl_heat_distance(V, F, [42])",
        "ok 0.0 inf 1",
    ),
    "igl-heat, an unreferenced vertex beside the source": (
        "V = np.vstack([[[5.0, 5.0, 5.0]], V]); F = F + 1",
        "igl_heat_distance(V, F, [1])",
        "ok 0.0 inf 42",
    ),
}


@pytest.mark.parametrize("case", sorted(SEGFAULT_CASES))
def test_libigl_never_gets_what_crashes_it(case):
    """Run three times each (libigl's heat method crashed in 2 of 6 runs): a clear error or
    an answer (0 at the source, ``inf`` where no path reaches, the count of finite values),
    never a dead interpreter."""
    build, call, expect = SEGFAULT_CASES[case]
    code = f"""
        import numpy as np
        from meshlap_core.errors import MeshError
        from meshlap_core.primitives import icosphere
        from meshlap_core.diffusion import exact_distance, igl_heat_distance
        V, F = icosphere(1)
        {build}
        try:
            d = {call}
        except MeshError as exc:
            print("refused", exc)
        else:
            src = int(np.argmin(d))
            print("ok", d[src], d.max(), int(np.isfinite(d).sum()))
    """
    for _ in range(3):
        res = _in_subprocess(code)
        assert res.returncode == 0, f"crashed ({res.returncode}): {res.stderr[-500:]}"
        assert expect in res.stdout, res.stdout


def test_the_exact_distance_of_a_mesh_at_1e_55_is_scaled_not_a_memory_blow_up():
    """MMP's absolute tolerances at 1e-55 filled 4 GB in 27 s: the component is solved at unit
    scale and scaled back. Run under a 1.5 GB address-space limit, in a subprocess."""
    code = """
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (1536 * 2**20, 1536 * 2**20))
        import numpy as np
        from meshlap_core.primitives import icosphere
        from meshlap_core.diffusion import exact_distance
        V, F = icosphere(2)
        tiny = exact_distance(V * 1e-55, F, [0])
        unit = exact_distance(V, F, [0])
        print("ratio", float(np.max(np.abs(tiny / 1e-55 - unit))))
    """
    res = _in_subprocess(code)
    assert res.returncode == 0, res.stderr[-800:]
    assert float(res.stdout.split()[-1]) < 1e-9


# ------------------------------------------------------------------ 4. --method igl-heat


def _two_spheres(tmp_path: Path) -> Path:
    V, F = primitives.icosphere(1)
    path = tmp_path / "two.obj"
    shifted = V + np.array([3.0, 0.0, 0.0])
    save_mesh(path, np.vstack([V, shifted]), np.vstack([F, F + len(V)]))
    return path


def test_igl_heat_puts_another_component_at_infinity_and_counts_it(tmp_path, capsys):
    path = _two_spheres(tmp_path)
    for method in ("igl-heat", "heat", "exact"):
        assert main(["geodesic", str(path), "--vertex", "0", "--method", method, "--json"]) == 0
        r = json.loads(capsys.readouterr().out)
        assert r["unreachable"] == 42, method  # the second sphere, whatever the method
        assert r["max"] < 3.5  # the finite distances are on the first sphere


def test_igl_heat_on_a_lone_triangle_is_its_straight_distance(tmp_path, capsys):
    """libigl's precomputation failed on a single triangle (exit 1): a flat triangle's
    geodesic distance is the straight one."""
    path = tmp_path / "tri.obj"
    save_mesh(path, np.array([[0.0, 0, 0], [3, 0, 0], [0, 4, 0]]), np.array([[0, 1, 2]]))
    out = tmp_path / "d.npy"
    args = ["geodesic", str(path), "--vertex", "1", "--method", "igl-heat", "--out", str(out)]
    assert main(args) == 0, capsys.readouterr().err
    np.testing.assert_allclose(np.load(out), [3.0, 0.0, 5.0], atol=1e-12)
    # and a lone triangle beside a sphere: each component on its own
    V, F = primitives.icosphere(1)
    tri = np.array([[5.0, 0, 0], [8, 0, 0], [5, 4, 0]])
    path2 = tmp_path / "lone.obj"
    save_mesh(path2, np.vstack([V, tri]), np.vstack([F, [[42, 43, 44]]]))
    args = ["geodesic", str(path2), "--vertex", "0", "--vertex", "43", "--method", "igl-heat"]
    assert main([*args, "--out", str(out)]) == 0, capsys.readouterr().err
    np.testing.assert_allclose(np.load(out)[42:], [3.0, 0.0, 5.0], atol=1e-12)


def test_igl_heat_refuses_a_nan_time_and_honours_m(tmp_path, sphere, capsys):
    from meshlap_core.diffusion import igl_heat_distance, mean_edge_length

    V, F = primitives.icosphere(2)
    for t in (float("nan"), 0.0, -1.0, float("inf"), True):
        with pytest.raises(MeshError, match=r"^t: "):
            igl_heat_distance(V, F, [0], t=t)
    _refused(["geodesic", str(sphere), "--vertex", "0", "--method", "igl-heat", "--m", "nan"],
             capsys, "--m")  # fmt: skip
    # --m is libigl's t = m h² (it was ignored)
    out = tmp_path / "d.npy"
    args = ["geodesic", str(sphere), "--vertex", "0", "--method", "igl-heat", "--out", str(out)]
    assert main([*args, "--m", "4"]) == 0
    t = 4 * mean_edge_length(V, F) ** 2
    np.testing.assert_allclose(np.load(out), igl_heat_distance(V, F, [0], t=t), atol=1e-12)
    # flags a method would ignore are refused
    _refused(["geodesic", str(sphere), "--vertex", "0", "--method", "exact", "--m", "2"],
             capsys, "--m", "exact")  # fmt: skip
    _refused(["geodesic", str(sphere), "--vertex", "0", "--method", "igl-heat",
              "--boundary", "neumann"], capsys, "--boundary")  # fmt: skip


# ------------------------------------------------------------------ 5. bounded counts


def test_heat_steps_are_bounded_before_any_work(sphere, capsys, monkeypatch):
    from meshlap_core.cli import heat as heat_cli

    monkeypatch.setattr(heat_cli, "load_mesh", lambda *a: pytest.fail("work started"))
    _refused(["heat", str(sphere), "--vertex", "0", "--t", "0.1", "--steps", "1000000000"],
             capsys, "--steps", "at most 1000")  # fmt: skip
    from meshlap_core.diffusion import HeatDiffusion

    hd = HeatDiffusion(*primitives.icosphere(1))
    with pytest.raises(MeshError, match=r"^steps: must be at most 1000"):
        hd.euler(np.ones(42), 0.1, 10**9)


def test_isolines_are_bounded_before_any_work(sphere, capsys, monkeypatch, tmp_path):
    from meshlap_core.cli import geodesic as geo_cli

    monkeypatch.setattr(geo_cli, "load_mesh", lambda *a: pytest.fail("work started"))
    curves = str(tmp_path / "c.obj")
    _refused(["geodesic", str(sphere), "--vertex", "0", "--isolines", "100000", "--curves",
              curves], capsys, "--isolines", "at most 1000")  # fmt: skip
    assert not os.path.exists(curves)


def test_a_quadric_radius_beyond_the_mesh_is_refused_at_once(sphere, capsys):
    for radius in ("1e9", "1e20"):
        _refused(["curvature", str(sphere), "--estimator", "quadric", "--radius", radius],
                 capsys, "--radius", "edge rings reach past the whole mesh")  # fmt: skip
    _refused(["curvature", str(sphere), "--estimator", "quadric", "--radius", "1"],
             capsys, "--radius", ">= 2")  # fmt: skip


def test_fitting_work_is_bounded_with_the_largest_radius_named(monkeypatch):
    """A radius whose balls would visit more than MAX_FIT_PAIRS pairs (the jet at 1e308 ran
    quadratic for minutes on armadillo) is refused before the fit, naming a radius that
    fits; the bound lowered here so that a small mesh shows it."""
    from meshlap_core.curvature import fields, jet_fit
    from meshlap_core.curvature.estimators import estimate_curvature

    V, F = primitives.icosphere(3)
    monkeypatch.setattr(jet_fit, "MAX_FIT_PAIRS", 20_000)
    monkeypatch.setattr(fields, "MAX_FIT_PAIRS", 20_000)
    monkeypatch.setattr(jet_fit, "_chunk", lambda *a: pytest.fail("work started"))
    with pytest.raises(MeshError, match=r"^radius: .*pairs to fit.*radius below about"):
        estimate_curvature(V, F, "jet", radius=1.0)
    with pytest.raises(MeshError, match=r"^radius: .*pairs to fit.*use at most \d+ rings"):
        estimate_curvature(V, F, "quadric", radius=8)


def test_a_long_heat_time_is_refused_not_an_internal_error(sphere, capsys):
    """``geodesic --m 1e20`` ended in numpy's LinAlgError (exit 1): M + tK is singular in
    double precision; the largest m for the mesh is named."""
    for m in ("1e20", "1e300"):
        _refused(["geodesic", str(sphere), "--vertex", "0", "--m", m], capsys, "--m",
                 "singular", "at most")  # fmt: skip


# ------------------------------------------------------------------ 6. internal errors


def test_huge_integers_and_nan_give_clear_errors(sphere, tmp_path, capsys):
    out = str(tmp_path / "f.obj")
    base = ["filter", str(sphere), "--k", "10", "--no-cache", "--out", out]
    _refused([*base, "--band", "0:1000000000000000000000000000000"], capsys, "--band")
    _refused([*base, "--explicit", "0.1", "1000000000000000000000000000000"], capsys,
             "--explicit", "at most")  # fmt: skip
    _refused([*base, "--explicit", "0.1", "2.5"], capsys, "--explicit", "integer")
    _refused([*base, "--explicit", "nan", "3"], capsys, "--explicit", "finite")
    _refused([*base, "--explicit", "5", "400"], capsys, "--explicit", "overflows")
    for est in ("quadric", "jet"):
        _refused(["curvature", str(sphere), "--estimator", est, "--radius", "nan"], capsys,
                 "--radius")  # fmt: skip
    assert not os.path.exists(out)


# ------------------------------------------------------------------ 7. silently wrong curvature


def test_the_quadric_fit_at_1e_55_gives_the_curvature_not_zero():
    from meshlap_core.curvature.estimators import estimate_curvature

    V, F = primitives.icosphere(3)
    unit = estimate_curvature(V, F, "quadric")
    for s in (1e-55, 1e74):
        p = estimate_curvature(V * s, F, "quadric")
        np.testing.assert_allclose(p.k1 * s, unit.k1, rtol=1e-6)
        np.testing.assert_allclose(p.K * s * s, unit.K, rtol=1e-6)
        assert np.median(p.K) == pytest.approx(np.median(unit.K) / s**2, rel=1e-6)  # not 0


def test_a_failed_quadric_fit_is_said_not_reported_as_zero():
    """libigl lists the vertices whose fit failed and gives them 0 (a tetrahedron: K = 0 at
    every corner): refused."""
    from meshlap_core.curvature.estimators import estimate_curvature

    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    with pytest.raises(MeshError, match=r"quadric fit failed at 4 vertices"):
        estimate_curvature(V, F, "quadric", radius=2)


def test_the_jet_refuses_a_ball_below_the_edges_or_over_the_whole_mesh(sphere, capsys):
    _refused(["curvature", str(sphere), "--estimator", "jet", "--radius", "0.01"], capsys,
             "--radius", "too small", "needs 6")  # fmt: skip
    _refused(["curvature", str(sphere), "--estimator", "jet", "--radius", "1e308"], capsys,
             "--radius", "half the mesh's bounding-box diagonal")  # fmt: skip
    # the automatic radius of a mesh at 1e74 (it overflowed to inf: "got None")
    from meshlap_core.curvature.estimators import estimate_curvature

    V, F = primitives.icosphere(3)
    unit = estimate_curvature(V, F, "jet")
    big = estimate_curvature(V * 1e74, F, "jet")
    np.testing.assert_allclose(big.k1 * 1e74, unit.k1, rtol=1e-6)


def test_directions_and_field_on_the_same_path_are_refused(sphere, tmp_path, capsys):
    x = str(tmp_path / "x.npy")
    _refused(["curvature", str(sphere), "--estimator", "rusinkiewicz", "--directions", x,
              "--out", x], capsys, "--directions", "same file")  # fmt: skip
    assert not os.path.exists(x)


# ------------------------------------------------------------------ 9. curvature-study


@pytest.mark.parametrize(
    ("flag", "value"),
    [("--flips", "-0.5"), ("--flips", "nan"), ("--flips", "2"), ("--jitter", "-1"),
     ("--jitter", "nan")],
)  # fmt: skip
def test_curvature_study_refuses_bad_fractions_naming_the_flag(flag, value, capsys):
    _refused(["curvature-study", "--surfaces", "sphere", "--estimators", "cotan", "--levels",
              "6", flag, value], capsys, flag)  # fmt: skip


def test_curvature_study_empty_outputs_and_duplicate_levels(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    base = ["curvature-study", "--surfaces", "sphere", "--estimators", "cotan"]
    for flag in ("--csv", "--figure"):
        _refused([*base, "--levels", "6", flag, ""], capsys, flag, "empty")
    assert main([*base, "--levels", "6,8,6,8", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["res"] for r in rows] == [6, 8]


# ------------------------------------------------------------------ 10. words and flags


def test_vertex_indices_out_of_range_are_shown_as_typed(sphere, capsys):
    for v in ("100000000000000000000", "9223372036854775808"):
        _refused(["geodesic", str(sphere), "--vertex", v], capsys, "--vertex", v, "out of range")
    _refused(["heat", str(sphere), "--vertex", "-1", "--t", "1"], capsys, "--vertex", "-1")


def test_filter_checks_gain_stl_and_taubin_before_the_work(sphere, tmp_path, capsys, monkeypatch):
    from meshlap_core.cli import spectral

    monkeypatch.setattr(spectral, "compute_basis", lambda *a: pytest.fail("work started"))
    out = str(tmp_path / "f.obj")
    base = ["filter", str(sphere), "--k", "10", "--no-cache"]
    _refused([*base, "--band", "2:5", "--gain", "nan", "--out", out], capsys, "--gain", "finite")
    _refused([*base, "--low-pass", "4", "--gain", "3", "--out", out], capsys, "--gain")
    _refused([*base, "--low-pass", "4", "--out", str(tmp_path / "f.stl")], capsys,
             str(tmp_path / "f.stl"), ".stl")  # fmt: skip
    monkeypatch.undo()
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))
    _refused([*base, "--taubin", "0.5", "0.6", "2", "--out", out], capsys, "--taubin", "MU < -LAM")


def test_heat_refuses_flags_of_the_other_method(sphere, capsys):
    base = ["heat", str(sphere), "--vertex", "0", "--t", "0.1"]
    _refused([*base, "--method", "euler", "--k", "10"], capsys, "--k")
    _refused([*base, "--method", "spectral", "--k", "10", "--steps", "3"], capsys, "--steps")
    _refused([*base, "--method", "euler", "--no-cache"], capsys, "--no-cache")


def test_animate_refuses_another_panels_options(sphere, tmp_path, capsys):
    pytest.importorskip("polyscope")
    args = ["animate", str(sphere), "--panel", "smoothing", "--out", str(tmp_path / "a.gif")]
    from meshlap_app.registry import animated

    options = animated()["diffusion"].animation_declared().options
    heat_flag = next(o.flag for o in options if "heat" in o.flag)
    value = "0" if heat_flag != "--heat" else None
    argv = [*args, heat_flag] + ([value] if value is not None else [])
    line = _refused(argv, capsys, heat_flag, "--panel diffusion")
    assert "smoothing" in line
    assert not os.path.exists(tmp_path / "a.gif")


def test_file_names_are_printed_escaped(sphere, tmp_path, capsys):
    out = tmp_path / "a\x1b[31mred.csv"
    assert main(["curvature", str(sphere), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "\x1b" not in text and "a\\x1b[31mred.csv" in text
    assert out.is_file()


# ------------------------------------------------------------------ exercises init


def test_exercises_init_refuses_an_empty_folder_name(tmp_path, monkeypatch, capsys):
    """``exercises init ''`` once wrote into the current folder (``Path('')`` is ``.``)."""
    monkeypatch.chdir(tmp_path)
    assert main(["exercises", "init", ""]) == 2
    line = _error(capsys)
    assert line.startswith("meshlap: error: DIR:") and "empty" in line
    assert os.listdir(tmp_path) == []
    assert main(["exercises", "init", "  "]) == 2 and os.listdir(tmp_path) == []
    assert main(["exercises", "init", "sub"]) == 0 and (Path("sub") / "exercises.py").is_file()
