"""The protocol every panel's code follows (its hooks, with defaults).

A panel is declared by its spec (:class:`meshlap_app.panel_spec.PanelSpec`: name, title,
settings, checks, animation) and drawn by a subclass of :class:`Panel` named there. It owns one
feature end to end: its widgets (:meth:`Panel.draw`), the structures it registers (shown,
hidden, framed), the captions under them, what *export* writes, its slice of a saved session,
its shortcut keys and what *play* / *record* / ``meshlap animate`` advance. The viewer
(:mod:`meshlap_app.viewer`) and the headless animator (:mod:`meshlap_app.animate`) are *hosts*:
they loop over the registered specs (:mod:`meshlap_app.registry`) and never name a panel. A
panel never imports the viewer; it types against :class:`meshlap_app.host.Host`.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from ..host import Host
from ..state.isolines import IsolineFields, Isolines
from ..state.watch import Watch

if TYPE_CHECKING:
    from ..panel_spec import PanelSpec

ExportItem = tuple[str, "np.ndarray | None", "np.ndarray | None", "np.ndarray | None"]
"""(file name, V or ``None``, F or ``None``, per-vertex scalars or ``None``): a mesh (PLY with
the scalars) when V is given, else the scalars alone (CSV)."""


def shown_field(
    stem: str, V: np.ndarray, F: np.ndarray, field: np.ndarray | None
) -> list[ExportItem]:
    """A mesh on screen as *export* writes it: ``<stem>.ply`` (``V (n,3)``, ``F (m,3)`` in
    the mesh's own coordinates, the colour field ``field (n,)`` as its vertex ``quality``)
    and, with a field, the field alone as ``<stem>.csv``."""
    items: list[ExportItem] = [(f"{stem}.ply", V, F, field)]
    if field is not None:
        items.append((f"{stem}.csv", None, None, field))
    return items


@dataclass(frozen=True)
class Pick:
    """A click on the 3D view as a panel's :meth:`Panel.pick` sees it: what polyscope's pick
    found there, and the modifier keys held (every panel gets them; e.g. shift-click adds a
    source in the Diffusion view).

    Attributes
    ----------
    structure_name : str
        The structure hit (polyscope's name).
    structure_data : dict
        polyscope's per-structure data (``element_type``, ``index``, barycentric
        coordinates ...).
    position : tuple of 3 float
        The 3D point hit, in display coordinates (a tuple: picks compare by value).
    modifiers : frozenset of str
        The keys held during the click: a subset of ``{"shift", "ctrl", "alt"}``
        (:data:`meshlap_app.ui.MODIFIERS`).
    """

    structure_name: str
    structure_data: dict[str, Any] = field(default_factory=dict)
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    modifiers: frozenset[str] = frozenset()

    @classmethod
    def of(cls, hit: Any, modifiers: Iterable[str] = ()) -> Pick:
        """From polyscope's pick result ``hit`` and the keys held."""
        return cls(
            str(hit.structure_name),
            dict(getattr(hit, "structure_data", {}) or {}),
            tuple(float(x) for x in getattr(hit, "position", (0.0, 0.0, 0.0))),  # type: ignore[arg-type]
            frozenset(modifiers),
        )

    @property
    def shift(self) -> bool:
        """Shift was held."""
        return "shift" in self.modifiers


HOST_SHORTCUTS: tuple[tuple[str, str], ...] = (
    ("F", "frame what the view shows (the one-ring: the selected vertex's ring)"),
    ("R", "reset the camera to the whole subject (a view may use R for its own reset)"),
    ("mouse", "left-drag rotate, right-drag pan, wheel zoom; click a vertex for its one-ring"),
    ("drop", "drop a mesh file (or a session .json) on the window to open it"),
)
"""The keys and gestures every host answers itself (each panel lists its own ``shortcuts``)."""


class Panel:
    """Defaults for every hook of the protocol; a panel overrides what it does.

    It is made with its spec (``name`` and ``title`` come from there) and its state slice.
    Class attributes a panel sets:

    ``shows_mesh``
        The main mesh is visible while this view is active.
    ``shows_curvature``
        The main mesh shows the curvature field (with its colour bar) while this view is
        active.
    ``pick_through``
        A click on the mesh in this view may select a vertex for another panel (the
        curvature view hands its clicks to the one-ring).
    ``framed``
        Names of the surface meshes it registers that framing fits in view.
    ``shortcuts``
        ``(key, what it does)`` rows for the help window and the README.
    ``keys``
        The key names (:meth:`meshlap_app.ui.UI.key`) :meth:`on_key` is offered while this
        view is active (a section: always).
    ``view_direction``
        Where the camera looks from when it frames this view (``None``: the mesh's front).
    """

    shows_mesh: ClassVar[bool] = True
    shows_curvature: ClassVar[bool] = False
    pick_through: ClassVar[bool] = False
    framed: ClassVar[tuple[str, ...]] = ()
    shortcuts: ClassVar[tuple[tuple[str, str], ...]] = ()
    keys: ClassVar[tuple[str, ...]] = ()
    view_direction: ClassVar[tuple[float, float, float] | None] = None

    def __init__(self, spec: PanelSpec, state: Any = None) -> None:
        self.spec = spec
        self.name = spec.name
        self.title = spec.title  # its header
        self.state = state  # this panel's slice of the AppState (None: it has none)
        self.watch = Watch()  # what was uploaded, and from which inputs
        self.isolines = Isolines()  # isoline toggle and count of each scalar field it shows

    # -------------------------------------------------------------- every frame
    def draw(self, host: Host) -> None:
        """Its widgets (while its view is active, or always for a section)."""

    def sync(self, host: Host) -> None:
        """Bring what it uploaded up to date with the state (every frame, every panel: cheap
        when nothing changed, see :class:`~meshlap_app.state.watch.Watch`)."""

    def overlay(self, host: Host) -> None:
        """Text drawn over the 3D view while its view is active (labels, hover)."""

    # -------------------------------------------------------------- the scene
    def on_new_mesh(self, host: Host) -> None:
        """Forget what belonged to the previous mesh."""

    def show(self, host: Host, active: Panel) -> None:
        """Enable its structures when ``active`` is this panel, disable them otherwise."""

    def points(self, host: Host, name: str) -> np.ndarray | None:
        """Display positions of the structure ``name`` it registered (framing), or ``None``."""
        return None

    def focus(self, host: Host) -> bool:
        """Frame the camera its own way (True), or leave it to the host (False)."""
        return False

    def pick(self, host: Host, hit: Any, active: Panel) -> bool:
        """Handle a click on the 3D view (``hit``: a :class:`Pick`, polyscope's pick result
        with the modifier keys held); True if used."""
        return False

    def captions(self, host: Host) -> dict[str, str]:
        """Caption of each structure it shows side by side (its view active)."""
        return {}

    # -------------------------------------------------------------- files
    def export_items(self, host: Host) -> list[ExportItem]:
        """What *export what is shown* writes for this view: every mesh it shows (its
        ``framed`` copies and the main mesh when it ``shows_mesh``) with the field on it
        (:func:`shown_field`). ``[]``: the default export (the mesh with the curvature field
        when the view ``shows_curvature``, else the plain mesh)."""
        return []

    def capture(self, host: Host) -> dict[str, Any]:
        """Its settings for a saved session: its section, one value per key of its spec's
        ``settings``; by default each its state's attribute of the same name, and its
        isolines (:class:`~meshlap_app.state.isolines.IsolineFields`) from :attr:`isolines`
        (a panel whose state names them otherwise, or derives one, overrides this)."""
        out = {}
        for s in self.spec.settings:
            if isinstance(s, IsolineFields):
                out[s.key] = s.capture(self.isolines)
            else:
                out[s.key] = s.coerce(getattr(self.state, s.key))
        return out

    def configure(self, host: Host, values: dict[str, Any]) -> None:
        """Restore settings of a session before the mesh is registered (no computation); by
        default each declared setting's value goes to its state's attribute of that name
        (its isolines to :attr:`isolines`)."""
        for s in self.spec.settings:
            if isinstance(s, IsolineFields):
                s.apply(self.isolines, values[s.key])
            else:
                setattr(self.state, s.key, values[s.key])

    def isolines_section(self) -> dict[str, Any]:
        """Its declared isoline settings by key (for a panel that writes its own
        :meth:`capture`)."""
        return {
            s.key: s.capture(self.isolines)
            for s in self.spec.settings
            if isinstance(s, IsolineFields)
        }

    def configure_isolines(self, values: dict[str, Any]) -> None:
        """Set :attr:`isolines` from a session section (for a panel that writes its own
        :meth:`configure`)."""
        for s in self.spec.settings:
            if isinstance(s, IsolineFields):
                s.apply(self.isolines, values[s.key])
        self.watch.forget()  # the fields are uploaded again with them

    def restore(self, host: Host, values: dict[str, Any], active: bool) -> None:
        """Restore the rest of a session once the mesh is registered (``active``: the session's
        view is this panel)."""

    def start(self, host: Host, options: dict[str, Any], shown: bool, screenshot: bool) -> None:
        """Apply ``meshlap view`` options it understands (``--vertex``, ``--k``, ...) when the
        window opens; ``shown``: it is the first view; ``screenshot``: a headless picture
        follows."""

    def busy(self) -> str:
        """What background job of this panel is running (``""``: none); while one runs a
        session is not loaded (jobs of ``state.jobs`` are seen by the host without it)."""
        return ""

    def animating(self) -> bool:
        """Something of this panel plays (a sweep, a smoothing run, a turn): while it is the
        view on screen the window keeps its full frame rate, not the busy or idle rate of a
        window without input."""
        return False

    # -------------------------------------------------------------- keys, play
    def on_key(self, host: Host, key: str) -> bool:
        """React to a shortcut key; True when it was used."""
        return False

    def frames(self, host: Host, options: dict[str, Any]) -> Iterator[str]:
        """``meshlap animate``: set up each frame of its animation, yield the frame's caption
        (only panels whose spec has an ``animation``)."""
        raise NotImplementedError(f"the {self.name} panel has no animation")
