"""Where the viewer keeps its own files: its config folder (no polyscope import).

The viewer writes nothing where the user did not ask. polyscope and Dear ImGui would keep
their UI layout in ``./imgui.ini`` and ``./.polyscope.ini`` (the current directory: a user's
own ``imgui.ini`` there was rewritten by ``meshlap view --screenshot``, ``view --session`` and
``animate``). meshlap turns their files off (:func:`meshlap_app.viewer.init_polyscope`) and
keeps the layout of the interactive window in its config folder instead:

- ``$XDG_CONFIG_HOME/meshlap/`` when ``XDG_CONFIG_HOME`` is set (an absolute path),
  else ``~/.config/meshlap/``;
- ``imgui.ini`` there (:func:`layout_file`): read when a window opens, written (atomically)
  when it closes. Headless renders (``--screenshot``, ``animate``, the report's pictures)
  neither read nor write it, so they look the same on every machine.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

from meshlap_core.errors import MeshError, MeshWarning
from meshlap_core.io import atomic_write
from meshlap_core.io.reader import read_input

LAYOUT_NAME = "imgui.ini"
LAYOUT_MAX_BYTES = 1 * 2**20
"""A layout file larger than this is ignored (ImGui's own files are a few KiB)."""


def config_dir() -> Path:
    """The viewer's config folder: ``$XDG_CONFIG_HOME/meshlap`` (when set and absolute, as
    the XDG specification asks), else ``~/.config/meshlap``. Not created here."""
    xdg = os.environ.get("XDG_CONFIG_HOME", "")
    base = Path(xdg) if xdg and os.path.isabs(xdg) else Path.home() / ".config"
    return base / "meshlap"


def layout_file() -> Path:
    """The interactive window's UI layout (Dear ImGui's ini text)."""
    return config_dir() / LAYOUT_NAME


def read_layout() -> str | None:
    """The saved layout text, or ``None`` when there is none or it cannot be read (a layout is
    a convenience: the window opens with the default one)."""
    path = layout_file()
    if not path.exists():
        return None
    try:
        return read_input(path, what="layout file", max_bytes=LAYOUT_MAX_BYTES).decode("utf-8")
    except (MeshError, UnicodeDecodeError):
        return None


def write_layout(text: str) -> Path | None:
    """Write the layout ``text`` to :func:`layout_file` atomically (creating the folder).

    Returns the path, or ``None`` after a :class:`MeshWarning` saying why it could not be
    written (a read-only home, a full disk): closing the window never fails for it.
    """
    path = layout_file()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(path) as f:
            f.write(text)
    except (OSError, MeshError) as exc:
        why = exc.problem if isinstance(exc, MeshError) else (exc.strerror or str(exc))
        warnings.warn(MeshWarning(f"the window layout was not kept in {path}: {why}"), stacklevel=2)
        return None
    return path
