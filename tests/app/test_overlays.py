"""Text drawn over the scene: hovering a neighbour's sphere names its weight, and hover labels and
the captions of side-by-side copies end left of meshlap's panel."""

from __future__ import annotations

import pytest

ps = pytest.importorskip("polyscope")


from tests.support.widgets import drive, frames  # noqa: E402


def test_hovering_a_neighbour_sphere_shows_its_weight(viewer, monkeypatch):
    from types import SimpleNamespace

    viewer.set_panel("onering")
    drive(viewer, "vertex", 5)
    panel = viewer.panels["onering"]
    r = panel.state
    hit = SimpleNamespace(is_hit=True, structure_name="one-ring neighbours", local_index=2)
    monkeypatch.setattr(ps, "pick", lambda screen_coords: hit)
    text = panel.hover_text(viewer, (10.0, 10.0))
    j = r.neighbors[2]
    w = next(t.weight_cotan for t in r.inspection.neighbors if t.index == j)
    assert text == f"neighbour 2 = vertex {j}: w_ij = {w:.4g}"
    assert panel.hovered_vertex == j  # its table row is lit


def test_hover_labels_and_captions_end_left_of_the_panel(viewer, monkeypatch):
    from meshlap_app.scene import scene_width
    from meshlap_app.state.onering import HoverThrottle

    viewer.set_panel("onering")
    frames(viewer)
    panel = viewer.panels["onering"]
    t = [0.0]
    panel.clock, panel.throttle = (lambda: t[0]), HoverThrottle()
    label = "vertex 12345   field value -0.000123456"
    monkeypatch.setattr(panel, "hover_text", lambda host, pos: label)
    w, _ = ps.get_window_size()
    right = scene_width(w, viewer.state.ui_scale)
    for x in (40.0, right - 30.0, w - 5.0):  # clear of the panel, near it, under it
        for _ in range(3):  # the cursor rests: picked, then shown
            viewer.ui.overlays.clear()
            drive(viewer, "hover", (x, 100.0))
            t[0] += 0.2
        shown = [pos for pos, text in viewer.ui.overlays if text == label]
        assert shown, f"no hover label at x={x}"
        (lx, _), width = shown[-1], ps.imgui.CalcTextSize(label)[0]
        assert lx + width <= viewer.ui.overlay_right <= right
        if x + 16 + width <= right:
            assert lx == x + 16  # where it was when there is room
    # captions of side-by-side copies too (curvature side by side)
    viewer.set_panel("curvature")
    drive(viewer, "side by side", True)
    viewer.ui.overlays.clear()
    frames(viewer, 2)
    captions = viewer.ui.overlays
    assert captions
    for (cx, _), text in captions:
        assert 0 <= cx and cx + ps.imgui.CalcTextSize(text)[0] <= right
    drive(viewer, "side by side", False)
