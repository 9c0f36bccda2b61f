"""The Help section: shortcuts, mouse use, polyscope's own panels, the UI scale and sessions."""

from __future__ import annotations

import polyscope as ps

from ..host import Host
from ..panel_spec import PanelSpec
from ..registry import VIEW_KEYS, VIEWS
from ..session import SessionWidgets
from .base import HOST_SHORTCUTS, Panel


def shortcut_rows(host: Host) -> list[tuple[str, str]]:
    """Every key the window answers: the views' numbers and the host's own keys, then each
    panel's (registry order)."""
    digits = [k for k in VIEW_KEYS if k != "0"]
    rows = [(f"{digits[0]}-{digits[-1]}", f"views: {', '.join(VIEWS[: len(digits)])}")]
    if "0" in VIEW_KEYS:
        rows.append(("0", f"the tenth view ({VIEWS[VIEW_KEYS.index('0')]})"))
    rows += HOST_SHORTCUTS
    for p in host.panels.values():
        rows += list(p.shortcuts)
    return rows


class HelpPanel(Panel):
    """Shortcut list, a toggle for polyscope's own panels, the UI scale, saved sessions."""

    keys = ("h",)
    shortcuts = (("H", "this help"),)

    def __init__(self, spec: PanelSpec, state: object = None) -> None:
        super().__init__(spec, state)
        self.open: bool | None = None  # H toggles: force the header open / closed once
        self.shown = False
        self.polyscope_panels = False
        self.session = SessionWidgets()  # save / load a session (app/session.py)

    def on_key(self, host: Host, key: str) -> bool:
        if key != "h":
            return False
        self.toggle()
        return True

    def toggle(self) -> None:
        self.shown = not self.shown
        self.open = self.shown

    def draw(self, host: Host) -> None:
        ui = host.ui
        self.shown = ui.header(self.title, default_open=False, force=self.open)
        self.open = None
        if not self.shown:
            return
        self.session.draw(host)  # first: the lecture's prepared view, one click away
        for key, what in shortcut_rows(host):
            ui.text(f"{key:>12}  {what}")
        ch, on = ui.checkbox(
            "polyscope's own panels",
            self.polyscope_panels,
            "show polyscope's options and structure list on the left",
        )
        if ch:
            self.polyscope_panels = on
            ps.set_build_default_gui_panels(on)
            host.request_frame()
        ch, scale = ui.slider_float(
            "UI scale",
            host.state.ui_scale,
            0.5,
            3.0,
            "%.2f",
            "size of text and widgets (projectors)",
        )
        if ch:
            host.set_ui_scale(scale)
