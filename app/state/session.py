"""Saved sessions: the viewer's settings as a versioned JSON file (no polyscope import).

A session file is one JSON object::

    {"format": "meshlap-session", "version": 1, "meshlap": "0.1.0",
     "mesh": "bumpy.obj", "panel": "smoothing", "ui_scale": 1.0, "camera": {...},
     "curvature": {"field": "cotan", "area": "barycentric", "boundary": "pi", "clip": 2.0,
                   "side_by_side": false, "second_field": "uniform"},
     "onering": {"vertex": -1, "reverse": false},
     "spectral": {"computed": false, "k_request": 100, "k": 10, "mode": 1, "play": "modes"},
     "smoothing": {"method": "implicit", "laplacian": "uniform", "lam": 0.5,
                   "noise_alpha": 0.0, "seed": 0, "iterations": 15,
                   "lam_steps": [[0.5, 10], [2.0, 5]]},
     "surfaces": {"surface": "helicoid", "res": 48, "u": 0.0, "v": 0.0, "theta": 30.0}}

``camera`` is polyscope's ``get_view_as_json()`` parsed (or ``null``). A relative ``mesh`` is
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

**Keys added after the first files** (:data:`ADDED_KEYS`): ``smoothing.lam_steps``,
``spectral.play`` (what the Spectral panel's *play* plays: ``k sweep`` or ``modes``) and
``surfaces.theta`` (the normal section's θ in degrees). Each is written only when it differs
from its default, and a missing one takes its default.

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
import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from meshlap_core import __version__
from meshlap_core.errors import MeshError
from meshlap_core.io import atomic_write, check_output_path
from meshlap_core.options import AREA_KINDS, BOUNDARY_RULES, LAPLACIAN_KINDS
from meshlap_core.surfaces import SURFACES

from .names import FIELDS, PANELS, PLAY_KINDS
from .surface import MAX_RES

FORMAT = "meshlap-session"
VERSION = 1
"""The session format this meshlap writes and the newest it reads."""

Check = Callable[[Any], str | None]  # returns what is wrong with a value, or None


def _one_of(choices: tuple[str, ...]) -> Check:
    def check(x: Any) -> str | None:
        if not isinstance(x, str):
            return f"must be a string, got {type(x).__name__}"
        return None if x in choices else f"must be one of {', '.join(choices)}, got {x!r}"

    return check


def _boolean(x: Any) -> str | None:
    return None if isinstance(x, bool) else f"must be true or false, got {json.dumps(x)}"


def _integer(lo: int, hi: int | None = None) -> Check:
    def check(x: Any) -> str | None:
        if not isinstance(x, int) or isinstance(x, bool):
            return f"must be an integer, got {json.dumps(x)}"
        if x < lo or (hi is not None and x > hi):
            top = f" and <= {hi}" if hi is not None else ""
            return f"must be >= {lo}{top}, got {x}"
        return None

    return check


def _number(lo: float = -math.inf, hi: float = math.inf, positive: bool = False) -> Check:
    def check(x: Any) -> str | None:
        if not isinstance(x, int | float) or isinstance(x, bool) or not math.isfinite(x):
            return f"must be a finite number, got {json.dumps(x)}"
        if positive and not x > 0:
            return f"must be > 0, got {x}"
        if not lo <= x <= hi:
            return f"must be between {lo:g} and {hi:g}, got {x}"
        return None

    return check


def _lam_steps(x: Any) -> str | None:
    """What is wrong with a ``lam_steps`` value (``null`` or a list of ``[λ > 0, count >= 1]``);
    the counts' sum is checked against ``iterations`` by :func:`_check_lam_steps`."""
    if x is None:
        return None
    if not isinstance(x, list):
        return f"must be a list of [lam, steps] pairs or null, got {json.dumps(x)}"
    positive = _number(positive=True)
    for k, run in enumerate(x):
        if not isinstance(run, list) or len(run) != 2:
            return f"entry {k} must be a [lam, steps] pair, got {json.dumps(run)}"
        problem = positive(run[0])
        if problem:
            return f"entry {k}: lam {problem}"
        problem = _integer(1)(run[1])
        if problem:
            return f"entry {k}: steps {problem}"
    return None


