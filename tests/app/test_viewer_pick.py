"""The click protocol: every panel's ``pick`` hook gets a :class:`~meshlap_app.panels.base.Pick`
with the modifier keys held (scripted clicks on polyscope's openGL_mock; the real keys are
read from imgui, see ``tests/window/test_diffusion.py`` for a shift-click in a window)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")

from meshlap_app.panels.base import Pick  # noqa: E402

from tests.support.widgets import frames  # noqa: E402


@pytest.fixture(scope="module")
def mock(polyscope_mock):
    return polyscope_mock


def fake_pick(monkeypatch, vertex: int) -> None:
    """polyscope's pick answers a hit on the mesh's ``vertex`` wherever one clicks."""
    hit = SimpleNamespace(
        is_hit=True,
        structure_name="mesh",
        structure_data={"element_type": "vertex", "index": vertex},
        position=np.array([0.1, 0.2, 0.3]),
    )
    monkeypatch.setattr(ps, "pick", lambda screen_coords: hit)


@pytest.mark.parametrize(
    ("click", "held"),
    [
        ((5.0, 6.0), set()),
        ((5.0, 6.0, "shift"), {"shift"}),
        ((1, 2, "ctrl", "alt"), {"ctrl", "alt"}),
    ],
)
def test_every_panel_is_handed_the_modifier_keys_of_a_click(viewer, monkeypatch, click, held):
    fake_pick(monkeypatch, 4)
    seen: dict[str, Pick] = {}
    for name, panel in viewer.panels.items():

        def record(host, hit, active, name=name):
            seen[name] = hit
            return False  # not used: the next panel is asked too

        monkeypatch.setattr(panel, "pick", record)
    viewer.ui.script("click", click)
    frames(viewer, 1)
    assert set(seen) == set(viewer.panels)  # every panel, the active one first
    for hit in seen.values():
        assert isinstance(hit, Pick)
        assert hit.modifiers == held and hit.shift == ("shift" in held)
        assert hit.structure_name == "mesh" and hit.structure_data["index"] == 4
        assert hit.position == (0.1, 0.2, 0.3)


def test_a_panel_that_ignores_modifiers_still_answers_a_modified_click(viewer, monkeypatch):
    fake_pick(monkeypatch, 9)
    viewer.set_panel("onering")
    viewer.ui.script("click", (3.0, 4.0, "shift"))
    frames(viewer, 1)
    assert viewer.panels["onering"].state.vertex == 9


def test_pick_of_polyscope_result_copies_it():
    res = SimpleNamespace(structure_name="mesh", structure_data={"index": 2}, position=(1, 2, 3))
    hit = Pick.of(res, ["shift"])
    assert hit == Pick("mesh", {"index": 2}, hit.position, frozenset({"shift"}))
    res.structure_data["index"] = 5  # a copy: polyscope's result may be reused
    assert hit.structure_data["index"] == 2 and hit.position == (1.0, 2.0, 3.0)
    assert Pick.of(res, ["shift"]) != hit  # compared by value: the hit changed
    assert not Pick("mesh").shift and Pick("mesh").modifiers == frozenset()
