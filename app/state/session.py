"""Saved sessions: the viewer's settings as a versioned JSON file (no polyscope import).

A session file is one JSON object::

    {"format": "meshlap-session", "version": 1, "meshlap": "0.1.0",
     "mesh": "bumpy.obj", "panel": "smoothing", "ui_scale": 1.0, "camera": {...},
     "curvature": {"field": "cotan", "area": "voronoi", "boundary": "pi", "clip": 2.0,
                   "side_by_side": false, "second_field": "uniform"},
     "onering": {"vertex": -1, "reverse": false},
     "spectral": {"computed": false, "k_request": 100, "k": 10, "mode": 1, "play": "modes"},
     "smoothing": {"method": "implicit", "laplacian": "uniform", "lam": 0.5,
                   "noise_alpha": 0.0, "seed": 0, "iterations": 15,
                   "lam_steps": [[0.5, 10], [2.0, 5]]},
     "surfaces": {"surface": "helicoid", "res": 48, "u": 0.0, "v": 0.0, "theta": 30.0}}

Each section after ``camera`` is one registered panel's settings (:mod:`meshlap_app.registry`):
its keys, defaults and checks are the panel's spec's settings schema
(:class:`~meshlap_app.state.settings.Settings`, declared once in ``app/state/<panel>.py``;
:func:`schema` collects them), so a new panel brings its own section. A value refused is named
``section.key`` (a wrong type, a value out of range, NaN, an integer too large for a float).
``camera`` is polyscope's ``get_view_as_json()`` parsed (or ``null``), checked like every other
section (:func:`.camera.check_camera`: its keys, window size, projection, ``fov``,
``viewMat``). The file is read through :func:`meshlap_core.io.reader.read_json` (a regular file
of at most 16 MiB) and the mesh checked with ``check_input``. A relative ``mesh`` is
resolved against the session file's folder; ``null`` means the bundled default mesh. Missing
keys take the defaults below; unknown keys, wrong types, values out of range, a newer
``version`` or a missing mesh are a :class:`MeshError` naming the file and the problem.

**The λ of every smoothing step.** ``smoothing.lam_steps`` lists the λ the run used, run-length
encoded: ``[[0.5, 10], [2.0, 5]]`` is 10 steps at λ = 0.5, then 5 at 2.0 (the viewer's λ field
changes λ and keeps the mesh; only λ can change during a run: a new method, Laplacian, noise or
seed rebuilds the stepper and starts again at iteration 0). The counts sum to ``iterations``;
``lam`` is the λ set now (the next step's, which may differ from the last run's). Loading
replays the runs exactly (bit for bit). The key is written only when it says something that
``lam`` and ``iterations`` do not (λ changed during the run); missing or ``null``, the run is
``iterations`` steps at ``lam``, as version-1 files have always been read.

**Keys added after the first files** (settings declared ``added``, :func:`added_keys`):
``smoothing.lam_steps``, ``spectral.play`` (what the Spectral panel's *play* plays: ``k sweep``
or ``modes``) and ``surfaces.theta`` (the normal section's θ in degrees). Each is written only
when it differs from its default, and a missing one takes its default. The top-level ``up``
(the mesh's axis shown up, ``meshlap view --up``) is written only when it is not the mesh's
rule (:data:`.display.UP_BY_MESH`, else ``"y"``), which a missing ``up`` means.

**Why the version stays 1.** A file is bumped only when an older reader would *misread* it. A
reader of this version refuses every unknown key (``unknown key(s) in 'smoothing'``), so an
older meshlap given a file with an added key refuses it instead of replaying it with the wrong
λ; and a file without them means exactly what it meant before, so older meshlaps keep opening
it. A bump to 2 would make every new file unreadable to them for no gain.

This module only maps a :class:`Session` to and from a dict and a file; the viewer
(:mod:`meshlap_app.session`) captures one from its panels and applies one to them.
"""

from __future__ import annotations

import copy
import functools
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from meshlap_core import __version__
from meshlap_core.errors import MeshError
from meshlap_core.io import atomic_write, check_output_path
from meshlap_core.io.reader import check_input, read_json
from meshlap_core.options import UP_AXES

from ..registry import REGISTRY, VIEWS
from .camera import check_camera
from .mesh import MeshState
from .settings import Choice, Number, Setting, Settings

