"""Isolines of every scalar field the viewer shows: the shared, polyscope-free settings
(:mod:`meshlap_app.state.isolines`) tested headless, and each panel's toggle and count driven
through the widgets (ScriptedUI on polyscope's ``openGL_mock``) with the options polyscope
received read from the :class:`tests.support.legend_ledger.Ledger`. The drivers
(:mod:`tests.support.drivers.isolines`) are also part of the widget tour of
``tests/app/test_viewer_widgets.py`` (every widget driven)."""

from __future__ import annotations

import numpy as np
import pytest
from meshlap_app.state.diffusion import HEAT_TITLES
from meshlap_app.state.isolines import COUNT_RANGE, Isolines, isoline_period

ps = pytest.importorskip("polyscope")

from tests.support.drivers.isolines import drive_isolines  # noqa: E402
from tests.support.legend_ledger import Ledger  # noqa: E402
from tests.support.widgets import frames  # noqa: E402


# ---------------------------------------------------------------- the settings, headless
def test_period_divides_the_finite_range_by_the_count():
    # range [-1, 3] (the inf ignored): 4 / 8 = 0.5 by hand
    assert isoline_period(np.array([-1.0, 0.0, 3.0, np.inf]), 8) == pytest.approx(0.5)
    assert isoline_period(np.array([2.0, 2.0]), 5) == 1.0  # flat: any positive period
    assert isoline_period(None, 5) == 1.0
    assert isoline_period(np.array([np.nan]), 5) == 1.0


def test_each_field_has_its_own_toggle_and_count():
    iso = Isolines()
    assert iso.options("mean", np.arange(3.0)) == {"isolines_enabled": False}
    assert iso.of("distance", on=True).on  # a field may start shown
    iso.of("mean").on = True
    iso.of("mean").set_count(4)
    opts = iso.options("mean", np.array([0.0, 2.0]))
    assert opts == {"isolines_enabled": True, "isoline_period": pytest.approx(0.5)}
    assert not iso.of("gaussian").on  # another field is untouched
    iso.of("mean").set_count(0)
    assert iso.of("mean").count == COUNT_RANGE[0]
    iso.of("mean").set_count(10**9)
    assert iso.of("mean").count == COUNT_RANGE[1]


# ---------------------------------------------------------------- through the widgets
@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def test_isolines_of_every_panel_reach_polyscope(viewer):
    drive_isolines(viewer)


def test_heat_animation_frames_carry_the_distance_isolines(viewer, monkeypatch):
    """``meshlap animate --heat``: each frame's field has the isolines of the view's setting,
    the count over its range [0, peak]."""
    ledger = Ledger().install(monkeypatch)
    panel = viewer.panels["diffusion"]
    viewer.set_panel("diffusion")
    frames(viewer)
    panel.isolines.of("distance", True).set_count(5)
    opts = {"heat_vertex": 3, "heat_t": (-1.0, 1.0), "heat_frames": 2}
    captions = list(panel.frames(viewer, opts))
    assert len(captions) == 2 and "vertex 3" in captions[0]
    q = ledger.quantities["mesh"][HEAT_TITLES["euler"]]
    assert q.isolines and q.isoline_period == pytest.approx(float(np.max(q.values)) / 5)
    panel.isolines.of("distance").on = False
    list(panel.frames(viewer, opts))
    assert not ledger.quantities["mesh"][HEAT_TITLES["euler"]].isolines
