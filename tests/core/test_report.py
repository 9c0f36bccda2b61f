"""``meshlap report``: a quick report on the bundled assets builds, its figures are valid PNGs, its
tables have the expected columns and the numbers in them obey the mathematics; the HTML is
well-formed; a failing screenshot function degrades to matplotlib renderings with a note, and the
screenshot function gets the mesh, panel and options the report asks for."""

from __future__ import annotations

import csv
import json
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from meshlap_app.screenshots import ViewerScreenshots

from meshlap_core.cli import main
from meshlap_core.course_report import SECTIONS, build_report, parse_sections
from meshlap_core.errors import MeshError

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"

# the columns every table must have (written here, independently of the module)
EXPECTED_COLUMNS = {
    "onering_cube": [
        "vertex",
        "valence",
        "kind",
        "neighbours_ccw",
        "neighbours_cw",
        "ccw_pairs_are_faces",
    ],
    "uniform_ranges": [
        "mesh",
        "field",
        "vertices",
        "n",
        "min",
        "max",
        "mean",
        "median",
        "p01",
        "p99",
    ],
    "gauss_bonnet": ["mesh", "euler_characteristic", "sum_K_A", "two_pi_chi", "abs_difference"],
    "helicoid_origin": ["quantity", "computed", "closed_form", "abs_difference"],
    "helicoid_coursework": [
        "u",
        "v",
        "quantity",
        "signs",
        "computed",
        "closed_form",
        "abs_difference",
        "outward",
    ],
    "helicoid_principal": [
        "u",
        "v",
        "k1",
        "k2",
        "k1_exact",
        "k2_exact",
        "K",
        "K_exact",
        "H_surfaces",
        "H_core_sign",
        "classification",
    ],
    "convergence": [
        "surface",
        "mesher",
        "res",
        "vertices",
        "h",
        "estimator",
        "max_error",
        "order_max",
        "mean_error",
        "order_mean",
    ],
    "convergence_summary": [
        "surface",
        "mesher",
        "estimator",
        "levels",
        "max_error_coarsest",
        "max_error_finest",
        "order_max_finest",
        "mean_error_finest",
        "order_mean_finest",
    ],
    "cotan_uniform_ranges": [
        "mesh",
        "field",
        "vertices",
        "min",
        "max",
        "mean",
        "median",
        "p01",
        "p99",
    ],
    "cotan_scaling": [
        "estimator",
        "median_abs_s1",
        "median_abs_s2",
        "ratio",
        "expected_for_a_curvature",
    ],
    "spectral_errors": [
        "k",
        "lambda_k",
        "mean_error",
        "max_error",
        "rms_error",
        "rms_error_no_mass",
        "rms_error_unit_vectors",
    ],
    "spectral_timings": [
        "mesh",
        "vertices",
        "k",
        "method",
        "seconds",
        "eigensolve_seconds",
        "max_residual",
        "lambda_max",
        "speedup_vs_388s",
        "speedup_vs_5771s",
    ],
    "smoothing_stability": [
        "mesh",
        "laplacian",
        "method",
        "lam",
        "lam_over_limit",
        "mu_min",
        "explicit_lam_limit",
        "high_freq_gain",
        "spectral_radius",
        "stable",
        "iterations",
        "diverged",
        "drift_rms",
        "volume_change_pct",
        "ms_per_step",
    ],
    "denoise_sweep": [
        "case",
        "noise",
        "method",
        "laplacian",
        "lam",
        "lam_over_limit",
        "iters",
        "rmse",
        "rmse_noisy",
        "max_error",
        "volume_change_pct",
        "volume_change_noisy_pct",
        "dihedral_mae_deg",
        "dihedral_mae_noisy_deg",
        "normal_dev_deg",
        "stable",
        "diverged",
        "seconds",
    ],
    "denoise_recommendation": [
        "case",
        "noise_level",
        "rmse_noisy",
        "best_rmse_setting",
        "best_rmse",
        "rmse_reduction_pct",
        "best_rmse_volume_change_pct",
        "best_dihedral_setting",
        "best_dihedral_mae_deg",
        "noisy_dihedral_mae_deg",
        "best_rmse_volume_1pct_setting",
        "best_rmse_volume_1pct",
        "best_rmse_volume_1pct_change_pct",
    ],
    "denoise_best_per_method": [
        "case",
        "noise_level",
        "laplacian",
        "method",
        "lam",
        "lam_over_limit",
        "iters",
        "rmse",
        "rmse_noisy",
        "volume_change_pct",
        "dihedral_mae_deg",
        "diverged_runs",
        "runs",
    ],
    "section_timings": ["section", "title", "seconds", "figures", "tables", "status"],
}


