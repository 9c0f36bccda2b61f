"""Play in the views that animate: the smoothing play stops at the first step that grows past the
stable limit (saying why) while a stable λ plays on; the k sweep's play and pause are one
button's width and its caption names the k of the slider drawn in the same frame."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

ps = pytest.importorskip("polyscope")


from tests.support.widgets import compute_basis, drive, frames  # noqa: E402


def test_play_beyond_the_stable_limit_stops_at_the_first_growing_step(viewer):
    viewer.set_panel("smoothing")
    frames(viewer)
    st = viewer.panels["smoothing"].state
    drive(viewer, "method", "explicit")
    drive(viewer, "noise alpha", 0.01)
    limit = st.smoother.stability.max_stable_lam
    assert limit is not None
    drive(viewer, "lambda", str(1.5 * limit))
    assert st.smoother.stability.message()  # the warning is shown

    def rms_move(before: np.ndarray) -> float:
        return float(np.sqrt(np.mean(np.sum((np.array(st.V) - before) ** 2, axis=1))))

    before = np.array(st.V)
    drive(viewer, "play", True)  # the frame that presses play takes the first step
    moves = [rms_move(before)]
    for _ in range(60):
        if not st.playing:
            break
        before = np.array(st.V)
        frames(viewer)
        moves.append(rms_move(before))
    assert not st.playing, "play ran on beyond the stable limit"
    assert "play stopped at iteration" in st.error and "stable limit" in st.error
    # it stopped at the first step that grew (the last one), well before the mesh blows up
    assert len(moves) >= 2 and moves[-1] > moves[-2]
    assert all(b <= a for a, b in pairwise(moves[:-1]))
    assert f"iteration {st.smoother.iteration}:" in st.error
    drift = float(np.sqrt(np.mean(np.sum((np.array(st.V) - st.V_start) ** 2, axis=1))))
    diagonal = float(np.linalg.norm(np.ptp(st.V_start, axis=0)))
    assert drift < 0.5 * diagonal
    # the panel shows why (in red, under the buttons); a stable lambda plays on
    drive(viewer, "reset", True)
    drive(viewer, "lambda", str(0.5 * limit))
    drive(viewer, "play", True)
    frames(viewer, 30)
    assert st.playing and st.smoother.iteration >= 30 and not st.error
    viewer.ui.script("key space", True)
    frames(viewer)
    assert not st.playing


def test_play_and_pause_are_one_width(viewer):
    compute_basis(viewer)
    st = viewer.panels["spectral"].state
    drive(viewer, "play what", "k sweep")
    widths = viewer.ui.button_widths
    drive(viewer, "play", True)
    assert st.playing
    frames(viewer, 2)
    drive(viewer, "pause", True)
    assert not st.playing
    frames(viewer)
    # play and pause take turns in one place: the same width, wide enough for either label
    w_play, w_pause = widths[("spectral", "play")], widths[("spectral", "pause")]
    assert w_play == w_pause > 0
    assert w_play >= max(ps.imgui.CalcTextSize(t)[0] for t in ("play", "pause"))


def test_the_caption_shows_the_k_of_the_slider_drawn_in_the_same_frame(viewer):
    compute_basis(viewer)
    st = viewer.panels["spectral"].state
    drive(viewer, "play what", "k sweep")
    drive(viewer, "play", True)
    assert st.playing
    viewer.ui.overlays.clear()
    for _ in range(5):
        frames(viewer)
        # the slider drawn this frame and the caption under the copy name the same k
        k = viewer.ui.drawn[("spectral", "k (reconstruct)")]
        assert k == st.k
        captions = [t for _, t in viewer.ui.overlays if t.startswith("k = ")]
        assert captions == [f"k = {k} of {st.basis.k_max} modes"]
        viewer.ui.overlays.clear()
    drive(viewer, "pause", True)
