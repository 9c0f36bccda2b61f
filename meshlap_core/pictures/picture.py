"""Pictures of a mesh and its fields that a notebook shows inline: :func:`show` and
:func:`show_side_by_side` return a :class:`MeshPicture` (``_repr_png_``).

The picture is drawn by the viewer's headless renderer, found through the
``meshlap.pictures`` entry point (:data:`PICTURES_GROUP`; the core never imports the viewer):
polyscope's EGL backend in a child process, with the window's colour maps, colour bars,
isolines, one-ring and inspector, and crosses. Where the viewer is not installed or EGL cannot
start, matplotlib draws the same scene (:mod:`.fallback`) and the picture says why, in its
caption and in :attr:`MeshPicture.reason`.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from ..errors import MeshError
from ..options import check_choice
from . import scene as sc

Renderer = Literal["auto", "egl", "matplotlib"]
RENDERERS = ("auto", "egl", "matplotlib")

PICTURES_GROUP = "meshlap.pictures"
"""Entry-point group of the viewer's scene renderer: ``f(scene) -> list of (h, w, 4) uint8``
(:func:`meshlap_app.pictures.render_frames`)."""


@dataclass(frozen=True)
class MeshPicture:
    """A rendered picture; a notebook shows it inline.

    Attributes
    ----------
    png : bytes
        The PNG.
    renderer : {"egl", "matplotlib"}
        What drew it.
    reason : str
        Why matplotlib drew it ("" when EGL did, or when matplotlib was asked for).

    Examples
    --------
    A picture drawn by matplotlib (asked for here; the default tries the viewer's EGL
    renderer first) is a PNG of the requested size:

    >>> from meshlap_core import icosphere, show
    >>> V, F = icosphere(2)
    >>> pic = show(V, F, V[:, 1], size=(400, 300), renderer="matplotlib")
    >>> pic.png[1:4], pic.image.shape  # the PNG signature, rows × columns × RGB
    (b'PNG', (300, 400, 3))
    """

    png: bytes
    renderer: str
    reason: str = ""

    def _repr_png_(self) -> bytes:
        return self.png

    def __repr__(self) -> str:
        w, h = self.size
        why = f": {self.reason}" if self.reason else ""
        return f"<MeshPicture {w}x{h} drawn by {self.renderer}{why}>"

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` in pixels."""
        from PIL import Image

        with Image.open(io.BytesIO(self.png)) as img:
            return img.width, img.height

    @property
    def image(self) -> np.ndarray:
        """The picture as an ``(h, w, 3) uint8`` array."""
        from PIL import Image

        with Image.open(io.BytesIO(self.png)) as img:
            return np.asarray(img.convert("RGB"))

    def save(self, path: str | os.PathLike) -> Path:
        """Write the PNG to ``path`` (a ``.png``), atomically; returns the path."""
        from ..io import atomic_write, check_output_path

        target = check_output_path(path, (), suffixes=(".png",))
        with atomic_write(target, mode="wb") as fh:
            fh.write(self.png)
        return target


def check_renderer(renderer: Any) -> str:
    """``renderer`` if it is one of :data:`RENDERERS`."""
    if not isinstance(renderer, str):
        raise MeshError(f"must be one of {', '.join(RENDERERS)}, got {renderer!r}", "renderer")
    return check_choice(renderer, RENDERERS, "renderer", "renderer")


def render(scene: dict[str, Any], renderer: str = "auto") -> tuple[list[np.ndarray], str, str]:
    """The frames of ``scene`` as ``(h, w, 3) uint8`` images, what drew them and why not EGL.

    Parameters
    ----------
    scene : dict
        :func:`.scene.build_scene`.
    renderer : {"auto", "egl", "matplotlib"}
        ``"auto"``: the viewer's EGL renderer, matplotlib if it is not installed or cannot
        render (the reason returned and written on the picture); ``"egl"`` raises instead.

    Raises
    ------
    RuntimeError
        ``renderer="egl"`` and EGL did not render.
    """
    check_renderer(renderer)
    reason = ""
    if renderer != "matplotlib":
        try:
            frames = _viewer_frames(scene)
            return [_caption(f, scene) for f in frames], "egl", ""
        except RuntimeError as exc:
            if renderer == "egl":
                raise
            reason = str(exc)
    from .fallback import draw

    return draw(scene, reason), "matplotlib", reason


