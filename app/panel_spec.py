"""The panel contract: one :class:`PanelSpec` per panel, declared in ``app/state/<name>.py``.

A spec says, in one typed place, everything a host needs to know of a panel before it draws:
its name (module, session section, ``--panel`` value), its title (its header) and one-line
summary (``meshlap view --help``), whether it is a *view* of the combo or a section drawn on
every frame, its panel class (named, loaded only when a window or a render needs it, so
``meshlap view --help`` never imports polyscope), its state factory, its one settings schema
(:class:`~meshlap_app.state.settings.Settings`) and, as named members, what the schema cannot
say alone: the checks across a section's keys (``check_section``), against the session's mesh
(``check_mesh``), of the ``meshlap view`` options against the loaded mesh (``check_start``), and
its ``meshlap animate`` declaration (:class:`~meshlap_app.state.animation.Animation`).

The registry (:mod:`meshlap_app.registry`) lists the specs; the session file, the command-line
flags and their help, the animator, the state's slices and the tests are derived from them. A
spec missing a required part fails when its module is imported, naming the panel.
"""

from __future__ import annotations

import pkgutil
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

from meshlap_core.errors import MeshError

from .state.animation import Animation
from .state.settings import UNSET, Flag, Setting, Settings

Command = Literal["view", "animate"]


class SpecError(ValueError):
    """A panel spec that lacks a required part or contradicts itself (raised at import)."""


