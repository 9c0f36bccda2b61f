"""The mouse on handle discs (a mixin of the panel that moves them): a press on a handle drags
it in the screen plane; a press elsewhere released in place is a click (a handle; shift: one
more; ctrl: a fixed disc). The panel provides ``state`` (seeds, moves, the built handle set),
``_positions(host, method)`` and the names of the structures it draws.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import polyscope as ps

from .host import Host
from .rigid_drag import display_frame, screen_plane_point
from .scene import picked_vertex

CLICK_SLOP = 5.0
"""A press and release this many pixels apart or fewer is a click (more: the camera turned)."""
DRAG_TIP = (
    "press on a handle (red) and drag: it moves in the screen plane; press elsewhere and drag: "
    "the camera turns"
)


class HandleMouse:
    """Picks, clicks and screen-plane drags of handle discs (see the module docstring)."""

    state: Any
    copies: tuple[str, str]  # the deformed copies' structures (first method, second)
    dots: tuple[str, str]  # the handle points' and the fixed points' structures
    _press: tuple[int, frozenset[str], tuple[float, float]] | None = None
    _drag: dict[str, Any] | None = None

    def _positions(self, host: Host, method: str) -> np.ndarray:
        raise NotImplementedError

    def pick(self, host: Host, hit: Any, active: Any) -> bool:
        """A press on a deformed copy: on a handle it starts a screen-plane drag; elsewhere
        it is kept and becomes a click if the mouse is released where it was pressed."""
        if active is not self or hit.structure_name not in (*self.copies, *self.dots):
            return False
        st = self.state
        idx = self._picked(host, hit)
        if idx is None:
            return False
        io = host.ui.im.GetIO()
        at = (float(io.MousePos[0]), float(io.MousePos[1]))
        mods = frozenset(getattr(hit, "modifiers", ()))
        b = st.built
        if not mods and b is not None and idx in set(b.regions.vertices.tolist()):
            seed = int(b.regions.seeds[b.regions.region[np.searchsorted(b.regions.vertices, idx)]])
            if seed in st.handles:
                self.start_drag(host, st.handles.index(seed), np.asarray(hit.position), at)
                return True
        self._press = (idx, mods, at)
        return True

    def _picked(self, host: Host, hit: Any) -> int | None:
        """The mesh vertex a pick hit: on a copy, or a handle's or the fixed region's point."""
        st, b = self.state, self.state.built
        data = hit.structure_data
        if hit.structure_name in self.dots:
            if b is None or "index" not in data:
                return None
            points = b.regions.vertices if hit.structure_name == self.dots[0] else b.fixed
            i = int(data.get("index", -1))
            return int(points[i]) if 0 <= i < len(points) else None
        method = st.methods[0 if hit.structure_name == self.copies[0] else -1]
        return picked_vertex(hit, self._positions(host, method), host.state.mesh.F)

    def start_drag(
        self, host: Host, index: int, anchor: np.ndarray, at: tuple[float, float]
    ) -> None:
        """Drag handle ``index`` in the screen plane from the display point ``anchor`` (the
        camera stays put meanwhile)."""
        st = self.state
        st.active = index
        st.checkpoint()
        self._drag = {"index": index, "anchor": anchor, "move": dict(st.moves[index]), "at": at}
        ps.set_do_default_mouse_interaction(False)

    def _end_drag(self) -> None:
        self._drag = None
        ps.set_do_default_mouse_interaction(True)

    def follow_drag(self, host: Host, xy: tuple[float, float]) -> None:
        """The dragged handle follows the mouse in the screen plane (its turn kept)."""
        drag = self._drag
        assert drag is not None
        p = screen_plane_point(xy, drag["anchor"])
        if p is None:
            return
        Rd, s, _ = display_frame(host.state.display)
        delta = Rd.T @ (p - drag["anchor"]) / s
        base = drag["move"]
        move = {"rotate": list(base["rotate"]), "move": list(np.asarray(base["move"]) + delta)}
        self.state.set_move(drag["index"], move)

    def handle_mouse(self, host: Host) -> bool:
        """This frame's mouse: follow a drag, end it, or turn a press released in place into a
        click. Returns whether the left button is held."""
        xy, held = host.ui.scene_drag(DRAG_TIP)
        st = self.state
        if self._drag is not None:
            if held:
                self.follow_drag(host, xy)
            else:
                a = self._drag["at"]
                if math.dist(a, xy) <= CLICK_SLOP and st.moves == st.undo_stack[-1]["moves"]:
                    st.undo_stack.pop()  # a click on a handle: it is the active one now
                self._end_drag()
        elif self._press is not None and not held:
            vertex, mods, at = self._press
            self._press = None
            if math.dist(at, xy) <= CLICK_SLOP:
                self.click(host, vertex, mods)
        return held

    def click(self, host: Host, vertex: int, mods: frozenset[str] = frozenset()) -> bool:
        """A vertex clicked: the handle (shift: one more; ctrl: a fixed disc, again: let go)."""
        n = len(host.state.mesh.V)
        if "ctrl" in mods:
            return self.state.add_fixed(n, vertex)
        return self.state.select(n, vertex, add="shift" in mods)
