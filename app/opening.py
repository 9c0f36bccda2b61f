"""Opening a mesh in the viewer: one job of the Mesh section, and the preview of a big scan.

In the window the file is read, validated and its curvature fields computed in a child
process (:func:`meshlap_app.jobs.in_child`; the previous mesh stays on screen meanwhile). As
soon as a big file is parsed, the job hands over a :class:`~.state.preview.MeshPreview` (its
geometry and a quick uniform-H field, :mod:`.state.preview`), which :func:`show_preview`
puts on screen in place of the mesh at once, on the UI thread, leaving the state untouched.
When the validated mesh arrives, :func:`keep_preview` keeps the structure registered for the
preview if validation left the geometry as parsed (no second registration and upload of
millions of triangles; the child sends the mesh back without that geometry, the window holds
it already), and the Curvature panel uploads the final colours. A job that fails or is
cancelled after its preview brings the previous mesh back (:func:`restore_mesh`).
:func:`opens_later` says when ``meshlap view FILE`` opens the window first and loads the
file that way.

Imports polyscope.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import polyscope as ps

from . import scene, window
from .jobs import Reporter
from .registry import REGISTRY
from .scene import MESH
from .state.preview import PREVIEW_LABEL, MeshPreview

ASYNC_OPEN_BYTES = 8 * 2**20
"""``meshlap view FILE`` with a larger file opens the window on the bundled mesh at once and
loads FILE as a job (progress and Cancel in the Mesh section); a smaller file is loaded before
the window opens (a bad one exits 2 as every command does)."""


def open_mesh(viewer: Any, path: Path | None) -> bool:
    """Load ``path`` into ``viewer`` (see :meth:`meshlap_app.viewer.Viewer.open`): a job of
    the Mesh section (``viewer.background``; True: started) or right here (True: loaded);
    a failure is kept in ``state.mesh.error`` and the mesh stays."""
    from .state.mesh import read_mesh_with_fields

    section = REGISTRY[0].name  # the first section: the mesh's
    state = viewer.state
    curv = state.curv
    settings = (curv.area, curv.boundary)
    read = state.jobs.offload(read_mesh_with_fields, path, *settings)  # a child process

    def work(reporter: Reporter) -> Any:
        loaded, fields = read(reporter)  # sent back without the geometry previewed
        return loaded.with_geometry(reporter.last_partial), fields

    def apply(result: Any) -> None:
        loaded, fields = result
        state.jobs.cancel_all()  # what other panels computed belongs to the old mesh
        state.mesh.adopt(loaded)
        if (curv.area, curv.boundary) == settings:
            curv.adopt(state.mesh, fields)
        viewer.sync_mesh()
        viewer.reframe = True

    def fail(message: str) -> None:
        state.mesh.error = message

    name = Path(path).name if path is not None else "the default mesh"
    viewer.opening = name  # the Mesh section says so while the job runs (Viewer.loading)
    job = state.jobs.start(
        section,
        f"opening {name}",
        work,
        apply,
        fail,
        background=viewer.background,
        preview=viewer.show_preview,
    )
    if job is None:  # start replaces a running job: never refused
        raise RuntimeError("the opening job was refused")
    return bool(viewer.background) or job.status == "done"


def load_now(state: Any, path: Path | None) -> bool:
    """Load ``path`` (the bundled default when ``None``) in this thread with its curvature
    fields (the window's first mesh, ``--screenshot``): computed here, before any structure
    is registered with polyscope, with the mesh's own edge table, the fields' temporaries
    (about 400 MB at 692k vertices) never sit on top of polyscope's buffers; what they freed
    goes back to the system (:func:`.heap.release_freed`). A failure is kept in
    ``state.mesh.error`` (False)."""
    from meshlap_core.errors import MeshError

    from .heap import release_freed
    from .state.mesh import read_mesh_with_fields

    curv = state.curv
    try:
        loaded, fields = read_mesh_with_fields(path, curv.area, curv.boundary)
    except MeshError as exc:
        state.mesh.error = str(exc)
        return False
    except OSError as exc:
        state.mesh.error = f"{path}: {exc.strerror or exc}"
        return False
    state.mesh.adopt(loaded)
    curv.adopt(state.mesh, fields)
    release_freed()
    return True


def fit_of(display: Any) -> tuple[Any, ...]:
    """What the display positions of a mesh depend on besides its vertices."""
    return (display.scale, *np.asarray(display.centre).tolist(), display.up)


def show_preview(viewer: Any, preview: MeshPreview) -> None:
    """Show a mesh being opened as parsed (the Mesh job's partial result) in place of the
    mesh, coloured by its preview field; the views' own structures are hidden meanwhile.
    The state is untouched: the validated mesh replaces it (:func:`keep_preview`), or a
    failed or cancelled job brings the mesh back (:func:`restore_mesh`)."""
    state = viewer.state
    display = copy.deepcopy(state.display)
    display.fit(preview.corners(), state.up_for(preview.name))  # the same fit as to V
    points = display.points(preview.V)
    viewer.no_shadow = scene.shadow_for(len(preview.F), viewer.no_shadow)
    scene.show_preview(
        points, preview.F, preview.field, preview.vminmax, PREVIEW_LABEL, state.ui_scale
    )
    viewer.preview, viewer.preview_fit = preview, fit_of(display)
    section = viewer.panels[REGISTRY[0].name]  # no view: each hides its structures
    for p in viewer.panels.values():
        p.show(viewer, section)
    window.set_title(window.window_title(preview.name, True))


def keep_preview(viewer: Any, mesh: Any) -> bool:
    """The structure registered for the preview already shows ``mesh`` (validation left the
    geometry as parsed; the display fitted to it already): keep it, without its preview
    colours. True when kept; the preview is forgotten either way."""
    preview, viewer.preview = viewer.preview, None
    if preview is None or not ps.has_surface_mesh(MESH) or preview.name != mesh.name:
        return False
    if viewer.preview_fit != fit_of(viewer.state.display):
        return False
    if not preview.same_geometry(mesh.V, mesh.F):
        return False
    ps.get_surface_mesh(MESH).remove_quantity(PREVIEW_LABEL)
    return True


def restore_mesh(viewer: Any) -> None:
    """Show the current mesh again after a preview whose job failed or was cancelled:
    registered anew, every panel's uploads redone from its unchanged state."""
    viewer.preview = None
    mesh = viewer.state.mesh
    viewer.no_shadow = scene.shadow_for(len(mesh.F), viewer.no_shadow)
    scene.remove_structure(MESH)
    ps.register_surface_mesh(MESH, viewer.mesh_points(), mesh.F, smooth_shade=True)
    for p in viewer.panels.values():
        p.watch.forget()
    window.set_title(window.window_title(mesh.name, True))
    viewer.refresh()
    viewer.reframe = True


def opens_later(path: Path | None, shot: Path | None, saved: Any, options: dict[str, Any]) -> bool:
    """Whether ``meshlap view`` opens the window first and loads ``path`` as a job: a window
    (no screenshot, no session, no option that needs the mesh) and a file larger than
    :data:`ASYNC_OPEN_BYTES`."""
    if path is None or shot is not None or saved is not None:
        return False
    if any(v is not None for v in options.values()):
        return False
    try:
        return path.stat().st_size > ASYNC_OPEN_BYTES
    except OSError:
        return False  # said by the load, before the window
