"""The Surfaces view's κₙ plot: drawn against the geometric angle φ of the tangent plane (Euler's
formula, k1 and k2 marked where the curve reaches them) while the parameter angle θ is kept,
labelled as such, and the normal section is marked at its φ."""

from __future__ import annotations

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")


from tests.support.widgets import drive, frames  # noqa: E402


def test_euler_plot_is_in_the_geometric_angle(viewer):
    viewer.set_panel("surfaces")
    frames(viewer)
    s = viewer.panels["surfaces"].state
    assert s.name == "helicoid"
    for u, v in ((0.0, 0.0), (0.7, 0.4), (-1.2, 1.5)):
        drive(viewer, "u", u)
        drive(viewer, "v", v)
        plots = {label: rec for (sec, label), rec in viewer.ui.plots.items() if sec == "surfaces"}
        _kind, phi_deg, kn = plots["k_n"]
        phi_deg, kn = np.asarray(phi_deg), np.asarray(kn)
        p = s.point
        # the plotted extremes are 90° apart (the parameter-angle curve had them 99–109° apart)
        i_max, i_min = int(np.argmax(kn[:-1])), int(np.argmin(kn[:-1]))
        gap = abs(phi_deg[i_max] - phi_deg[i_min]) % 180.0
        assert gap == pytest.approx(90.0, abs=2.1)  # 2° sampling
        # Euler's formula on the plotted curve
        phi = np.radians(phi_deg)
        euler = p.k1 * np.cos(phi) ** 2 + p.k2 * np.sin(phi) ** 2
        assert np.allclose(kn, euler, atol=1e-9 * max(1.0, abs(p.k1), abs(p.k2)))
        # k1 and k2 are marked (named with their values) where the curve reaches them
        for name, k in (("k1", p.k1), ("k2", p.k2)):
            at = np.asarray(plots[f"{name} = {k:.3g}"][1])
            assert np.allclose(np.interp(at, phi_deg, kn), k)
        assert list(plots[f"k1 = {p.k1:.3g}"][1]) == [0.0, 180.0, 360.0]
        assert list(plots[f"k2 = {p.k2:.3g}"][1]) == [90.0, 270.0]
    # the parameter angle θ is kept, labelled as such, and the section is marked at its φ
    tip = viewer.ui.tooltips[("surfaces", "section theta")]
    assert "(u, v) plane" in tip and "tangent plane from the first principal" in tip
    drive(viewer, "section theta", 40.0)
    marked = viewer.ui.plots[("surfaces", "section")][1][0]
    assert marked == pytest.approx(s.section_phi_deg())
    t, kn = s.section()
    e1 = s.point.dir1
    assert np.degrees(np.arccos(abs(t @ e1))) == pytest.approx(
        min(marked % 180.0, 180.0 - marked % 180.0), abs=1e-6
    )
    phi = np.radians(marked)
    assert kn == pytest.approx(s.point.k1 * np.cos(phi) ** 2 + s.point.k2 * np.sin(phi) ** 2)
    assert "in (u, v), φ = " in s.section_caption()


def _surfaces_texts(viewer) -> list[tuple[str, object]]:
    return [(t, rgba) for sec, t, rgba in viewer.ui.texts if sec == "surfaces"]


def test_the_courses_signs_are_labelled_wherever_they_are_on(viewer):
    """The helicoid at its origin, by hand in do Carmo's convention (the coursework's):
    f = p_uv · n = −1/√(1+u²) = −1, e = g = 0, E = G = 1, so κₙ(θ) = −sin 2θ, largest at
    θ = 3π/4; meshlap's own sign has f = +1, largest at π/4.
    Through the Surfaces panel's *signs* combo: the II line, the plot's title, a coloured
    line naming the convention and the recording's caption say which sign is on."""
    from meshlap_app.panels.surfaces import SIGNS_COLOR

    from meshlap_core.surfaces import signs_note

    viewer.set_panel("surfaces")
    frames(viewer)
    drive(viewer, "surface", "helicoid")
    drive(viewer, "u", 0.0)
    drive(viewer, "v", 0.0)
    s = viewer.panels["surfaces"].state
    assert s.point.f == pytest.approx(1.0)  # meshlap's sign
    drive(viewer, "signs", "do-carmo")
    texts = _surfaces_texts(viewer)
    assert any(t.startswith("II: e = 0  f = -1  g = 0") for t, _ in texts), texts
    assert (signs_note("do-carmo"), SIGNS_COLOR) in texts  # said, in colour
    assert "normal curvature k_n(phi), signs: do-carmo" in viewer.ui.legend_at
    assert s.section_caption().endswith("signs: do-carmo")
    # the course's κₙ(θ) = −sin 2θ (θ in the (u, v) plane: here the tangent plane's too)
    for deg in (0.0, 45.0, 135.0, 200.0):
        drive(viewer, "section theta", deg)
        assert s.section()[1] == pytest.approx(-np.sin(2 * np.radians(deg)), abs=1e-12)
    theta, kn = s.point.theta_uv_max, s.point.k1
    assert np.degrees(theta) % 180.0 == pytest.approx(135.0) and kn == pytest.approx(1.0)
    drive(viewer, "signs", "outward")
    texts = _surfaces_texts(viewer)
    assert any(t.startswith("II: e = 0  f = 1  g = 0") for t, _ in texts), texts
    assert (signs_note("outward"), None) in texts  # meshlap's own: a grey note
    assert np.degrees(s.point.theta_uv_max) % 180.0 == pytest.approx(45.0)
    assert "signs" not in s.section_caption()


def test_the_markers_keep_the_colours_of_their_arrows(viewer, monkeypatch):
    """k1's marker in the κₙ plot had ImPlot's next colour, the blue of the k2 arrow on the
    surface: each marker now has its arrow's colour, on every point and either sign."""
    arrows: dict[str, tuple] = {}
    real = ps.PointCloud.add_vector_quantity

    def add_vector(cloud, name, values, *args, **kw):
        arrows[name] = tuple(kw["color"]) if "color" in kw else None
        return real(cloud, name, values, *args, **kw)

    monkeypatch.setattr(ps.PointCloud, "add_vector_quantity", add_vector)
    viewer.set_panel("surfaces")
    frames(viewer)
    s = viewer.panels["surfaces"].state
    for signs, u, v in (("outward", 0.3, 0.2), ("do-carmo", 0.3, 0.2), ("outward", 1.0, 1.0)):
        drive(viewer, "signs", signs)
        drive(viewer, "u", u)
        drive(viewer, "v", v)
        colours, p = viewer.ui.plot_colors, s.point
        for name, k in (("k1", p.k1), ("k2", p.k2)):
            assert arrows[f"{name} direction"] is not None
            assert colours[f"{name} = {k:.3g}"] == pytest.approx((*arrows[f"{name} direction"], 1))
        assert colours[f"k1 = {p.k1:.3g}"] != colours[f"k2 = {p.k2:.3g}"]
