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
