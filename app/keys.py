"""Shortcut key names (what a panel declares in ``keys``) and the imgui key codes they name
(no polyscope import)."""

from __future__ import annotations

KEYS = {
    "space": "ImGuiKey_Space",
    "left": "ImGuiKey_LeftArrow",
    "right": "ImGuiKey_RightArrow",
    "up": "ImGuiKey_UpArrow",
    "down": "ImGuiKey_DownArrow",
    "escape": "ImGuiKey_Escape",
    "enter": "ImGuiKey_Enter",
    "tab": "ImGuiKey_Tab",
    "backspace": "ImGuiKey_Backspace",
    "delete": "ImGuiKey_Delete",
    "home": "ImGuiKey_Home",
    "end": "ImGuiKey_End",
    "pageup": "ImGuiKey_PageUp",
    "pagedown": "ImGuiKey_PageDown",
}
"""The named shortcut keys and their imgui names; any single letter or digit needs no entry
(see :func:`imgui_key`)."""


def imgui_key(name: str) -> str:
    """The imgui name of the shortcut key ``name``.

    Parameters
    ----------
    name : str
        A key of :data:`KEYS` (``"space"``, ``"left"``, ...) or one letter or digit, in either
        case (``"f"`` and ``"F"`` are the same key).

    Returns
    -------
    str
        The attribute of ``polyscope.imgui`` holding the key's code.

    Raises
    ------
    ValueError
        For any other name (a typo in a panel's shortcut fails at once, also in tests).

    Examples
    --------
    >>> imgui_key("space"), imgui_key("f"), imgui_key("7")
    ('ImGuiKey_Space', 'ImGuiKey_F', 'ImGuiKey_7')
    """
    low = name.lower()
    if low in KEYS:
        return KEYS[low]
    if len(name) == 1 and name.isascii() and name.isalnum():
        return f"ImGuiKey_{name.upper()}"
    raise ValueError(
        f"unknown shortcut key {name!r}: use one letter or digit, or one of {', '.join(KEYS)}"
    )
