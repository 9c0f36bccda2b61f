"""What a panel declares to be animated by ``meshlap animate --panel NAME`` (no polyscope).

A panel whose spec (:class:`~meshlap_app.panel_spec.PanelSpec`) has an ``animation`` (an
:class:`Animation`) is animatable: the animate command adds its options to the command line
(the flags of its settings, :attr:`.settings.Setting.animate`, and the animation's own
:class:`Option` s: ranges, frame counts), fills the ones not typed from a saved session's
section, checks them before the renderer starts, and the panel's ``frames`` sets up each frame.
Nothing outside the panel's files names its options.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Option:
    """One command-line option of an animation that is not a setting of the panel (a range of
    k, a frame count; argparse's default is ``None`` so that a typed value can be told apart
    from a session's; ``default`` is the built-in one)."""

    flag: str
    help: str
    default: Any = None
    type: Callable[[str], Any] | None = None
    choices: tuple[str, ...] | None = None
    metavar: str | None = None
    store_true: bool = False

    @property
    def dest(self) -> str:
        """The option's key in the options dict (``--lam`` → ``lam``)."""
        return self.flag.lstrip("-").replace("-", "_")


def _no_session(options: dict[str, Any], values: dict[str, Any], source: Any) -> None:
    return None


def _nothing(options: dict[str, Any], mesh: Any) -> None:
    return None


@dataclass(frozen=True)
class Animation:
    """A panel's animation: its options and the functions the animate command calls.

    Attributes
    ----------
    summary : str
        One line for ``meshlap animate --help`` (what the frames show).
    options : tuple of Option
        Its command-line options besides its settings' flags.
    session_help : str
        How a saved session's section fills the options (``--help`` epilog).
    check : callable
        ``check(options)`` after the defaults are filled: validates and converts in place
        (ranges parsed, numbers bounded); raises ``MeshError`` naming the option.
    kind : callable
        ``kind(options)``: what is animated (``smoothing``, ``k``, ``modes``, ``theta``...),
        the key of ``fps``.
    fps : dict
        Default frames per second of each kind.
    frame_count : callable
        ``frame_count(options)``.
    from_session : callable
        ``from_session(options, section, source)`` fills the options not typed (``None``)
        from the panel's saved section, before each setting's flag takes its saved value (so
        it still sees which of those were typed).
    check_mesh : callable
        ``check_mesh(options, mesh)`` once the mesh is loaded (e.g. k ≤ vertices).
    uses_mesh : bool
        ``False``: the frames do not show the mesh (it is not loaded without a session).
    colorbar : bool
        The frames show a colour map, whose on-screen colour bar is kept (polyscope draws it
        with imgui).
    session_overrides : dict
        Settings of the panel's section replaced when a session is restored before its
        animation (e.g. the smoothing restarts at iteration 0: the frames run it). Other
        panels' sections take their settings' ``quiet`` values (nothing computed).
    """

    summary: str
    options: tuple[Option, ...]
    check: Callable[[dict[str, Any]], None]
    kind: Callable[[dict[str, Any]], str]
    fps: dict[str, float]
    frame_count: Callable[[dict[str, Any]], int]
    session_help: str = ""
    from_session: Callable[[dict[str, Any], dict[str, Any], Any], None] = _no_session
    check_mesh: Callable[[dict[str, Any], Any], None] = _nothing
    uses_mesh: bool = True
    colorbar: bool = True
    session_overrides: dict[str, Any] = field(default_factory=dict)


RECORDER_WIDGETS: dict[str, str] = {
    "record file": "the file the next recording writes (an action's argument)",
    "record": "an action: records a frame per change from now",
    "stop": "an action: writes the recording",
}
"""The *record* header's widgets (:mod:`meshlap_app.record`) in a panel that plays: why none
is a setting (a panel's spec lists them in its ``unsaved``)."""
