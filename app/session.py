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

from .state.mesh import MeshState
from .state.session import (
    Session,
    check_vertex,
    encode_lam_steps,
    read_session,
    replay_steps,
    write_session,
)

if TYPE_CHECKING:
    from .viewer import Viewer


def _finite_json(x: Any) -> bool:
    if isinstance(x, float):
        return math.isfinite(x)
    if isinstance(x, dict):
        return all(_finite_json(v) for v in x.values())
    if isinstance(x, list):
        return all(x_ is not None and _finite_json(x_) for x_ in x)
    return True


def camera_json() -> dict[str, Any] | None:
    """polyscope's current view as a dict, or ``None`` before the first frame (NaN matrix)."""
    camera = json.loads(ps.get_view_as_json())
    return camera if _finite_json(camera) else None


def capture(viewer: Viewer) -> Session:
    """The viewer's current settings, panel, UI scale and camera."""
    curv, cpanel = viewer.curv, viewer.panels["curvature"]
    spec = viewer.panels["spectral"].state
    sm = viewer.panels["smoothing"].state
    surf = viewer.surf
    s = Session(
        mesh=viewer.mesh.path,
        panel=viewer.panel,
        ui_scale=float(viewer.panels["help"].ui_scale),
        camera=camera_json(),
    )
    s.settings["curvature"].update(
        field=curv.field_name,
        area=curv.area,
        boundary=curv.boundary,
        clip=float(curv.percentile),
        side_by_side=bool(cpanel.side_by_side),
        second_field=cpanel.second_field,
    )
    s.settings["onering"].update(vertex=int(viewer.ring.vertex), reverse=bool(viewer.ring.reverse))
    computed = spec.basis is not None
    s.settings["spectral"].update(
        computed=computed,
        k_request=int(spec.basis.k_max if computed else spec.k_request),
        k=int(spec.k),
        mode=int(spec.mode),
        play=spec.play_what,
    )
    s.settings["smoothing"].update(
        method=sm.method,
        laplacian=sm.laplacian,
        lam=float(sm.lam),
        noise_alpha=float(sm.noise_alpha),
        seed=int(sm.seed),
        iterations=int(sm.smoother.iteration) if sm.smoother is not None else 0,
        lam_steps=encode_lam_steps(sm.lam_steps, sm.lam) if sm.smoother is not None else None,
    )
    s.settings["surfaces"].update(
        surface=surf.name, res=int(surf.res), u=surf.u, v=surf.v, theta=float(surf.section_deg)
    )
    return s


def save(viewer: Viewer, path: str | Path) -> Path:
    """Write the viewer's session to ``path`` (atomically). Returns the resolved path.

    Raises
    ------
    MeshError
        A bad output path, or a mesh that has no file (nothing to reopen).
    """
    session = capture(viewer)
    if session.mesh is None and viewer.mesh.name != "bumpy (generated)":
        raise MeshError("the mesh on screen has no file to reopen", "save session")
    return write_session(path, session)


def load(viewer: Viewer, path: str | Path, resize: bool = False) -> Session:
    """Read ``path`` and apply it to the viewer (an open window keeps its size unless
    ``resize``); on any error nothing changes.

    Raises
    ------
    MeshError
        The file is refused (:func:`~.state.session.read_session`), its mesh cannot be loaded,
        or its one-ring vertex does not exist on that mesh.
    """
    session = read_session(path)
    apply(viewer, session, Path(path), resize)
    return session


