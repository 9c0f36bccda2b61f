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
