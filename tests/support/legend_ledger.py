"""What colour quantities the viewer left visible, and with which legend.

polyscope's Python API cannot say whether a quantity is enabled or has an on-screen colour bar,
so :class:`Ledger` wraps the calls that add or remove quantities and structures (a pytest
``monkeypatch``) and keeps, per structure name, each scalar or colour quantity's last
arguments. polyscope enables one colour quantity per structure: enabling one disables the
others, as here. Tests import it as a plain module (``from legend_ledger import Ledger``).
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import polyscope as ps

KINDS = {
    "surface_mesh": (ps.SurfaceMesh, ps.has_surface_mesh, ps.get_surface_mesh),
    "point_cloud": (ps.PointCloud, ps.has_point_cloud, ps.get_point_cloud),
    "curve_network": (ps.CurveNetwork, ps.has_curve_network, ps.get_curve_network),
}


@dataclass
class Quantity:
    """One colour quantity as last added: ``scalar`` (a colour map) or ``color`` (RGB)."""

    kind: str
    enabled: bool
    colorbar: bool
    vminmax: tuple[float, float] | None
    owner: str = ""  # the panel whose code added it ("" for the host)
    isolines: bool = False  # ``isolines_enabled`` as passed
    isoline_period: float | None = None  # ``isoline_period`` as passed (None: not passed)
    values: Any = None  # the values uploaded (a scalar quantity)


def _calling_panel() -> str:
    """The name of the panel whose method is on the call stack (innermost), or ``""``."""
    from meshlap_app.panels.base import Panel

    f = sys._getframe(2)
    while f is not None:
        obj = f.f_locals.get("self")
        if isinstance(obj, Panel):
            return obj.name
        f = f.f_back
    return ""


@dataclass
class Ledger:
    """Per structure name, its colour quantities (see the module docstring), and each surface
    mesh's vertex positions and faces as last uploaded (``meshes``: registered, then moved by
    ``update_vertex_positions``)."""

    quantities: dict[str, dict[str, Quantity]] = field(default_factory=dict)
    kind_of: dict[str, str] = field(default_factory=dict)
    meshes: dict[str, tuple[Any, Any]] = field(default_factory=dict)

    def install(self, monkeypatch: Any) -> Ledger:
        """Wrap polyscope's calls with ``monkeypatch``; returns ``self``."""
        for kind, (cls, _, _) in KINDS.items():
            self._wrap_class(monkeypatch, cls)
            self._wrap_register(monkeypatch, kind)
            self._wrap_remove(monkeypatch, kind)
        real_all = ps.remove_all_structures

        def remove_all() -> None:
            real_all()
            self.quantities.clear()
            self.meshes.clear()

        monkeypatch.setattr(ps, "remove_all_structures", remove_all)
        return self

    def _add(self, structure: str, name: str, q: Quantity) -> None:
        q.owner = _calling_panel()
        qs = self.quantities.setdefault(structure, {})
        if q.enabled:
            for other in qs.values():
                other.enabled = False
        qs[name] = q

    def _wrap_class(self, monkeypatch: Any, cls: type) -> None:
        ledger = self
        real_scalar, real_color = cls.add_scalar_quantity, cls.add_color_quantity
        real_remove, real_remove_all = cls.remove_quantity, cls.remove_all_quantities

        def add_scalar(obj: Any, name: str, values: Any, *args: Any, **kw: Any) -> Any:
            out = real_scalar(obj, name, values, *args, **kw)
            vm = kw.get("vminmax")
            q = Quantity(
                "scalar",
                bool(kw.get("enabled", False)),
                bool(kw.get("onscreen_colorbar_enabled", False)),
                None if vm is None else (float(vm[0]), float(vm[1])),
            )
            q.isolines = bool(kw.get("isolines_enabled", False))
            q.isoline_period = kw.get("isoline_period")
            q.values = values
            ledger._add(obj.get_name(), name, q)
            return out

        def add_color(obj: Any, name: str, values: Any, *args: Any, **kw: Any) -> Any:
            out = real_color(obj, name, values, *args, **kw)
            q = Quantity("color", bool(kw.get("enabled")), False, None)
            ledger._add(obj.get_name(), name, q)
            return out

        def remove(obj: Any, name: str, *args: Any, **kw: Any) -> Any:
            out = real_remove(obj, name, *args, **kw)
            ledger.quantities.get(obj.get_name(), {}).pop(name, None)
            return out

        def remove_all(obj: Any) -> Any:
            out = real_remove_all(obj)
            ledger.quantities.pop(obj.get_name(), None)
            return out

        if cls is ps.SurfaceMesh:
            real_update = cls.update_vertex_positions

            def update(obj: Any, points: Any, *args: Any, **kw: Any) -> Any:
                out = real_update(obj, points, *args, **kw)
                name = obj.get_name()
                faces = ledger.meshes.get(name, (None, None))[1]
                ledger.meshes[name] = (np.array(points, dtype=np.float64), faces)
                return out

            monkeypatch.setattr(cls, "update_vertex_positions", update)
        monkeypatch.setattr(cls, "add_scalar_quantity", add_scalar)
        monkeypatch.setattr(cls, "add_color_quantity", add_color)
        monkeypatch.setattr(cls, "remove_quantity", remove)
        monkeypatch.setattr(cls, "remove_all_quantities", remove_all)

    def _wrap_register(self, monkeypatch: Any, kind: str) -> None:
        real = getattr(ps, f"register_{kind}")

        def register(name: str, *args: Any, **kw: Any) -> Any:
            self.quantities.pop(name, None)
            self.kind_of[name] = kind
            if kind == "surface_mesh":
                points, faces = args[0], args[1] if len(args) > 1 else kw.get("faces")
                self.meshes[name] = (
                    np.array(points, dtype=np.float64),
                    np.array(faces, dtype=np.int64),
                )
            return real(name, *args, **kw)

        monkeypatch.setattr(ps, f"register_{kind}", register)

    def _wrap_remove(self, monkeypatch: Any, kind: str) -> None:
        real = getattr(ps, f"remove_{kind}")

        def remove(name: str, *args: Any, **kw: Any) -> Any:
            self.quantities.pop(name, None)
            if kind == "surface_mesh":
                self.meshes.pop(name, None)
            return real(name, *args, **kw)

        monkeypatch.setattr(ps, f"remove_{kind}", remove)

    # ------------------------------------------------------------------ reading
    def structure_enabled(self, name: str) -> bool:
        return any(has(name) and get(name).is_enabled() for _, has, get in KINDS.values())

    def shown_meshes(self) -> dict[str, tuple[Any, Any, Quantity | None]]:
        """The enabled surface meshes: name -> (positions, faces, its visible colour quantity
        or ``None``)."""
        out = {}
        for name, (points, faces) in self.meshes.items():
            if not (ps.has_surface_mesh(name) and ps.get_surface_mesh(name).is_enabled()):
                continue
            on = [q for q in self.quantities.get(name, {}).values() if q.enabled]
            out[name] = (points, faces, on[0] if on else None)
        return out

    def visible(self) -> dict[tuple[str, str], Quantity]:
        """The enabled colour quantities of the enabled structures: (structure, name) ->."""
        return {
            (s, n): q
            for s, qs in self.quantities.items()
            if self.structure_enabled(s)
            for n, q in qs.items()
            if q.enabled
        }


# ---------------------------------------------------------------------- colour bar titles
UNIT = r"dimensionless|(?:1/)?length(?:\^[234])?|mixed: [^\[\]]+"
"""The units a colour bar may give: lengths to a power, ``dimensionless``, or a field whose
parts have different units said as such (``uniform − cotan H``: a length minus a curvature)."""
TITLE = re.compile(rf"(?P<quantity>.*[A-Za-z].*) \[(?P<unit>{UNIT})\]")
FACTOR = re.compile(r" \(x 1e-?\d+\)$")  # values rescaled for float32 (scene.scalar_for_upload)


def title_problem(title: str) -> str | None:
    """What is wrong with a colour bar's title (``None``: it names its quantity and gives its
    unit in brackets at its end, ``[dimensionless]`` for a ratio; a float32 rescaling factor
    ``(x 1e-74)`` may follow)."""
    bare = FACTOR.sub("", title)
    if not TITLE.fullmatch(bare):
        return f"{title!r} does not name a quantity with its [unit] (or [dimensionless])"
    return None