@dataclass(frozen=True, kw_only=True)
class PanelSpec:
    """One panel's declaration (see the module docstring).

    Attributes
    ----------
    name : str
        The panel's name: ``app/panels/<name>.py``, ``app/state/<name>.py``, its session
        section and ``--panel`` value.
    title : str
        Its header in meshlap's panel.
    summary : str
        One line: what it shows or does (``meshlap view --help``).
    panel : str
        The name of its :class:`~meshlap_app.panels.base.Panel` subclass in
        ``app/panels/<name>.py`` (imported by :meth:`panel_class`, not before).
    view : bool
        A view of the *view* combo and a number key; ``False``: a section drawn every frame.
    state : callable or None
        Makes its slice of :class:`~meshlap_app.state.app.AppState` (``None``: it has none).
    settings : Settings
        Its settings: the session section, flags, widget limits and test tables.
    check_section : callable or None
        ``check_section(values, source)``: checks across the keys of a read section (each
        key already checked); may normalize ``values`` in place.
    check_mesh : callable or None
        ``check_mesh(values, mesh, source)``: refuses a section that does not fit the
        session's mesh (a vertex it does not have), naming ``section.key``.
    check_start : callable or None
        ``check_start(options, state)``: its ``meshlap view`` options (parsed and in range)
        against the loaded mesh, naming the flag.
    animation : Animation or None
        ``meshlap animate --panel <name>`` (``None``: not animatable).
    unsaved : dict of str to str
        Each widget label of the panel that sets none of its settings, and why it is not a
        setting (an action such as *play* or *export*, a value a session keeps elsewhere, a
        setting another panel declares). With its settings' ``labels`` these are all its
        widgets (``tests/test_viewer_widgets.py`` audits them): a widget a user can change is
        declared, and so kept by a session, or says here why not.
    """

    name: str = UNSET
    title: str = UNSET
    summary: str = UNSET
    panel: str = UNSET
    view: bool = True
    state: Callable[[], Any] | None = None
    settings: Settings = field(default_factory=Settings)
    check_section: Callable[[dict[str, Any], Any], None] | None = None
    check_mesh: Callable[[dict[str, Any], Any, Any], None] | None = None
    check_start: Callable[[dict[str, Any], Any], None] | None = None
    animation: Animation | None = None
    unsaved: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        name = self.name if isinstance(self.name, str) else "?"
        if not name.isidentifier():
            raise SpecError(f"a panel spec needs a name (an identifier), got {self.name!r}")
        for part in ("title", "summary", "panel"):
            value = getattr(self, part)  # the spec's own fields, by name
            if not isinstance(value, str) or not value.strip():
                raise SpecError(f"panel {name!r}: its spec lacks its {part}")
        if not self.panel.isidentifier():
            raise SpecError(f"panel {name!r}: panel must name its class, got {self.panel!r}")
        if not isinstance(self.settings, Settings):
            raise SpecError(f"panel {name!r}: settings must be a Settings, got {self.settings!r}")
        if self.state is not None and not callable(self.state):
            raise SpecError(f"panel {name!r}: state must make its state slice")
        if self.animation is not None and not isinstance(self.animation, Animation):
            raise SpecError(f"panel {name!r}: animation must be an Animation")
        if (self.animation is not None or self.flags("view")) and not self.view:
            raise SpecError(f"panel {name!r}: a section (view=False) has no flags or animation")
        for command in ("view", "animate"):
            dests = [f.dest for _, f in self.flags(command)]  # type: ignore[arg-type]
            if command == "animate" and self.animation is not None:
                dests += [o.dest for o in self.animation.options]
            if len(set(dests)) != len(dests):
                raise SpecError(f"panel {name!r}: two {command} flags share a name")
        if self.flags("animate") and self.animation is None:
            raise SpecError(f"panel {name!r}: animate flags without an animation")
        for label, why in self.unsaved.items():
            if not (isinstance(why, str) and why.strip()):
                raise SpecError(f"panel {name!r}: unsaved widget {label!r} needs its reason")
            if any(label in s.labels for s in self.settings):
                raise SpecError(f"panel {name!r}: {label!r} is a setting's widget, not unsaved")

    # -------------------------------------------------------------- the panel
    def panel_class(self) -> type:
        """The panel's class, resolved from its reference ``meshlap_app.panels.<name>:<panel>``
        (imports polyscope; :func:`pkgutil.resolve_name`, as an entry point is loaded).

        Raises
        ------
        SpecError
            The module has no class of that name.
        """
        reference = f"meshlap_app.panels.{self.name}:{self.panel}"
        try:
            cls = pkgutil.resolve_name(reference)
        except AttributeError:
            cls = None
        if not isinstance(cls, type):
            raise SpecError(f"panel {self.name!r}: {reference} is not a class")
        return cls

    # -------------------------------------------------------------- flags
    def flags(self, command: Command) -> list[tuple[Setting, Flag]]:
        """The settings with a flag of ``command`` and that flag."""
        out = []
        for s in self.settings:
            flag = s.view if command == "view" else s.animate
            if flag is not None:
                out.append((s, flag))
        return out

    def check_view(self, options: dict[str, Any], state: Any) -> None:
        """Its ``meshlap view`` options (by dest; ``None``: not given): each parsed and checked
        in place by its setting (type and range), then against the loaded mesh
        (``check_start``).

        Raises
        ------
        MeshError
            Naming the flag.
        """
        for setting, flag in self.flags("view"):
            if options.get(flag.dest) is not None:
                options[flag.dest] = setting.from_flag(options[flag.dest], flag.name)
        if self.check_start is not None:
            self.check_start(options, state)

    # -------------------------------------------------------------- sessions
    def check_values(self, values: Any, source: Any) -> dict[str, Any]:
        """Its section of a session file checked (each key, then across keys).

        Raises
        ------
        MeshError
            Naming ``section.key`` and the problem.
        """
        out = self.settings.check(values, self.name, source)
        if self.check_section is not None:
            self.check_section(out, source)
        return out

    # -------------------------------------------------------------- meshlap animate
    def animation_options(self, typed: dict[str, Any]) -> dict[str, Any]:
        """The options of its animation as typed (``None``: not typed), by dest."""
        anim = self.animation_declared()
        dests = [f.dest for _, f in self.flags("animate")] + [o.dest for o in anim.options]
        return {d: typed.get(d) for d in dests}

    def fill_options(
        self, options: dict[str, Any], section: dict[str, Any] | None, source: Any = None
    ) -> None:
        """Fill what was not typed: from a session's ``section`` when given (the animation's
        ``from_session`` first, which sees what was typed; then each setting's flag takes
        the saved value), then the built-in defaults."""
        anim = self.animation_declared()
        if section is not None:
            anim.from_session(options, section, source)
            for s, flag in self.flags("animate"):
                if options.get(flag.dest) is None:
                    options[flag.dest] = section[s.key]
        for s, flag in self.flags("animate"):
            if options.get(flag.dest) is None:
                options[flag.dest] = s.default if flag.default is UNSET else flag.default
        for opt in anim.options:
            if options.get(opt.dest) is None and opt.default is not None:
                options[opt.dest] = opt.default

    def check_options(self, options: dict[str, Any]) -> None:
        """Check (and convert in place) the animation's options: each setting's flag by its
        setting's type and range, then the animation's own checks.

        Raises
        ------
        MeshError
            Naming the flag.
        """
        anim = self.animation_declared()
        for s, flag in self.flags("animate"):
            if options.get(flag.dest) is not None:
                options[flag.dest] = s.from_flag(options[flag.dest], flag.name)
        anim.check(options)

    def animation_declared(self) -> Animation:
        """Its animation, or a MeshError naming ``--panel`` (not animatable)."""
        if self.animation is None:
            raise MeshError(f"the {self.name} panel has no animation", "--panel")
        return self.animation