def apply(
    viewer: Viewer,
    session: Session,
    source: str | Path = "session",
    resize: bool = True,
    mesh: MeshState | None = None,
) -> None:
    """Restore ``session`` in ``viewer``: mesh, settings, replayed smoothing, basis, camera.

    Everything that can fail (the mesh file, the vertex index, an eigen computation still
    running) is checked before the viewer changes, so a refused session leaves the window as
    it was. ``resize``: take the window size saved with the camera (headless renders and a
    window being opened); ``False`` keeps the size of an open window. ``mesh``: the session's
    mesh already loaded (``meshlap view --session`` loads it before the window opens).

    Long because it restores every panel in the order their dependencies need (mesh, then the
    fields, one-ring, surfaces, basis and smoothing run, then the panel and the camera).
    """
    st = session.settings
    if viewer.panels["spectral"].state.busy:
        raise MeshError(
            "the eigenbasis is still being computed; load the session when it is done", source
        )
    if mesh is None:
        mesh = MeshState()
        if not mesh.load(session.mesh):
            raise MeshError(f"cannot open its mesh: {mesh.error}", source)
    check_vertex(session, len(mesh.V), source)
    vertex = st["onering"]["vertex"]
    old = viewer.mesh
    if mesh is not old:  # the new mesh goes into the viewer's MeshState (bumped version)
        for name in ("V", "F", "name", "info", "path"):
            setattr(old, name, getattr(mesh, name))
        old.error = ""
        old.version += 1
    if old.path is not None:
        viewer.panels["mesh"].remember(old.path)
    viewer.panels["help"].set_scale(viewer, session.ui_scale)
    c = st["curvature"]
    curv, cpanel = viewer.curv, viewer.panels["curvature"]
    curv.field_name, curv.area, curv.boundary = c["field"], c["area"], c["boundary"]
    curv.set_percentile(c["clip"])
    cpanel.side_by_side, cpanel.second_field = c["side_by_side"], c["second_field"]
    viewer.ring.reverse = st["onering"]["reverse"]
    viewer.sync_mesh()  # registers the mesh and the fields (the ring is reset per mesh)
    viewer.ring.reverse = st["onering"]["reverse"]
    if vertex >= 0:
        viewer.select_vertex(vertex)
    sf = st["surfaces"]
    if viewer.surf.set_surface(sf["surface"], sf["res"]):
        viewer.surf.set_uv(sf["u"], sf["v"])
    viewer.surf.set_section(sf["theta"])  # a finite number: checked when the file was read
    _apply_spectral(viewer, st["spectral"])
    _apply_smoothing(viewer, st["smoothing"], session.panel == "smoothing")
    viewer.set_panel(session.panel)
    viewer.frame()  # caption boxes and a sensible view when the file has no camera
    viewer.reframe = viewer.panels["smoothing"].new_copy = False  # keep the saved camera
    if session.camera is not None:
        camera = dict(session.camera)
        if not resize:  # an open window keeps its size; the view matrix is restored
            size = ps.get_window_size()
            camera["windowWidth"], camera["windowHeight"] = int(size[0]), int(size[1])
        ps.set_view_from_json(json.dumps(camera))
    viewer._window_size = tuple(ps.get_window_size())  # no re-frame for the (new) size


def _apply_spectral(viewer: Viewer, sp: dict[str, Any]) -> None:
    """What *play* plays; the basis (from the cache when it was computed before), mode, k."""
    panel = viewer.panels["spectral"]
    state = panel.state
    state.k_request = min(sp["k_request"], max(len(viewer.mesh.V), 2))
    state.k, state.mode = sp["k"], sp["mode"]
    state.set_play_what(sp["play"])
    if not sp["computed"]:
        return
    state.start(viewer.mesh.V, viewer.mesh.F, background=False)  # cache=True by default
    if state.basis is None:
        return  # the error is shown in the Spectral panel
    state.set_mode(sp["mode"])
    state.set_k(sp["k"])
    panel.push_mode(viewer, force=True)
    panel.push_k(viewer, force=True)


def _apply_smoothing(viewer: Viewer, sm: dict[str, Any], shown: bool) -> None:
    """Options; when the run had steps (or its panel is shown), rebuild and replay them, each
    run of steps with the λ it used (``lam_steps``), then set the saved ``lam``."""
    panel = viewer.panels["smoothing"]
    state = panel.state
    state.method, state.laplacian = sm["method"], sm["laplacian"]
    state.lam, state.noise_alpha, state.seed = sm["lam"], sm["noise_alpha"], sm["seed"]
    state.smoother, state.playing = None, False
    if not (shown or sm["iterations"]):
        return
    runs = replay_steps(sm)
    state.lam = runs[0][0] if runs else sm["lam"]  # the stepper is built with the first λ
    if not state.rebuild(viewer.mesh.V, viewer.mesh.F):
        state.lam = sm["lam"]  # (set_lam would clear the error the Smoothing panel shows)
        return
    for lam, steps in runs:
        state.set_lam(lam)
        if not all(state.step() for _ in range(steps)):
            break  # a diverging run stops where it stopped when it was saved
    state.set_lam(sm["lam"])
    panel.push(force=True)


class SessionWidgets:
    """The *session file* field and the *save session* / *load session* buttons (drawn in the
    Help and window section; a refused file is shown in red there and nothing changes)."""

    def __init__(self) -> None:
        self.text = ""  # the session file (relative: in the export folder)
        self.status = ""

    def draw(self, viewer: Viewer) -> None:
        ui = viewer.ui
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
            text = self.text.strip() or f"{Path(viewer.mesh.name).stem}.session.json"
            path = Path(text).expanduser()
            if not path.is_absolute():
                path = viewer.panels["export"].folder / path
            if save_it:
                self.text = str(save(viewer, path))
                self.status = f"saved {self.text}"
            else:
                load(viewer, path)
                self.status = f"loaded {path}"
        if self.status:
            ui.note(self.status)
