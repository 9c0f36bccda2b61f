"""What the panels say: why a mesh has no genus, plurals, the MP4 extra's install hint, κₙ
round-off shown as 0, a missing export folder named with where files go, and a recorded file's
name never broken at its dot when the status wraps."""

from __future__ import annotations

from pathlib import Path

import pytest

ps = pytest.importorskip("polyscope")


from tests.support.widgets import drive, frames  # noqa: E402

README = Path(__file__).resolve().parents[2] / "README.md"


def test_genus_none_is_explained_and_small_texts(viewer, tmp_path):
    from meshlap_app.panels.mesh_info import genus_reason
    from meshlap_app.state.surfaces import SurfaceState
    from meshlap_app.text_numbers import plural

    from meshlap_core.io.animation import VIDEO_EXTRA

    fin = tmp_path / "fin.obj"  # three triangles on one edge: not a manifold
    fin.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 1 2 5\n")
    assert viewer.open(fin)
    frames(viewer)
    info = viewer.state.mesh.info
    assert info["genus"] is None
    why = genus_reason(info)
    assert "not a manifold" in why and "boundary is not a set of loops" in why
    # "1 step", the README's install hint in the MP4 error, κₙ round-off shown as 0
    assert plural(1, "step") == "1 step" and plural(3, "step") == "3 steps"
    assert "pip install -e '.[video]'" in VIDEO_EXTRA
    assert "pip install -e '.[video]'" in README.read_text(encoding="utf-8")
    s = SurfaceState()
    s.set_surface("saddle")
    s.set_section(45.0)  # κₙ = 4.4e-16 in floating point
    assert "κₙ = 0 " in s.section_caption()


def test_a_missing_export_folder_is_reported_with_where_files_go(viewer, tmp_path):
    from meshlap_core.errors import MeshError

    with pytest.raises(MeshError, match="create it first") as err:
        viewer.state.set_folder(str(tmp_path / "nope"))
    assert str(viewer.state.folder) in str(err.value)


def test_the_recorded_file_name_is_never_broken_at_its_dot(viewer, tmp_path):
    from meshlap_app.record import RECORD_HEADER
    from meshlap_app.text_wrap import wrap_at_spaces

    viewer.set_panel("smoothing")
    frames(viewer)
    folder = tmp_path / ("a_long_folder_name_" * 4)
    folder.mkdir()
    path = folder / "smoothing.gif"

    def opened(label: str, value) -> None:  # the record header is open in that frame
        viewer.ui.script(RECORD_HEADER, True)
        drive(viewer, label, value)

    opened("record file", str(path))
    opened("record", True)
    for _ in range(3):
        opened("step", True)
    opened("stop", True)
    assert path.exists()
    viewer.ui.lines.clear()
    viewer.ui.script(RECORD_HEADER, True)
    frames(viewer)
    lines = [line for sec, line in viewer.ui.lines if sec == "smoothing"]
    assert any(line.startswith("wrote ") for line in lines), lines
    # the status is wider than the panel: wrapped, but the path stays one word, whole
    assert len(lines) > 1 and str(path) in lines
    assert " ".join(lines) == viewer.panels["smoothing"].recorder.status
    # only at spaces: a dotted name is never split (imgui's own wrap breaks after the dot)
    assert wrap_at_spaces("to smoothing.gif", 1.0, len) == ["to", "smoothing.gif"]


def test_the_noise_tooltip_says_what_the_noise_is(viewer):
    """The tooltip said normal noise with σ = α × mean edge length; the noise added is
    isotropic with σ = α × the bounding-box diagonal: the input the panel builds at α = 0.02
    moves every coordinate by about σ (the RMS over the 3n offsets, not along the normals)."""
    import numpy as np

    viewer.set_panel("smoothing")
    st = viewer.panels["smoothing"].state
    frames(viewer)
    V = np.array(viewer.state.mesh.V)
    drive(viewer, "noise alpha", 0.02)
    tip = viewer.ui.tooltips[("smoothing", "noise alpha")]
    assert "isotropic" in tip and "sigma = alpha x the bounding-box diagonal" in tip
    assert "edge length" not in tip and "along the normals" not in tip
    offsets = np.asarray(st.V) - V  # the noisy input, before any step
    sigma = 0.02 * float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    assert np.sqrt(np.mean(offsets**2)) == pytest.approx(sigma, rel=0.15)
    normals_only = np.abs(offsets).min(axis=1)  # normal noise leaves no coordinate unmoved...
    assert np.median(normals_only) > 0.1 * sigma  # ...isotropic moves all three


def test_uniform_h_is_labelled_a_length(viewer, monkeypatch):
    """Uniform H is not divided by an area: it scales like the mesh (a length), not like
    1/length. Its colour bar says so, and doubling the mesh doubles it (by hand: the
    uniform Laplacian of 2x is twice that of x)."""
    import numpy as np
    from meshlap_app.state.preview import PREVIEW_LABEL

    from meshlap_core.curvature import mean_curvature_uniform
    from tests.support.legend_ledger import Ledger

    ledger = Ledger().install(monkeypatch)
    viewer.set_panel("curvature")
    drive(viewer, "field", "uniform")
    frames(viewer)
    shown = [name for (_, name), q in ledger.visible().items() if q.kind == "scalar"]
    assert shown == ["mean curvature H (uniform Laplacian) [length]"]
    assert PREVIEW_LABEL.endswith("[length]")
    V, F = viewer.state.mesh.V, viewer.state.mesh.F
    np.testing.assert_allclose(
        mean_curvature_uniform(2.0 * V, F), 2.0 * mean_curvature_uniform(V, F), atol=1e-12
    )
