"""The camera of a saved session: the one check for ``meshlap view --session`` and
``meshlap animate --session`` (no polyscope import).

A session's ``camera`` is polyscope's ``get_view_as_json()`` parsed. polyscope applies it
unchecked: a window 100000 or −5 pixels wide ends in an OpenGL error, and a bad ``fov``, a
short ``viewMat`` or a string width are silently ignored. :func:`check_camera` refuses all of
them, and any key polyscope does not write, when the session is read
(:func:`.session.from_dict`), so both commands say the same thing before a renderer starts.
"""

from __future__ import annotations

import json
import math
from typing import Any

from meshlap_core.errors import MeshError

MIN_WINDOW = 64
MAX_WINDOW = 8192
"""A saved window's width and height are integers in ``MIN_WINDOW..MAX_WINDOW`` pixels."""
MIN_FOV, MAX_FOV = 1.0, 179.0
"""The vertical field of view, in degrees (``tan(fov/2)`` must be finite and > 0)."""

PROJECTION_MODES = ("Perspective", "Orthographic")
UP_DIRS = ("X Up", "NegX Up", "Y Up", "NegY Up", "Z Up", "NegZ Up")
FRONT_DIRS = ("X Forward", "NegX Forward", "Y Forward", "NegY Forward", "Z Forward", "NegZ Forward")
NAVIGATE_STYLES = ("Turntable", "Free", "Planar", "Arcball", "None", "First Person")
VIEW_RELATIVE_MODES = ("Center Relative", "Length Relative")
"""The names polyscope 2.6 writes for its enums (anything else it ignores without a word)."""

WINDOW_KEYS = ("windowWidth", "windowHeight")


def _window(x: Any) -> str | None:
    if isinstance(x, int) and not isinstance(x, bool) and MIN_WINDOW <= x <= MAX_WINDOW:
        return None
    shown = json.dumps(x) if not isinstance(x, int) or abs(x) < 10**40 else "a huge integer"
    return f"must be an integer {MIN_WINDOW} to {MAX_WINDOW}, got {shown}"


def _finite(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def _numbers(count: int) -> Any:
    def check(x: Any) -> str | None:
        if isinstance(x, list) and len(x) == count and all(_finite(v) for v in x):
            return None
        if not isinstance(x, list):
            return f"must be a list of {count} finite numbers, got {_short(x)}"
        if len(x) != count:
            return f"must be a list of {count} finite numbers, got {len(x)} entries"
        k = next(i for i, v in enumerate(x) if not _finite(v))
        return f"must be a list of {count} finite numbers, entry {k} is {_short(x[k])}"

    return check


def _positive(x: Any) -> str | None:
    return None if _finite(x) and x > 0 else f"must be a finite number > 0, got {_short(x)}"


def _fov(x: Any) -> str | None:
    if _finite(x) and MIN_FOV <= x <= MAX_FOV:
        return None
    return f"must be a number of degrees {MIN_FOV:g} to {MAX_FOV:g}, got {_short(x)}"


def _name(choices: tuple[str, ...]) -> Any:
    def check(x: Any) -> str | None:
        if isinstance(x, str) and x in choices:
            return None
        return f"must be one of {', '.join(map(repr, choices))}, got {_short(x)}"

    return check


def _short(x: Any) -> str:
    """``x`` as JSON, cut to 60 characters (a hostile value may be huge)."""
    text = json.dumps(x) if not (isinstance(x, int) and abs(x) >= 10**40) else "a huge integer"
    return text if len(text) <= 60 else text[:57] + "..."


CAMERA_KEYS: dict[str, Any] = {
    "farClip": _positive,
    "fov": _fov,
    "frontDir": _name(FRONT_DIRS),
    "navigateStyle": _name(NAVIGATE_STYLES),
    "nearClip": _positive,
    "projectionMode": _name(PROJECTION_MODES),
    "upDir": _name(UP_DIRS),
    "viewCenter": _numbers(3),
    "viewMat": _numbers(16),
    "viewRelativeMode": _name(VIEW_RELATIVE_MODES),
    "windowHeight": _window,
    "windowWidth": _window,
}
"""Each key polyscope's ``get_view_as_json()`` writes, with its check (every key optional)."""


def check_camera(camera: Any, source: Any) -> dict[str, Any] | None:
    """Return a session's ``camera`` (``None`` or a checked dict), or refuse it.

    Parameters
    ----------
    camera : object
        The parsed ``camera`` entry of a session file.
    source : str or PathLike
        Named in the error (the session file).

    Returns
    -------
    dict or None

    Raises
    ------
    MeshError
        ``camera`` is not an object or ``null``; it has a key polyscope does not write
        (:data:`CAMERA_KEYS`); a window size that is not an integer
        ``MIN_WINDOW..MAX_WINDOW``; an unknown projection mode or direction; a ``fov`` that is
        not a finite number of degrees in ``MIN_FOV..MAX_FOV``; a ``viewMat`` that is not 16
        finite numbers. The message names ``camera.<key>``.
    """
    if camera is None:
        return None
    if not isinstance(camera, dict):
        raise MeshError(f'"camera" must be an object or null, got {_short(camera)}', source)
    unknown = sorted(set(camera) - set(CAMERA_KEYS))
    if unknown:
        shown = ", ".join(repr(k[:40]) for k in unknown[:5]) + (", ..." if len(unknown) > 5 else "")
        raise MeshError(f"unknown key(s) in 'camera': {shown}", source)
    for key, check in CAMERA_KEYS.items():
        if key in camera:
            problem = check(camera[key])
            if problem:
                raise MeshError(f'"camera.{key}" {problem}', source)
    return camera


def window_size(camera: dict[str, Any], source: Any) -> tuple[int, int]:
    """The window size saved with ``camera`` (``meshlap animate --session`` needs it).

    Raises
    ------
    MeshError
        ``windowWidth`` or ``windowHeight`` missing or not an integer
        ``MIN_WINDOW..MAX_WINDOW``.
    """
    size = []
    for key in WINDOW_KEYS:
        x = camera.get(key)
        problem = _window(x)
        if problem:
            raise MeshError(f'"camera.{key}" {problem}', source)
        size.append(int(x))
    return size[0], size[1]


def captured(camera: dict[str, Any]) -> dict[str, Any]:
    """polyscope's view as a session keeps it: the keys of :data:`CAMERA_KEYS` only, and a
    window size brought into ``MIN_WINDOW..MAX_WINDOW`` (a window can be resized beyond),
    so that every session the viewer saves reads back."""
    out = {k: v for k, v in camera.items() if k in CAMERA_KEYS}
    for key in WINDOW_KEYS:
        x = out.get(key)
        if isinstance(x, int) and not isinstance(x, bool):
            out[key] = min(max(x, MIN_WINDOW), MAX_WINDOW)
    return out
