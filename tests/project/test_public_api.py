"""The curated public API of ``meshlap_core``: every name resolves, and importing is cheap."""

import subprocess
import sys

import pytest

import meshlap_core


@pytest.mark.parametrize("name", meshlap_core.__all__)
def test_every_public_name_resolves(name):
    value = getattr(meshlap_core, name)
    assert value is not None
    assert name in dir(meshlap_core)


def test_unknown_names_raise_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        meshlap_core.nope  # noqa: B018


def test_torus_mesh_is_the_triangle_mesh_and_surface_the_parametric_one():
    V, F = meshlap_core.torus_mesh(8, 6)
    assert V.shape == (48, 3) and F.shape == (96, 3)
    assert meshlap_core.get_surface("torus").name == "torus"


def test_import_loads_no_numerics_until_a_name_is_used():
    """``import meshlap_core`` stays cheap (the CLI's Ctrl-C guard relies on it)."""
    code = (
        "import sys, meshlap_core\n"
        "assert 'numpy' not in sys.modules, 'numpy imported'\n"
        "meshlap_core.load_mesh\n"
        "assert 'numpy' in sys.modules\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr


def test_diffusion_names_are_the_diffusion_modules():
    """Heat, geodesic distance and spectral filters from the top level: the same objects as
    ``meshlap_core.diffusion``; the heat method on the unit sphere reaches the antipode at
    about π (great circle)."""
    import numpy as np

    from meshlap_core import diffusion

    for name, there in [
        ("HeatDiffusion", "HeatDiffusion"), ("heat_spectral", "heat_spectral"),
        ("HeatGeodesic", "HeatGeodesic"), ("exact_distance", "exact_distance"),
        ("SpectralFilter", "SpectralFilter"), ("transfer_function", "transfer"),
        ("heat_kernel_signature", "heat_kernel_signature"), ("isolines", "isolines"),
        ("save_polylines", "save_polylines"),
    ]:  # fmt: skip
        assert getattr(meshlap_core, name) is getattr(diffusion, there)
    V, F = meshlap_core.icosphere(3)
    d = meshlap_core.HeatGeodesic(V, F).distance([0])
    far = int(np.argmin(V @ V[0]))
    assert abs(d[far] - np.pi) < 0.05 * np.pi


def test_the_curvature_names_live_on_the_curvature_shelf():
    """The top-level curvature names are the objects of the ``meshlap_core.curvature`` package's
    modules, and the package re-exports every public function of ``curvature.fields``."""
    import importlib

    from meshlap_core import curvature
    from meshlap_core.curvature import estimators, fields, jet_fit, principal

    assert meshlap_core.estimate_curvature is estimators.estimate_curvature
    assert meshlap_core.PrincipalCurvatures is principal.PrincipalCurvatures
    assert meshlap_core.jet_curvatures is jet_fit.jet_curvatures
    for name in curvature.__all__:
        assert getattr(curvature, name) is getattr(fields, name)
    for name in ("curvature_field", "all_curvature_fields", "vertex_normals"):
        assert getattr(meshlap_core, name) is getattr(fields, name)
    assert importlib.import_module("meshlap_core.io.animation").FrameWriter is not None


@pytest.mark.parametrize(
    "old",
    [
        "meshlap_core.curvature_estimators",
        "meshlap_core.curvature_fit",
        "meshlap_core.curvature_topology",
        "meshlap_core.curvature_study",
        "meshlap_core.principal",
        "meshlap_core.frames",
        "meshlap_core.study",
        "meshlap_core.surfaces.convergence",
    ],
)
def test_the_module_paths_renamed_since_0_1_0_are_gone(old):
    """docs/commands.md's 'Renamed since 0.1.0' lists them, with their new shelves: no alias
    module."""
    import importlib

    with pytest.raises(ModuleNotFoundError):
        importlib.import_module(old)


def test_flatten_names_are_the_flatten_package():
    """The maps to the plane from the top level: the same objects as ``meshlap_core.flatten``
    (whose one-shot ``flatten`` stays there: the top-level name is the package); Tutte's map
    of a flat grid has no flipped face."""
    from meshlap_core import flatten

    for name in ("Flattener", "UVMap", "make_disk", "measure_distortion"):
        assert getattr(meshlap_core, name) is getattr(flatten, name)
    V, F = meshlap_core.grid(5, 5)
    assert meshlap_core.Flattener(V, F).map("tutte").summary()["flipped"] == 0
