"""The window itself: its title, its place on the screen, and the wait for its events.

polyscope 2.6's Python API sets the title once, when the window is created
(``set_program_name``), and has no call that places the window or tells the screen's size: it
opens a 1280×720 window at (20, 20), cut at the edge of a 1280×720 screen. The GLFW library
that draws polyscope's window is linked into polyscope's binding and exports GLFW's public C
API (``glfwSetWindowTitle``, ``glfwGetMonitorWorkarea``, ``glfwSetWindowPos``, ...): this
module calls those functions on polyscope's own window (the current GLFW context), through
:mod:`ctypes`, with no new dependency. Where they cannot be reached (another build of
polyscope, a headless backend) nothing is called: :func:`can_follow` is then False and
the viewer keeps a title that names no mesh (:func:`window_title`), so the title never lies.

Between two frames the window waits for its events (``glfwWaitEventsTimeout``,
:func:`wait_events`): a key or a mouse move ends the wait at once, where a sleep would keep
it waiting out the idle frame period (:mod:`.pacing`); another thread ends it with
:func:`wake` (``glfwPostEmptyEvent``, which GLFW allows from any thread).

The placement rule (:func:`fit_window`, pure): the window with its frame fits inside the
monitor's work area (the screen less panels and docks); a wanted size that does not fit
shrinks to the work area, and the window is centred in it.
"""

from __future__ import annotations

import ctypes
from functools import cache
from typing import Any

PRODUCT = "meshlap"
"""The window title when it cannot follow the mesh shown."""


def window_title(mesh_name: str | None, follows: bool) -> str:
    """``meshlap — <file>`` when the title can follow every mesh opened, else ``meshlap``
    (a title set once would keep naming the first mesh)."""
    return f"{PRODUCT} — {mesh_name}" if follows and mesh_name else PRODUCT


def fit_window(
    area: tuple[int, int, int, int],
    wanted: tuple[int, int],
    frame: tuple[int, int, int, int] = (0, 0, 0, 0),
) -> tuple[int, int, int, int]:
    """Position and size of a window's content area that fits, frame included, in ``area``.

    Parameters
    ----------
    area : (x, y, width, height) int
        The monitor's work area in screen pixels.
    wanted : (width, height) int
        The content size asked for (polyscope's 1280×720, or a saved one).
    frame : (left, top, right, bottom) int
        The window manager's decoration around the content (0 without one).

    Returns
    -------
    (x, y, width, height) int
        The content's top-left corner and size: ``width + left + right <= area width`` (the
        same for the height, sizes at least 1), centred in ``area``.
    """
    ax, ay, aw, ah = area
    left, top, right, bottom = frame
    w = max(1, min(int(wanted[0]), aw - left - right))
    h = max(1, min(int(wanted[1]), ah - top - bottom))
    x = ax + left + max(0, (aw - left - right - w) // 2)
    y = ay + top + max(0, (ah - top - bottom - h) // 2)
    return x, y, w, h


@cache
def _glfw() -> Any:
    """polyscope's binding opened as a C library with GLFW's functions typed, or None when
    it exports none of them."""
    try:
        import polyscope_bindings

        lib = ctypes.CDLL(polyscope_bindings.__file__)
        lib.glfwGetCurrentContext.restype = ctypes.c_void_p
        lib.glfwGetCurrentContext.argtypes = []
        lib.glfwSetWindowTitle.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
        lib.glfwGetPrimaryMonitor.restype = ctypes.c_void_p
        lib.glfwGetPrimaryMonitor.argtypes = []
        ints = [ctypes.POINTER(ctypes.c_int)] * 4
        lib.glfwGetMonitorWorkarea.argtypes = [ctypes.c_void_p, *ints]
        lib.glfwGetWindowFrameSize.argtypes = [ctypes.c_void_p, *ints]
        lib.glfwSetWindowPos.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
        lib.glfwGetWindowPos.argtypes = [ctypes.c_void_p, *ints[:2]]
        lib.glfwWaitEventsTimeout.argtypes = [ctypes.c_double]
        lib.glfwPostEmptyEvent.argtypes = []
    except (ImportError, OSError, AttributeError):
        return None
    return lib


def _window() -> tuple[Any, int] | None:
    """GLFW and polyscope's window (the current context), or None (headless, no GLFW)."""
    lib = _glfw()
    if lib is None:
        return None
    win = lib.glfwGetCurrentContext()
    return (lib, win) if win else None


def can_follow() -> bool:
    """Before the window opens: its title will be changeable later (polyscope's binding
    exports GLFW's functions)."""
    return _glfw() is not None


def title_follows() -> bool:
    """The window's title can be changed now (a GLFW window of polyscope's is open)."""
    return _window() is not None


def set_title(text: str) -> bool:
    """Write ``text`` in the window's title bar; False when there is no such window."""
    found = _window()
    if found is None:
        return False
    lib, win = found
    lib.glfwSetWindowTitle(win, text.encode("utf-8"))
    return True


def wait_events(seconds: float) -> bool:
    """Wait up to ``seconds`` for an event of polyscope's window (input, an expose, a
    :func:`wake`) and hand what arrived to its callbacks (ImGui queues the input for the next
    frame). The GIL is released meanwhile (a :mod:`ctypes` call): jobs' threads run. False
    when there is no GLFW window (nothing waited: the caller sleeps its own way)."""
    found = _window()
    if found is None:
        return False
    lib, _ = found
    lib.glfwWaitEventsTimeout(max(float(seconds), 0.0))
    return True


def wake() -> None:
    """End the window's :func:`wait_events` now (from any thread: GLFW posts an empty event).
    Only once the window is open (:func:`title_follows`, on the UI thread)."""
    lib = _glfw()
    if lib is not None:
        lib.glfwPostEmptyEvent()


def _four(fn: Any, handle: int) -> tuple[int, int, int, int]:
    vals = [ctypes.c_int(0) for _ in range(4)]
    fn(handle, *(ctypes.byref(v) for v in vals))
    a, b, c, d = (v.value for v in vals)
    return a, b, c, d


def screen_area() -> tuple[int, int, int, int] | None:
    """The primary monitor's work area ``(x, y, width, height)``, or None when unknown."""
    found = _window()
    if found is None:
        return None
    lib, _ = found
    monitor = lib.glfwGetPrimaryMonitor()
    if not monitor:
        return None
    area = _four(lib.glfwGetMonitorWorkarea, monitor)
    return area if area[2] > 0 and area[3] > 0 else None


def window_position() -> tuple[int, int] | None:
    """The content area's top-left corner on the screen, or None without a window."""
    found = _window()
    if found is None:
        return None
    lib, win = found
    x, y = ctypes.c_int(0), ctypes.c_int(0)
    lib.glfwGetWindowPos(win, ctypes.byref(x), ctypes.byref(y))
    return x.value, y.value


def place_window(wanted: tuple[int, int]) -> tuple[int, int, int, int] | None:
    """Size and place the window by :func:`fit_window` on the screen it opened on; returns
    ``(x, y, width, height)``, or None (nothing changed) when the screen is unknown."""
    import polyscope as ps

    area = screen_area()
    found = _window()
    if area is None or found is None:
        return None
    lib, win = found
    frame = _four(lib.glfwGetWindowFrameSize, win)
    x, y, w, h = fit_window(area, wanted, frame)
    ps.set_window_size(w, h)
    lib.glfwSetWindowPos(win, x, y)
    return x, y, w, h