def _viewer_frames(scene: dict[str, Any]) -> list[np.ndarray]:
    """The frames drawn by the first ``meshlap.pictures`` entry point.

    Raises
    ------
    RuntimeError
        No viewer installed, it does not import, or it could not render (its reason).
    """
    from importlib.metadata import entry_points

    found = list(entry_points(group=PICTURES_GROUP))
    if not found:
        raise RuntimeError("the viewer (meshlap_app) is not installed")
    try:
        fn = found[0].load()
    except ImportError as exc:
        raise RuntimeError(f"the viewer does not import: {exc}") from exc
    return [np.asarray(f, dtype=np.uint8) for f in fn(scene)]


def _caption(frame: np.ndarray, scene: dict[str, Any]) -> np.ndarray:
    """The titles of the panes written along the bottom (``left | right``), RGB."""
    from ..io.animation import burn_caption

    titles = [p.get("title") or "" for p in scene["panes"]]
    text = "   |   ".join(t for t in titles if t) if any(titles) else ""
    if len(titles) == 2 and all(titles):
        text = f"left: {titles[0]}   |   right: {titles[1]}"
    return burn_caption(frame, text)


def png_of(frame: np.ndarray) -> bytes:
    """A ``(h, w, 3|4) uint8`` image as PNG bytes."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(frame[..., :3])).save(buf, format="PNG")
    return buf.getvalue()


def show(
    mesh_or_V: Any,
    F: Any = None,
    field: Any = None,
    *,
    vectors: Any = None,
    vertex: Any = None,
    camera: Any = None,
    size: Any = (800, 600),
    title: str = "",
    label: str | None = None,
    cmap: str | None = None,
    clip: float = sc.CLIP_PERCENT,
    isolines: int = 0,
    edges: bool = False,
    up: str = "y",
    renderer: Renderer = "auto",
) -> MeshPicture:
    """A picture of a mesh coloured by a field, drawn as the window draws it.

    Parameters
    ----------
    mesh_or_V : Mesh, (V, F) pair, or (n,3) float
        A loaded ``Mesh``, a pair such as ``icosphere(3)``, or the vertices (then ``F``).
    F : (m,3) int, optional
    field : (n,) float or str, optional
        One finite value per vertex, or one of the window's curvature fields by name
        (``"cotan"``, ``"uniform"``, ``"gaussian"``, ``"k1"``, ``"k2"``, ``"difference"``).
        Signed values: ``coolwarm`` symmetric around 0; one sign: ``viridis``; the range
        clipped at ``clip`` percent each end, with a colour bar labelled ``label``.
    vectors : (n,3) float or PrincipalCurvatures, optional
        Arrows at the vertices (scaled to the mesh), or the principal directions of
        ``estimate_curvature(...)`` as the curvature lab's crosses (black k1, green k2).
    vertex : int, optional
        Draw this vertex's ordered one-ring (numbered neighbours) and the vertex inspector
        (ring edges by cotangent weight w_ij, corner angles, area cell, n and Δx), framed on
        the ring as the window's One-ring view does (unless ``camera`` is given).
    camera : (3,) float, optional
        The direction from the mesh towards the eye, y up (default: the window's front view,
        ``(0, 0.15, -1)``).
    size : (int, int)
        Width and height in pixels.
    title : str
        Written along the bottom.
    cmap : {"coolwarm", "viridis"}, optional
        Force the symmetric signed map or the one-sign map.
    isolines : int
        Level curves of the field (0: none).
    edges : bool
        Draw the triangles' edges.
    up : str
        The mesh axis drawn up (``"y"``, ``"z"``, ``"-z"``...), as ``meshlap view --up``.
    renderer : {"auto", "egl", "matplotlib"}
        ``"auto"``: EGL, else matplotlib saying why; ``"egl"``: raise if EGL cannot render.

    Returns
    -------
    MeshPicture

    Raises
    ------
    MeshError
        A bad argument (named in the message).
    RuntimeError
        ``renderer="egl"`` and EGL did not render.

    Examples
    --------
    >>> from meshlap_core import icosphere, show
    >>> V, F = icosphere(2)
    >>> pic = show(V, F, V[:, 1], isolines=8, renderer="matplotlib")
    >>> pic.renderer, pic.size
    ('matplotlib', (800, 600))
    """
    V, Fc, name = sc.subject(mesh_or_V, F)
    one = sc.pane(V, Fc, field, label=label, cmap=cmap, clip=clip, isolines=isolines,
                  vectors=vectors, edges=edges)  # fmt: skip
    one["title"] = str(title)
    scene = sc.build_scene([one], name, up=up, vertex=vertex, camera=camera, size=size)
    frames, used, reason = render(scene, renderer)
    return MeshPicture(png_of(frames[0]), used, reason)


def show_side_by_side(
    mesh_or_V: Any,
    F: Any = None,
    left: Any = None,
    right: Any = None,
    *,
    other: Any = None,
    titles: tuple[str, str] = ("", ""),
    same_range: bool = True,
    vectors: Any = None,
    camera: Any = None,
    size: Any = (900, 450),
    cmap: str | None = None,
    clip: float = sc.CLIP_PERCENT,
    isolines: int = 0,
    edges: bool = False,
    up: str = "y",
    renderer: Renderer = "auto",
) -> MeshPicture:
    """Two fields side by side, as the window's Curvature view shows two estimators: the
    mesh on the left coloured by ``left``, a copy on the right coloured by ``right``, each
    with its colour bar (on one range when ``same_range``).

    Parameters
    ----------
    mesh_or_V, F
        As :func:`show`.
    left, right : (n,) float or str, optional
        As :func:`show`'s ``field`` (``right`` per vertex of ``other`` when given).
    other : Mesh, (V, F) pair or (n,3) float, optional
        The right pane's mesh (e.g. the smoothed positions, same faces): a vertex array takes
        the left mesh's faces. Default: the same mesh.
    titles : (str, str)
        Written along the bottom (``left: … | right: …``).
    same_range : bool
        One colour range for both (the union of theirs), so that equal colours mean equal
        values; only when both maps are the same kind.
    vectors, camera, size, cmap, clip, isolines, edges, up, renderer
        As :func:`show` (``vectors`` on the left mesh).

    Returns
    -------
    MeshPicture

    Examples
    --------
    Two fields of one sphere side by side on one colour range:

    >>> from meshlap_core import icosphere, show_side_by_side
    >>> V, F = icosphere(2)
    >>> pic = show_side_by_side(V, F, V[:, 0], V[:, 1], titles=("x", "y"), renderer="matplotlib")
    >>> pic.size, pic.image.shape
    ((900, 450), (450, 900, 3))
    """
    V, Fc, name = sc.subject(mesh_or_V, F)
    V2, F2 = V, Fc
    if other is not None:
        is_array = not (hasattr(other, "V") or isinstance(other, tuple))
        V2, F2, _ = sc.subject(other, Fc if is_array else None)
    panes = []
    for k, (Vp, Fp, field) in enumerate(((V, Fc, left), (V2, F2, right))):
        p = sc.pane(
            Vp, Fp, field, label=None, cmap=cmap, clip=clip, isolines=isolines,
            vectors=vectors if k == 0 else None, edges=edges, prefix="" if k == 0 else "right ",
        )  # fmt: skip
        p["title"] = str(titles[k]) if k < len(titles) else ""
        if p.get("field") is not None:
            p["label"] = p["title"] or p["label"]
        panes.append(p)
    a, b = panes
    if same_range and "range" in a and "range" in b and a["cmap"] == b["cmap"]:
        lo, hi = min(a["range"][0], b["range"][0]), max(a["range"][1], b["range"][1])
        a["range"] = b["range"] = (lo, hi)
    if a.get("label") and a.get("label") == b.get("label"):
        b["label"] += " (right)"  # polyscope's colour bars are named by their field
    scene = sc.build_scene(panes, name, up=up, camera=camera, size=size)
    frames, used, reason = render(scene, renderer)
    return MeshPicture(png_of(frames[0]), used, reason)
