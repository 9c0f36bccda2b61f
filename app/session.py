"""Capture the viewer's settings and camera as a :class:`~.state.session.Session`, and apply one.

The mapping to and from JSON lives in :mod:`.state.session` (no polyscope); this module reads
the panels' state objects and polyscope's camera, and restores them: the mesh is loaded, every
panel's settings set, smoothing replayed to the saved iteration (same seed, same noise, same
result), the eigenbasis taken from the cache, and the camera set last.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.options import DEFAULT_UP

from .state.camera import captured
from .state.display import UP_BY_MESH
from .state.mesh import MeshState
from .state.session import Session, check_session_mesh, read_session, write_session

if TYPE_CHECKING:
    from .host import Host


def _finite_json(x: Any) -> bool:
    if isinstance(x, float):
        return math.isfinite(x)
    if isinstance(x, dict):
        return all(_finite_json(v) for v in x.values())
    if isinstance(x, list):
        return all(x_ is not None and _finite_json(x_) for x_ in x)
    return True


def camera_json() -> dict[str, Any] | None:
    """polyscope's current view as a dict, or ``None`` before the first frame (NaN matrix);
    only the keys a session keeps, the window size within the checked range
    (:func:`.state.camera.captured`), so that a saved session always reads back."""
    camera = json.loads(ps.get_view_as_json())
    return captured(camera) if _finite_json(camera) else None


def capture(host: Host) -> Session:
    """The host's current settings (each panel's section), view, UI scale and camera."""
    state = host.state
    up = state.up_for(state.mesh.name)  # written only when not the mesh's rule
    s = Session(
        mesh=state.mesh.path,
        panel=state.panel,
        ui_scale=float(state.ui_scale),
        up=None if up == UP_BY_MESH.get(state.mesh.name, DEFAULT_UP) else up,
        camera=camera_json(),
    )
    for name, p in host.panels.items():
        if name in s.settings:
            s.settings[name].update(p.capture(host))
    return s


def save(host: Host, path: str | Path) -> Path:
    """Write the host's session to ``path`` (atomically). Returns the resolved path.

    Raises
    ------
    MeshError
        A bad output path, or a mesh that has no file (nothing to reopen).
    """
    session = capture(host)
    if session.mesh is None and host.state.mesh.name != "bumpy (generated)":
        raise MeshError("the mesh on screen has no file to reopen", "save session")
    return write_session(path, session)


def load(host: Host, path: str | Path, resize: bool = False) -> Session:
    """Read ``path`` and apply it to the host (an open window keeps its size unless
    ``resize``); on any error nothing changes.

    Raises
    ------
    MeshError
        The file is refused (:func:`~.state.session.read_session`), its mesh cannot be loaded,
        or its one-ring vertex does not exist on that mesh.
    """
    session = read_session(path)
    apply(host, session, Path(path), resize)
    return session


def apply(
    host: Host,
    session: Session,
    source: str | Path = "session",
    resize: bool = True,
    mesh: MeshState | None = None,
) -> None:
    """Restore ``session`` in ``host``: mesh, every panel's settings, camera.

    Everything that can fail (the mesh file, settings that do not fit it, a background job
    still running) is checked before the host changes, so a refused session leaves the window
    as it was. ``resize``: take the window size saved with the camera (headless renders and a
    window being opened); ``False`` keeps the size of an open window. ``mesh``: the session's
    mesh already loaded (``meshlap view --session`` loads it before the window opens).

    Each panel restores its own section: ``configure`` before the mesh is registered (its
    settings), ``restore`` after (selection, basis, replayed smoothing run), in the registry's
    order; then the view and the camera.
    """
    running = [job for p in host.panels.values() if (job := p.busy())]
    running += [f"{job.title} is still running" for job in host.state.jobs.all_running()]
    if running:
        raise MeshError(f"{running[0]}; load the session when it is done", source)
    if mesh is None:
        mesh = MeshState()
        if not mesh.load(session.mesh):
            raise MeshError(f"cannot open its mesh: {mesh.error}", source)
    check_session_mesh(session, mesh, source)
    state = host.state
    state.mesh.show(mesh)  # the app's one MeshState takes it (its version moves on)
    if session.up is not None:  # the mesh's axis shown up (else the mesh's rule)
        state.up_given[mesh.name] = session.up
    else:
        state.up_given.pop(mesh.name, None)
    host.set_ui_scale(session.ui_scale)
    sections = session.settings
    for name, p in host.panels.items():
        if name in sections:
            p.configure(host, sections[name])
    state.panel = session.panel
    host.sync_mesh()  # registers the mesh, each panel forgets the previous one
    for name, p in host.panels.items():
        if name in sections:
            p.restore(host, sections[name], name == session.panel)
    host.set_panel(session.panel)
    host.frame()  # caption boxes and a sensible view when the file has no camera
    if session.camera is not None:
        camera = dict(session.camera)
        if not resize:  # an open window keeps its size; the view matrix is restored
            size = ps.get_window_size()
            camera["windowWidth"], camera["windowHeight"] = int(size[0]), int(size[1])
        ps.set_view_from_json(json.dumps(camera))
    host.keep_view()  # the saved camera stays: no re-frame, not even for the (new) size


class SessionWidgets:
    """The *session file* field and the *save session* / *load session* buttons (drawn in the
    Help and window section; a refused file is shown in red there and nothing changes)."""

    def __init__(self) -> None:
        self.text = ""  # the session file (relative: in the export folder)
        self.status = ""

    def draw(self, host: Host) -> None:
        ui = host.ui
        _, self.text = ui.input_text(
            "session file",
            self.text,
            "a .json file: mesh, every panel's settings, UI scale and camera "
            "(relative: in the export folder; empty: <mesh>.session.json there)",
        )
        save_it = ui.button("save session", "write the current view to the session file")
        ui.same_line()
        load_it = ui.button("load session", "restore the mesh, settings and camera of the file")
        if save_it or load_it:
            self.status = ""
            path = host.state.in_folder(self.text.strip() or f"{host.state.mesh.stem}.session.json")
            if save_it:
                self.text = str(save(host, path))
                self.status = f"saved {self.text}"
            else:
                load(host, path)
                self.status = f"loaded {path}"
        if self.status:
            ui.note(self.status)
