"""Every view's *export what is shown* writes what is on screen (openGL_mock, through the
widgets).

The Check view's export wrote the Curvature view's k1 field (``bumpy_k1.ply``) instead of the
student − reference map on the mesh. The class check: for each view of the registry (a view
without a set-up here fails :func:`test_every_view_has_a_setup`), the view is made to show
something, *export what is shown* is pressed, the files are read back and compared with what
the panel uploaded to polyscope (recorded by :class:`legend_ledger.Ledger`): every surface mesh
on screen is in a PLY file (the same vertices, up to the display's similarity transform: its
centring, scale, up axis and side offset), and the colour field on it is that file's per-vertex
``quality``, value for value.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.registry import VIEWS  # noqa: E402
from scipy.spatial import procrustes  # noqa: E402

from meshlap_core.io import load_mesh  # noqa: E402
from meshlap_core.io.load import load_vertex_scalars  # noqa: E402
from tests.support.drivers import view_setups  # noqa: E402
from tests.support.legend_ledger import Ledger  # noqa: E402
from tests.support.widgets import drive, frames  # noqa: E402


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def test_every_view_has_a_setup():
    """Each view's driver module says how it shows something (``show_for_export``)."""
    assert set(view_setups()) == set(VIEWS)


# ---------------------------------------------------------------- the files against the screen
def same_shape(a: np.ndarray, b: np.ndarray) -> bool:
    """``a`` and ``b`` (n,3) are the same points up to a similarity transform (Procrustes)."""
    if a.shape != b.shape or len(a) < 3:
        return False
    _, _, disparity = procrustes(a, b)
    return disparity < 1e-12


def written(viewer, folder: Path) -> list[Path]:
    """The files the last export says it wrote (``wrote a, b in <folder>``)."""
    status = viewer.panels["export"].status
    match = re.fullmatch(r"wrote (.+) in (.+)", status)
    assert match, status
    assert Path(match.group(2)) == folder.resolve()
    return [folder / name for name in match.group(1).split(", ")]


def export_problems(viewer, ledger: Ledger, folder: Path) -> list[str]:
    """Press *export what is shown* into ``folder``; what on screen is not in its files (the
    meshes framing shows: the main mesh and the panels' copies, ``Viewer.framed_names``)."""
    drive(viewer, "folder", str(folder))
    drive(viewer, "export what is shown", True)
    files = written(viewer, folder)
    plys = {}
    for path in files:
        assert path.is_file(), path
        if path.suffix == ".ply":
            mesh = load_mesh(path)
            try:
                quality = load_vertex_scalars(path)
            except Exception:  # no per-vertex field in this file
                quality = None
            plys[path.name] = (mesh.V, mesh.F, quality)
    problems = []
    framed = viewer.framed_names()
    shown = {k: v for k, v in ledger.shown_meshes().items() if k in framed}
    assert shown, "nothing on screen"
    for name, (points, faces, q) in shown.items():
        match = [
            f
            for f, (V, F, _) in plys.items()
            if np.array_equal(F, faces) and same_shape(np.asarray(V), points)
        ]
        if not match:
            problems.append(f"{name!r} on screen is in no PLY file of {sorted(plys)}")
            continue
        if q is None or q.kind != "scalar":
            continue
        uploaded = np.asarray(q.values, dtype=np.float64)
        if len(uploaded) == len(faces) != len(points):  # a field per face: its CSV
            columns = [np.genfromtxt(f, skip_header=1) for f in files if f.suffix == ".csv"]
            if not any(
                len(c) == len(uploaded) and np.allclose(c, uploaded, rtol=1e-6, equal_nan=True)
                for c in columns
            ):
                problems.append(f"the per-face field on {name!r} is in no CSV file")
            continue
        ok = False
        for f in match:
            quality = plys[f][2]
            if quality is not None and len(quality) == len(uploaded):
                finite = np.isfinite(quality)
                ok = ok or np.allclose(quality[finite], uploaded[finite], rtol=1e-12, atol=0)
        if not ok:
            problems.append(f"the field on {name!r} is not the 'quality' of {match}")
    return problems


@pytest.mark.parametrize("view", VIEWS)
def test_export_writes_what_the_view_shows(view, viewer, sphere, tmp_path, monkeypatch):
    ledger = Ledger().install(monkeypatch)
    assert viewer.open(sphere)  # everything registered again, through the ledger
    viewer.set_panel(view)
    frames(viewer, 2)
    steps = view_setups()[view](viewer, tmp_path)  # a generator: one export per state it yields
    problems: list[str] = []
    for i, what in enumerate(steps or [view]):
        frames(viewer, 3)
        out = tmp_path / f"out{i}"
        out.mkdir()
        problems += [f"{what}: {p}" for p in export_problems(viewer, ledger, out)]
    assert not problems, "\n".join(problems)