# section -> key -> (default, check). The defaults are the viewer's own start values.
SCHEMA: dict[str, dict[str, tuple[Any, Check]]] = {
    "curvature": {
        "field": ("cotan", _one_of(FIELDS)),
        "area": ("barycentric", _one_of(AREA_KINDS)),
        "boundary": ("pi", _one_of(BOUNDARY_RULES)),
        "clip": (2.0, _number(0.0, 49.0)),
        "side_by_side": (False, _boolean),
        "second_field": ("uniform", _one_of(FIELDS)),
    },
    "onering": {"vertex": (-1, _integer(-1)), "reverse": (False, _boolean)},
    "spectral": {
        "computed": (False, _boolean),
        "k_request": (100, _integer(2)),
        "k": (10, _integer(1)),
        "mode": (1, _integer(0)),
        "play": ("k sweep", _one_of(PLAY_KINDS)),
    },
    "smoothing": {
        "method": ("implicit", _one_of(("explicit", "implicit", "taubin"))),
        "laplacian": ("uniform", _one_of(LAPLACIAN_KINDS)),
        "lam": (0.5, _number(positive=True)),
        "noise_alpha": (0.0, _number(0.0)),
        "seed": (0, _integer(0)),
        "iterations": (0, _integer(0, 100_000)),
        "lam_steps": (None, _lam_steps),
    },
    "surfaces": {
        "surface": ("helicoid", _one_of(tuple(SURFACES))),
        "res": (48, _integer(1, MAX_RES)),
        "u": (0.0, _number()),
        "v": (0.0, _number()),
        "theta": (0.0, _number()),
    },
}
ADDED_KEYS = (("smoothing", "lam_steps"), ("spectral", "play"), ("surfaces", "theta"))
"""Keys newer than the first session files: written only when they differ from the default."""
TOP_LEVEL = ("format", "version", "meshlap", "mesh", "panel", "ui_scale", "camera", *SCHEMA)


def default_settings() -> dict[str, dict[str, Any]]:
    """Every section's settings at the viewer's defaults."""
    return {sec: {k: d for k, (d, _) in keys.items()} for sec, keys in SCHEMA.items()}


@dataclass
class Session:
    """What a session file holds, validated.

    ``mesh`` is an absolute path (``None``: the bundled default mesh); ``settings`` maps each
    section of :data:`SCHEMA` to its values; ``camera`` is polyscope's view JSON as a dict.
    """

    mesh: Path | None = None
    panel: str = "curvature"
    ui_scale: float = 1.0
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
            "camera": copy.deepcopy(self.camera),
            **_without_default_added_keys(copy.deepcopy(self.settings)),
        }