SHOTS = 4  # real viewer screenshots in the module's report (~2 s each)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """The quick report with a --meshes folder that has no mesh: the bundled assets are used.
    The first SHOTS pictures are viewer screenshots, the others matplotlib renderings (to keep
    the test short; both paths are then exercised)."""
    empty = tmp_path_factory.mktemp("no_meshes")
    out = tmp_path_factory.mktemp("report")
    with ViewerScreenshots() as screenshot:
        return build_report(out, empty, quick=True, max_screenshots=SHOTS, screenshot=screenshot)


def read_table(result, name: str) -> list[dict[str, str]]:
    with open(result.out_dir / "tables" / f"{name}.csv", newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def check_png(path: Path) -> None:
    import matplotlib.image as mpimg

    assert path.is_file(), path
    assert path.read_bytes()[:8] == PNG_MAGIC, path
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[0] >= 50 and img.shape[1] >= 50, (path, img.shape)
    rgb = img[..., :3].reshape(-1, 3)
    assert rgb.std(axis=0).max() > 0.02, f"{path} is blank"
    assert len(np.unique(np.round(rgb[:: max(1, len(rgb) // 20000)], 2), axis=0)) > 10, path


# --------------------------------------------------------------------------------------------
# the quick report on bundled assets


def test_quick_report_builds_and_says_it_uses_bundled_assets(quick):
    assert quick.errors == {}
    assert quick.markdown.is_file() and quick.html.is_file()
    assert set(quick.section_seconds) == set(SECTIONS)
    head = quick.markdown.read_text(encoding="utf-8").splitlines()[:4]
    assert any("bundled assets" in line for line in head), head
    assert "bundled assets" in quick.mesh_note
    # every course mesh name appears with its stand-in
    for name in ("cube", "lilium_s", "plane", "armadillo", "plane_ns", "fandisk", "fandisk_ns"):
        assert f"{name} → assets/" in quick.mesh_note


def test_every_referenced_figure_exists_and_is_a_valid_png(quick):
    md = quick.markdown.read_text(encoding="utf-8")
    md_figs = set(re.findall(r"\]\((figures/[^)]+\.png)\)", md))
    page = quick.html.read_text(encoding="utf-8")
    html_figs = set(re.findall(r'<img src="([^"]+)"', page))
    assert md_figs, "the report references no figure"
    assert md_figs == html_figs
    for rel in md_figs:
        check_png(quick.out_dir / rel)
    # nothing written that the report does not show
    written = {p.relative_to(quick.out_dir).as_posix() for p in quick.figures}
    assert written == md_figs
    assert {p.name for p in (quick.out_dir / "figures").iterdir()} == {
        Path(r).name for r in md_figs
    }


def test_screenshots_are_real_unless_egl_is_missing(quick):
    if quick.screenshots_ok == 0:
        reason = quick.screenshot_failures[0] if quick.screenshot_failures else "unknown"
        if ("EGL" in reason or "egl" in reason) and "re-initializing" not in reason:
            pytest.skip(f"no EGL on this machine: {reason}")
        pytest.fail(f"no viewer screenshot was taken: {reason}")
    assert quick.screenshot_failures == []
    assert quick.screenshots_ok == SHOTS
    md = quick.markdown.read_text(encoding="utf-8")
    # the one-ring screenshot is a real viewer frame: mesh and panel side by side
    assert "figures/onering_cube_viewer.png" in md
    check_png(quick.out_dir / "figures" / "onering_cube_viewer.png")
    # past the limit, pictures are drawn with matplotlib and the report says why
    assert f"the limit of {SHOTS} viewer screenshots was reached" in md
    assert "matplotlib rendering: no screenshot" in md


def test_every_table_has_the_expected_columns(quick):
    names = {p.stem for p in quick.tables}
    assert set(EXPECTED_COLUMNS) <= names
    md = quick.markdown.read_text(encoding="utf-8")
    for rel in re.findall(r"\]\((tables/[^)]+\.csv)\)", md):
        assert (quick.out_dir / rel).is_file(), rel
    for name, cols in EXPECTED_COLUMNS.items():
        with open(quick.out_dir / "tables" / f"{name}.csv", newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
        assert rows[0] == cols, name
        assert len(rows) > 1, f"{name} has no rows"
        assert all(len(r) == len(cols) for r in rows), name


VOID_TAGS = frozenset(
    {
        "area",
        "base",
        "br",
        "col",
        "embed",
        "hr",
        "img",
        "input",
        "link",
        "meta",
        "source",
        "track",
        "wbr",
    }
)


class _Checker(HTMLParser):
    VOID = VOID_TAGS

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.problems: list[str] = []
        self.imgs_without_alt = 0
        self.seen: set[str] = set()

    def handle_starttag(self, tag, attrs):
        self.seen.add(tag)
        if tag == "img" and not dict(attrs).get("alt"):
            self.imgs_without_alt += 1
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.seen.add(tag)
        if tag == "img" and not dict(attrs).get("alt"):
            self.imgs_without_alt += 1

    def handle_endtag(self, tag):
        if tag in self.VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.problems.append(
                f"</{tag}> closes <{self.stack[-1] if self.stack else None}>"
                f" at line {self.getpos()[0]}"
            )
            return
        self.stack.pop()


def test_html_is_well_formed(quick):
    page = quick.html.read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>")
    chk = _Checker()
    chk.feed(page)
    chk.close()
    assert chk.problems == []
    assert chk.stack == []
    assert chk.imgs_without_alt == 0
    assert {"html", "head", "body", "table", "img", "section"} <= chk.seen


# --------------------------------------------------------------------------------------------
# the numbers obey the mathematics


def test_tables_agree_with_the_mathematics(quick):
    # one-rings: every consecutive ccw pair (a, b) of v makes a face (v, a, b)
    ring = read_table(quick, "onering_cube")
    assert len(ring) == 8 and all(r["ccw_pairs_are_faces"] == "true" for r in ring)
    # the cw order is the ccw order reversed
    for r in ring:
        assert r["neighbours_cw"].split(" → ") == r["neighbours_ccw"].split(" → ")[::-1]
    # Gauss–Bonnet holds exactly with the pi boundary rule (closed and open meshes)
    for r in read_table(quick, "gauss_bonnet"):
        assert float(r["abs_difference"]) < 1e-9 * max(1.0, abs(float(r["two_pi_chi"])))
    # helicoid at the origin: E = G = 1, F = 0, e = g = 0, f = 1 (II = -p_uv . n), K = -1, k = ±1
    for r in read_table(quick, "helicoid_origin"):
        assert float(r["abs_difference"]) < 1e-8, r
    # the coursework's sign (do Carmo, e = p_uu . n): f = -1/sqrt(1+u²), κₙ = -sin 2θ at the
    # origin with its maximum at 135° in the tangent plane; meshlap's outward sign beside it
    course = {
        (float(r["u"]), float(r["v"]), r["quantity"]): r
        for r in read_table(quick, "helicoid_coursework")
    }
    assert {r["signs"] for r in course.values()} == {"do-carmo"}
    for (u, _v, q), r in course.items():
        assert float(r["abs_difference"]) < 1e-9, r
        if q == "f":
            w = 1 + u**2
            assert float(r["computed"]) == pytest.approx(-1 / np.sqrt(w), abs=1e-12)
            assert float(r["outward"]) == pytest.approx(1 / np.sqrt(w), abs=1e-12)
        if q == "K":
            assert float(r["outward"]) == pytest.approx(float(r["computed"]), abs=1e-12)
    assert float(course[(0.0, 0.0, "theta_max (deg, tangent plane)")]["computed"]) == (
        pytest.approx(135.0)
    )
    assert float(course[(0.0, 0.0, "theta_max (deg, tangent plane)")]["outward"]) == (
        pytest.approx(45.0)
    )
    at = {q: float(r["computed"]) for (u, _v, q), r in course.items() if u == 0.8}
    assert at["theta_max (deg, tangent plane)"] - at["theta_min (deg, tangent plane)"] == (
        pytest.approx(90.0)
    )
    # tan θ_uv = tan 45° / √1.64 at u = 0.8: the (u, v) angles are 104° apart
    assert at["theta_uv_max (deg, (u, v) plane)"] == pytest.approx(142.0148, abs=1e-4)
    assert at["theta_uv_min (deg, (u, v) plane)"] == pytest.approx(37.9852, abs=1e-4)
    for r in read_table(quick, "helicoid_principal"):
        u = float(r["u"])
        assert float(r["k1"]) == pytest.approx(1 / (1 + u * u), abs=1e-9)
        assert float(r["k2"]) == pytest.approx(-1 / (1 + u * u), abs=1e-9)
        # one sign convention: the core's H is the surfaces' H (0 on the minimal helicoid)
        assert float(r["H_core_sign"]) == pytest.approx(float(r["H_surfaces"]), abs=1e-12)
        assert float(r["H_surfaces"]) == pytest.approx(0.0, abs=1e-12)
    # convergence under refinement (analytic references): second order with the Voronoi area
    # on the icospheres, a stall near 15 % with the barycentric one; H uniform never converges
    # on the sphere (it is O(h^2), so its error tends to |H| = 1)
    conv = {
        (r["surface"], r["mesher"], r["estimator"]): r
        for r in read_table(quick, "convergence_summary")
    }
    ico = {e: r for (s_, m_, e), r in conv.items() if (s_, m_) == ("sphere", "icosphere")}
    assert float(ico["K deficit voronoi"]["order_max_finest"]) > 1.5
    assert 0.1 < float(ico["H cotan barycentric"]["max_error_finest"]) < 0.2
    assert float(ico["H uniform"]["max_error_finest"]) > 0.5
    # scaling by s: the cotangent H is a curvature (x 1/s), K goes as 1/s^2, uniform H as s
    sc = {r["estimator"]: float(r["ratio"]) for r in read_table(quick, "cotan_scaling")}
    assert sc["H cotan"] == pytest.approx(0.5, rel=1e-9)
    assert sc["K"] == pytest.approx(0.25, rel=1e-9)
    assert sc["H uniform"] == pytest.approx(2.0, rel=1e-9)


def test_spectral_and_smoothing_tables_show_the_expected_behaviour(quick):
    spec = read_table(quick, "spectral_errors")
    ks = [int(r["k"]) for r in spec]
    assert ks == sorted(ks) and ks[0] == 5
    lam = [float(r["lambda_k"]) for r in spec]
    assert all(x >= 0 for x in lam) and lam == sorted(lam)
    rms = [float(r["rms_error"]) for r in spec]
    unit = [float(r["rms_error_unit_vectors"]) for r in spec]
    nomass = [float(r["rms_error_no_mass"]) for r in spec]
    # with the M inner product more modes help; at the largest k both forms of the Euclidean
    # bug are worse
    assert rms[-1] < rms[0]
    assert unit[-1] > rms[-1] and nomass[-1] > rms[-1]
    for r in read_table(quick, "spectral_timings"):
        assert float(r["max_residual"]) < 1e-6
        assert float(r["speedup_vs_388s"]) == pytest.approx(388.0 / float(r["seconds"]))

    rows = read_table(quick, "smoothing_stability")
    for r in rows:
        gain, stable = float(r["high_freq_gain"]), r["stable"] == "true"
        lam, mu = float(r["lam"]), float(r["mu_min"])
        if r["method"] == "explicit":
            assert gain == pytest.approx(1 + lam * mu, rel=1e-9, abs=1e-9)
            assert stable == (float(r["lam_over_limit"]) <= 1 + 1e-9)
        else:
            assert gain == pytest.approx(1 / (1 - lam * mu), rel=1e-9)
            assert stable
        assert float(r["explicit_lam_limit"]) == pytest.approx(2 / abs(mu), rel=1e-9)
        if stable:
            assert r["diverged"] == "false"
    # the uniform Laplacian's spectrum lies in [-2, 0]
    assert all(-2 - 1e-9 <= float(r["mu_min"]) < 0 for r in rows if r["laplacian"] == "uniform")
    # twice the explicit limit multiplies the top mode by -3 per step: it must blow up
    twice = [
        r
        for r in rows
        if r["method"] == "explicit" and float(r["lam_over_limit"]) == pytest.approx(2.0, rel=1e-2)
    ]
    assert twice and all(r["diverged"] == "true" for r in twice)


def test_denoising_recommendation_is_read_off_the_sweep(quick):
    sweep = read_table(quick, "denoise_sweep")
    rec = read_table(quick, "denoise_recommendation")
    assert {r["case"] for r in rec} == {r["case"] for r in sweep}
    for r in rec:
        runs = [s for s in sweep if s["case"] == r["case"] and s["rmse"] not in ("", "nan")]
        best = min(runs, key=lambda s: float(s["rmse"]))
        assert float(r["best_rmse"]) == pytest.approx(float(best["rmse"]))
        assert float(r["best_rmse"]) <= float(r["rmse_noisy"])
        assert best["method"] in r["best_rmse_setting"]
        assert best["laplacian"] in r["best_rmse_setting"]
        improving = [s for s in runs if float(s["rmse"]) < float(s["rmse_noisy"])]
        dih = min(improving, key=lambda s: float(s["dihedral_mae_deg"]))
        assert float(r["best_dihedral_mae_deg"]) == pytest.approx(float(dih["dihedral_mae_deg"]))
    md = quick.markdown.read_text(encoding="utf-8")
    assert "computed from the table, not written by hand" in md


# --------------------------------------------------------------------------------------------
# degraded and command-line paths (small: sections 1 and 4 only)


def test_failed_screenshots_fall_back_to_renderings_with_a_note(tmp_path):
    empty = tmp_path / "none"
    empty.mkdir()

    def fail(mesh, panel, options, out_png):
        raise RuntimeError("no EGL display on this test machine")

    res = build_report(tmp_path / "out", empty, quick=True, sections="1,4", screenshot=fail)
    assert res.errors == {}
    assert res.screenshots_ok == 0
    assert res.screenshot_failures and "no EGL display" in res.screenshot_failures[0]
    md = res.markdown.read_text(encoding="utf-8")
    assert "no EGL display on this test machine" in md
    assert "matplotlib rendering: no screenshot" in md
    for rel in re.findall(r"\]\((figures/[^)]+\.png)\)", md):
        check_png(res.out_dir / rel)
    # only one attempt: later pictures do not retry a broken viewer
    assert len(res.screenshot_failures) == 1


def test_screenshot_function_gets_the_mesh_panel_and_options(tmp_path):
    """The study asks its screenshot function for the one-ring panel on the cube file with
    vertex 0, and for curvature maps of arrays named after the mesh; a written PNG is
    autocropped and shown as a screenshot, and a function returning False stops the rest."""
    import matplotlib.image as mpimg

    empty = tmp_path / "none"
    empty.mkdir()
    calls = []

    def fake(mesh, panel, options, out_png):
        calls.append((mesh, panel, dict(options), out_png))
        img = np.ones((120, 200, 4))
        img[30:90, 20:110, :3] = np.linspace(0, 0.8, 90)[None, :, None]  # a "mesh" on white
        img[0:40, 150:200, :3] = 0.2  # a "panel" at the top right
        mpimg.imsave(out_png, img)
        return len(calls) < 3

    res = build_report(tmp_path / "out", empty, quick=True, sections="1,4", screenshot=fake)
    assert res.errors == {} and res.screenshots_ok == 2
    (m0, p0, o0, out0), (m1, p1, o1, _) = calls[:2]
    assert isinstance(m0, Path) and m0.name == "cube.obj" and p0 == "onering"
    assert o0 == {"vertex": 0} and out0.is_absolute() and out0.name == "onering_cube_viewer.png"
    V, F, name = m1
    assert V.shape[1] == 3 and F.shape[1] == 3 and V.dtype == np.float64 and name == "lilium_s"
    assert p1 == "curvature" and o1 == {"field": "uniform"}
    # autocrop: the mesh (90 + 2 * 12 margin wide) and the panel (50) side by side, gap 12
    shot = mpimg.imread(out0)
    assert shot.shape[1] == 90 + 2 * 12 + 12 + 50
    md = res.markdown.read_text(encoding="utf-8")
    assert len(calls) == 3 and res.screenshot_failures == [
        "cotan_lilium_cotan: the viewer wrote no screenshot"
    ]
    assert "the viewer wrote no screenshot" in md


def test_cli_report_json_and_progress(tmp_path, capsys):
    empty = tmp_path / "none"
    empty.mkdir()
    code = main(
        [
            "report",
            "--meshes",
            str(empty),
            "--out",
            str(tmp_path / "o"),
            "--quick",
            "--sections",
            "onering",
            "--no-screenshots",
            "--json",
        ]
    )
    cap = capsys.readouterr()
    assert code == 0
    obj = json.loads(cap.out)
    assert Path(obj["markdown"]).is_file() and Path(obj["html"]).is_file()
    assert list(obj["section_seconds"]) == ["onering"]
    assert "report [" in cap.err and "section 1/1 onering" in cap.err and " s)" in cap.err


def test_cli_rejects_bad_arguments(tmp_path, capsys):
    code = main(["report", "--meshes", str(tmp_path / "missing"), "--out", str(tmp_path / "o")])
    assert code == 2
    assert "missing: is not a directory" in capsys.readouterr().err
    code = main(["report", "--sections", "9", "--out", str(tmp_path / "o")])
    assert code == 2
    assert "unknown section '9'" in capsys.readouterr().err


def test_parse_sections():
    assert parse_sections(None) == list(SECTIONS)
    assert parse_sections("5,1,spectral") == ["onering", "spectral"]
    with pytest.raises(MeshError, match="--sections"):
        parse_sections("0")
    with pytest.raises(MeshError, match="empty"):
        parse_sections(" , ")