FORMAT = "meshlap-session"
VERSION = 1
"""The session format this meshlap writes and the newest it reads."""


@functools.cache
def schema() -> dict[str, Settings]:
    """Section -> its settings: each registered panel with settings (its spec's
    ``settings``), in the registry's order. The defaults are the viewer's own start values."""
    return {spec.name: spec.settings for spec in REGISTRY if len(spec.settings)}


@functools.cache
def added_keys() -> tuple[tuple[str, str], ...]:
    """Keys newer than the first session files (settings declared ``added``): written only
    when they differ from the default."""
    return tuple((sec, key) for sec, settings in schema().items() for key in settings.added())


def top_level() -> tuple[str, ...]:
    """The keys a session object may have."""
    return ("format", "version", "meshlap", "mesh", "panel", "ui_scale", "up", "camera", *schema())


def default_settings() -> dict[str, dict[str, Any]]:
    """Every section's settings at the viewer's defaults."""
    return {sec: settings.defaults() for sec, settings in schema().items()}


TOP_LEVEL = (
    Choice("panel", VIEWS[0], choices=VIEWS, widget="none"),
    Number("ui_scale", 1.0, lo=0.5, hi=3.0, widget="none"),
    Choice("up", UP_AXES[0], choices=UP_AXES, widget="none"),
)
"""The top-level settings of a session (``up``: also ``null``, the mesh's rule)."""


@dataclass
class Session:
    """What a session file holds, validated.

    ``mesh`` is an absolute path (``None``: the bundled default mesh); ``settings`` maps each
    section of :func:`schema` to its values; ``camera`` is polyscope's view JSON as a dict.
    """

    mesh: Path | None = None
    panel: str = VIEWS[0]
    ui_scale: float = 1.0
    up: str | None = None  # the mesh's up axis when not its rule's (UP_BY_MESH, else y)
    camera: dict[str, Any] | None = None
    settings: dict[str, dict[str, Any]] = field(default_factory=default_settings)

    def to_dict(self, folder: Path | None = None) -> dict[str, Any]:
        """The JSON object of this session; the mesh path is written relative to ``folder``
        when the mesh lies inside it (so a folder of session + mesh can be moved)."""
        mesh: str | None = None
        if self.mesh is not None:
            mesh = str(self.mesh)
            if folder is not None:
                try:
                    mesh = Path(self.mesh).resolve().relative_to(folder.resolve()).as_posix()
                except ValueError:
                    pass  # outside the folder: keep the absolute path
        return {
            "format": FORMAT,
            "version": VERSION,
            "meshlap": __version__,
            "mesh": mesh,
            "panel": self.panel,
            "ui_scale": self.ui_scale,
            **({"up": self.up} if self.up is not None else {}),  # added: written when set
            "camera": copy.deepcopy(self.camera),
            **_without_default_added_keys(copy.deepcopy(self.settings)),
        }