def _without_default_added_keys(settings: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """``settings`` without the :data:`ADDED_KEYS` that hold their default (older readers
    refuse unknown keys: a file that does not need them stays readable there)."""
    for sec, key in ADDED_KEYS:
        if sec in settings and settings[sec].get(key, SCHEMA[sec][key][0]) == SCHEMA[sec][key][0]:
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
    unknown = sorted(set(data) - set(TOP_LEVEL))
    if unknown:
        raise MeshError(f"unknown key(s) {', '.join(map(repr, unknown))}", source)
    session = Session(mesh=_mesh_path(data.get("mesh"), source, folder))
    session.panel = _checked(data, "panel", "curvature", _one_of(PANELS), source)
    session.ui_scale = float(_checked(data, "ui_scale", 1.0, _number(0.5, 3.0), source))
    camera = data.get("camera")
    if camera is not None and not isinstance(camera, dict):
        raise MeshError(f'"camera" must be an object or null, got {json.dumps(camera)}', source)
    session.camera = camera
    for sec, keys in SCHEMA.items():
        values = data.get(sec, {})
        if not isinstance(values, dict):
            raise MeshError(f'"{sec}" must be an object, got {json.dumps(values)}', source)
        unknown = sorted(set(values) - set(keys))
        if unknown:
            raise MeshError(f"unknown key(s) in {sec!r}: {', '.join(map(repr, unknown))}", source)
        for key, (default, check) in keys.items():
            session.settings[sec][key] = _checked(values, key, default, check, source, sec)
    _check_lam_steps(session.settings["smoothing"], source)
    return session


def _check_lam_steps(sm: dict[str, Any], source: Any) -> None:
    """Check that ``lam_steps`` counts ``iterations`` steps; λ as floats, counts as ints."""
    runs = sm["lam_steps"]
    if runs is None:
        return
    total = sum(int(n) for _, n in runs)
    if total != sm["iterations"]:
        raise MeshError(
            f'"smoothing.lam_steps" counts {total} steps but "smoothing.iterations" is '
            f"{sm['iterations']}",
            source,
        )
    sm["lam_steps"] = [[float(lam), int(n)] for lam, n in runs]


def encode_lam_steps(runs: list[list[Any]], lam: float) -> list[list[Any]] | None:
    """``lam_steps`` to save for a run of ``runs`` (``[[λ, steps], ...]``) with ``lam`` set
    now: ``None`` when it says nothing that ``lam`` and ``iterations`` do not (no step, or every
    step at ``lam``), else a copy of ``runs``."""
    if not runs or (len(runs) == 1 and runs[0][0] == lam):
        return None
    return [[float(x), int(n)] for x, n in runs]


def replay_steps(sm: dict[str, Any]) -> list[list[Any]]:
    """The runs ``[[λ, steps], ...]`` that reproduce a saved ``smoothing`` section: its
    ``lam_steps``, or (missing, as in older files) ``iterations`` steps at ``lam``."""
    if sm.get("lam_steps") is not None:
        return [[float(x), int(n)] for x, n in sm["lam_steps"]]
    return [[float(sm["lam"]), int(sm["iterations"])]] if sm["iterations"] else []


def _checked(
    values: dict[str, Any], key: str, default: Any, check: Check, source: Any, sec: str = ""
) -> Any:
    value = values.get(key, default)
    problem = check(value)
    if problem:
        raise MeshError(f'"{sec + "." if sec else ""}{key}" {problem}', source)
    return float(value) if isinstance(default, float) else value


def _mesh_path(mesh: Any, source: str | os.PathLike, folder: Path | None) -> Path | None:
    if mesh is None:
        return None
    if not isinstance(mesh, str) or not mesh.strip():
        raise MeshError(f'"mesh" must be a file name or null, got {json.dumps(mesh)}', source)
    path = Path(mesh).expanduser()
    if not path.is_absolute() and folder is not None:
        path = folder / path
    if not path.is_file():
        raise MeshError(f"the mesh {mesh!r} does not exist (looked for {path})", source)
    return path.resolve()


def check_vertex(session: Session, n_vertices: int, source: str | os.PathLike) -> None:
    """Refuse a one-ring vertex that the session's mesh does not have.

    Raises
    ------
    MeshError
        ``onering.vertex >= n_vertices`` (named with the mesh's vertex count).
    """
    vertex = session.settings["onering"]["vertex"]
    if vertex >= n_vertices:
        raise MeshError(
            f'"onering.vertex" {vertex} is out of range (the mesh has {n_vertices} vertices)',
            source,
        )


def read_session(path: str | os.PathLike) -> Session:
    """Read and validate a session file.

    Raises
    ------
    MeshError
        The file cannot be read, is not JSON (line and column given), or :func:`from_dict`
        refuses it; the message starts with the file name.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise MeshError("not a session file (not UTF-8 text)", path) from None
    except OSError as exc:
        raise MeshError(f"cannot read the session: {exc.strerror or exc}", path) from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise MeshError(
            f"not JSON ({exc.msg} at line {exc.lineno}, column {exc.colno})", path
        ) from None
    return from_dict(data, path, path.resolve().parent)


def write_session(path: str | os.PathLike, session: Session) -> Path:
    """Write ``session`` to ``path`` atomically (indented JSON). Returns the resolved path.

    Raises
    ------
    MeshError
        The folder does not exist, the path is a directory, does not end in ``.json``, or is
        the session's mesh; or a value that :func:`from_dict` would refuse.
    """
    inputs = [session.mesh] if session.mesh is not None else []
    target = check_output_path(path, overwrite_inputs=inputs, suffixes=(".json",)).resolve()
    from_dict(session.to_dict(), target)  # write only what reads back (no NaN, no bad value)
    text = json.dumps(session.to_dict(target.parent), indent=2, allow_nan=False)
    with atomic_write(target, overwrite_inputs=inputs) as f:
        f.write(text + "\n")
    return target
