"""The registry of the viewer's panels: the one place that lists them, as their specs.

Each line is one panel's :class:`~meshlap_app.panel_spec.PanelSpec`, declared in its
polyscope-free module ``app/state/<name>.py`` (its code is ``app/panels/<name>.py``, loaded
only when a window or a render starts). The viewer, the session file, the command-line flags,
the animator, the recorder, the export and the help all loop over this tuple and never name a
panel. Views (``view=True``) are in the *view* combo and on the number keys in this order;
sections are drawn on every frame (the mesh, export and help sections).

Adding a panel: its two files, its test file, and one line here.

The import is polyscope-free: ``meshlap view --help`` reads the views and flags from here.
"""

from __future__ import annotations

from .panel_spec import PanelSpec
from .state import (
    check,
    curvature,
    curvature_lab,
    deform,
    diffusion,
    export,
    flatten,
    help,
    mesh_info,
    onering,
    smoothing,
    spectral,
    surfaces,
)

REGISTRY: tuple[PanelSpec, ...] = (
    mesh_info.SPEC,
    curvature.SPEC,
    onering.SPEC,
    spectral.SPEC,
    smoothing.SPEC,
    surfaces.SPEC,
    check.SPEC,
    diffusion.SPEC,
    curvature_lab.SPEC,
    deform.SPEC,
    flatten.SPEC,
    export.SPEC,
    help.SPEC,
)

VIEWS: tuple[str, ...] = tuple(s.name for s in REGISTRY if s.view)
"""The views of the *view* combo, in its order (keys 1, 2, ...); the first is the default."""

VIEW_KEYS: tuple[str, ...] = tuple("1234567890")[: len(VIEWS)]
"""The number key of each of the first ten views (the tenth: 0); a later view is chosen in the
*view* combo only."""


def _check_registry() -> None:
    """Distinct names; every flag of a command declared once (a second ``--vertex`` would
    silently shadow the first)."""
    names = [s.name for s in REGISTRY]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"panels registered twice: {', '.join(twice)}")
    if not VIEWS:
        raise ValueError("the registry has no view")
    for command in ("view", "animate"):
        owner: dict[str, str] = {}
        for spec in REGISTRY:
            flags = [f.name for _, f in spec.flags(command)]  # type: ignore[arg-type]
            if command == "animate" and spec.animation is not None:
                flags += [o.flag for o in spec.animation.options]
            for flag in flags:
                if owner.get(flag, spec.name) != spec.name:
                    raise ValueError(
                        f"meshlap {command} {flag} is declared by {owner[flag]} and {spec.name}"
                    )
                owner[flag] = spec.name


_check_registry()


def animated() -> dict[str, PanelSpec]:
    """The animatable panels' specs (``meshlap animate --panel``), in the registry's order."""
    return {s.name: s for s in REGISTRY if s.animation is not None}
