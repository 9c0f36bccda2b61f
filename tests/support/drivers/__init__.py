"""The drivers of the every-widget tour: ``drivers/<name>.py`` defines
``drive_panel_<name>(viewer, tmp_path)`` for the registered panel ``<name>``, driving every
widget it draws with good values and bad. ``tests/app/test_viewer_widgets.py`` runs them all on
one viewer and fails on a widget no driver drove, or on a setting the panel's spec declares whose
widget (its label, in the panel's section) no driver drove; a panel's own tests call its driver
too.

A new panel brings its driver in its own file here; the tour finds it by the panel's name, and
fails naming the panel when the file or its ``drive_panel_<name>`` is missing.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable


def panel_drivers() -> dict[str, Callable[..., None]]:
    """``drive_panel_<name>(viewer, tmp_path)`` of every registered panel, in the registry's
    order, from ``tests/support/drivers/<name>.py``. KeyError names a panel without one."""
    from meshlap_app.registry import REGISTRY

    drivers: dict[str, Callable[..., None]] = {}
    for spec in REGISTRY:
        name = f"drive_panel_{spec.name}"
        module_name = f"{__name__}.{spec.name}"
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name != module_name:
                raise
            where = f"tests/support/drivers/{spec.name}.py"
            raise KeyError(f"{spec.name}: no driver module {where}") from None
        if not hasattr(module, name):
            raise KeyError(f"{spec.name}: {name} is not defined in {module_name}")
        drivers[spec.name] = getattr(module, name)
    return drivers


def view_setups() -> dict[str, Callable[..., object]]:
    """``show_for_export(viewer, tmp_path)`` of every view, from its driver module: how the
    export test makes the view show its fields and copies (a generator yields once per state
    to export). KeyError names a view without one."""
    from meshlap_app.registry import VIEWS

    setups: dict[str, Callable[..., object]] = {}
    for name in VIEWS:
        module = importlib.import_module(f"{__name__}.{name}")
        if not hasattr(module, "show_for_export"):
            raise KeyError(f"{name}: show_for_export is not defined in {module.__name__}")
        setups[name] = module.show_for_export
    return setups