def _without_default_added_keys(settings: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """``settings`` without the :func:`added_keys` that hold their default (older readers
    refuse unknown keys: a file that does not need them stays readable there)."""
    sections = schema()
    for sec, key in added_keys():
        default = sections[sec].default(key)
        if sec in settings and settings[sec].get(key, default) == default:
            settings[sec].pop(key, None)
    return settings


def from_dict(
    data: Any, source: str | os.PathLike = "session", folder: Path | None = None
) -> Session:
    """Validate a session object and return the :class:`Session`.

    Parameters
    ----------
    data : object
        The parsed JSON.
    source : str or PathLike
        Named in every error (the session file).
    folder : Path, optional
        A relative mesh path is resolved against it (the session file's folder).

    Raises
    ------
    MeshError
        Not an object, another format, a newer version, an unknown key, a wrong type or value
        (named as ``section.key``), or a mesh file that does not exist.
    """
    if not isinstance(data, dict):
        raise MeshError(f"a session must be a JSON object, got {type(data).__name__}", source)
    if data.get("format") != FORMAT:
        raise MeshError(f'not a meshlap session ("format" must be "{FORMAT}")', source)
    version = data.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise MeshError(f'"version" must be an integer >= 1, got {json.dumps(version)}', source)
    if version > VERSION:
        raise MeshError(
            f"written by a newer meshlap ({data.get('meshlap', '?')}, session version {version}); "
            f"this meshlap {__version__} reads session version {VERSION}: update meshlap",
            source,
        )
    unknown = sorted(set(data) - set(top_level()))
    if unknown:
        raise MeshError(f"unknown key(s) {', '.join(map(repr, unknown))}", source)
    session = Session(mesh=_mesh_path(data.get("mesh"), source, folder))
    panel, ui_scale, up = TOP_LEVEL
    session.panel = _checked(data, panel, source)
    session.ui_scale = _checked(data, ui_scale, source)
    session.up = None if data.get("up") is None else _checked(data, up, source)
    session.camera = check_camera(data.get("camera"), source)
    specs = {spec.name: spec for spec in REGISTRY}
    for sec in schema():  # each key, then across the keys (e.g. a run's step counts)
        session.settings[sec] = specs[sec].check_values(data.get(sec, {}), source)
    return session


def _checked(data: dict[str, Any], setting: Setting, source: Any) -> Any:
    """A top-level value (its default when missing), or a MeshError naming it."""
    value = data.get(setting.key, setting.default)
    problem = setting.problem(value)
    if problem:
        raise MeshError(f'"{setting.key}" {problem}', source)
    return setting.coerce(value)


def _mesh_path(mesh: Any, source: str | os.PathLike, folder: Path | None) -> Path | None:
    if mesh is None:
        return None
    if not isinstance(mesh, str) or not mesh.strip():
        raise MeshError(f'"mesh" must be a file name or null, got {json.dumps(mesh)}', source)
    path = Path(mesh).expanduser()
    if not path.is_absolute() and folder is not None:
        path = folder / path
    if not os.path.lexists(path):
        raise MeshError(f"the mesh {mesh!r} does not exist (looked for {path})", source)
    try:  # a directory, a device or a FIFO is named as such, never "does not exist"
        check_input(path, what="mesh file")
    except MeshError as exc:
        raise MeshError(f"the mesh {mesh!r} ({path}): {exc.problem}", source) from None
    return path.resolve()


def check_session_mesh(session: Session, mesh: MeshState, source: str | os.PathLike) -> None:
    """Refuse a session whose settings do not fit its mesh (each spec's ``check_mesh``, e.g.
    a one-ring vertex the mesh does not have).

    Raises
    ------
    MeshError
        Naming the setting and the mesh's size.
    """
    for spec in REGISTRY:
        if spec.check_mesh is not None and spec.name in session.settings:
            spec.check_mesh(session.settings[spec.name], mesh, source)


def read_session(path: str | os.PathLike) -> Session:
    """Read and validate a session file.

    Raises
    ------
    MeshError
        The file cannot be read, is not a regular file, is over the session size limit
        (16 MiB), is not UTF-8 or not JSON (line and column given), nests too deeply or holds
        an integer beyond Python's digit limit (:func:`meshlap_core.io.reader.read_json`), or
        :func:`from_dict` refuses it; the message starts with the file name.
    """
    path = Path(path)
    try:  # a missing, special or oversize file: said before a byte is read
        check_input(path, what="session file")
    except MeshError as exc:
        raise MeshError(f"cannot read the session: {exc.problem}", path) from None
    data = read_json(path, what="session file")  # size, UTF-8, JSON, depth, digits
    return from_dict(data, path, path.resolve().parent)


def write_session(path: str | os.PathLike, session: Session) -> Path:
    """Write ``session`` to ``path`` atomically (indented JSON). Returns the absolute path.

    Raises
    ------
    MeshError
        The folder does not exist, the path is a directory, does not end in ``.json``, or is
        the session's mesh; or a value that :func:`from_dict` would refuse.
    """
    inputs = [session.mesh] if session.mesh is not None else []
    # (absolute, not resolved: a link named as the session file is replaced, not followed)
    target = check_output_path(path, overwrite_inputs=inputs, suffixes=(".json",)).absolute()
    from_dict(session.to_dict(), target)  # write only what reads back (no NaN, no bad value)
    text = json.dumps(session.to_dict(target.parent), indent=2, allow_nan=False)
    with atomic_write(target, overwrite_inputs=inputs) as f:
        f.write(text + "\n")
    return target
