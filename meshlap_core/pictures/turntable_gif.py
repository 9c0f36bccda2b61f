"""A turntable: the mesh and its field seen from a camera turning about the up axis, a few
frames as an animated GIF that a notebook shows inline (:class:`Turntable`)."""

from __future__ import annotations

import base64
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MeshError
from . import scene as sc
from .picture import Renderer, png_of, render

FRAME_COUNTS = (2, 120)
"""Frames a turntable may have."""


@dataclass(frozen=True)
class Turntable:
    """The frames of a turntable; a notebook shows the GIF (``_repr_html_``), a front end
    without HTML the first frame (``_repr_png_``).

    Attributes
    ----------
    frames : list of (h, w, 3) uint8
    fps : float
    renderer : {"egl", "matplotlib"}
    reason : str
        Why matplotlib drew it ("" when EGL did).

    Examples
    --------
    Four frames of a turning sphere; the GIF starts with its signature:

    >>> from meshlap_core import icosphere, turntable
    >>> V, F = icosphere(2)
    >>> turn = turntable(V, F, V[:, 2], frames=4, renderer="matplotlib")
    >>> len(turn.frames), turn.gif[:6]
    (4, b'GIF89a')
    """

    frames: list[np.ndarray]
    fps: float
    renderer: str
    reason: str = ""

    def save(self, path: str | os.PathLike) -> Path:
        """Write the frames to ``path`` (``.gif``, or ``.mp4`` with the ``video`` extra)
        atomically; returns the path."""
        from ..io.animation import FrameWriter

        writer = FrameWriter(path, self.fps)
        try:
            for frame in self.frames:
                writer.add(frame)
            return writer.close()
        except BaseException:
            writer.abort()
            raise

    @property
    def gif(self) -> bytes:
        """The animated GIF (looping)."""
        with tempfile.TemporaryDirectory(prefix="meshlap-turntable-") as tmp:
            return self.save(Path(tmp) / "turntable.gif").read_bytes()

    def _repr_html_(self) -> str:
        data = base64.b64encode(self.gif).decode("ascii")
        h, w = self.frames[0].shape[:2]
        why = f"<br><small>drawn by matplotlib: {self.reason}</small>" if self.reason else ""
        return f'<img src="data:image/gif;base64,{data}" width="{w}" height="{h}">{why}'

    def _repr_png_(self) -> bytes:
        return png_of(self.frames[0])

    def __repr__(self) -> str:
        h, w = self.frames[0].shape[:2]
        return f"<Turntable {len(self.frames)} frames {w}x{h} drawn by {self.renderer}>"


def turntable(
    mesh_or_V: Any,
    F: Any = None,
    field: Any = None,
    *,
    frames: int = 12,
    degrees: float = 360.0,
    fps: float = 8.0,
    vectors: Any = None,
    camera: Any = None,
    size: Any = (480, 360),
    title: str = "",
    label: str | None = None,
    cmap: str | None = None,
    clip: float = sc.CLIP_PERCENT,
    isolines: int = 0,
    edges: bool = False,
    up: str = "y",
    renderer: Renderer = "auto",
) -> Turntable:
    """The mesh coloured by ``field`` seen from a camera turning ``degrees`` about the up
    axis in ``frames`` equal steps (the arguments as :func:`~.picture.show`'s), at the
    same distance throughout.

    Returns
    -------
    Turntable

    Raises
    ------
    MeshError
        A bad argument (named in the message).

    Examples
    --------
    >>> from meshlap_core import icosphere, turntable
    >>> V, F = icosphere(1)
    >>> t = turntable(V, F, V[:, 0], frames=3, size=(96, 72), renderer="matplotlib")
    >>> len(t.frames), t.gif[:6]
    (3, b'GIF89a')

    Examples
    --------
    >>> from meshlap_core import icosphere, turntable
    >>> V, F = icosphere(2)
    >>> turn = turntable(V, F, V[:, 2], frames=3, size=(200, 150), renderer="matplotlib")
    >>> [frame.shape for frame in turn.frames]
    [(150, 200, 3), (150, 200, 3), (150, 200, 3)]
    """
    count = sc.check_count(frames, "frames", *FRAME_COUNTS)
    if not (isinstance(degrees, int | float) and np.isfinite(degrees) and degrees != 0):
        raise MeshError(f"must be a finite non-zero angle, got {degrees!r}", "degrees")
    if not (isinstance(fps, int | float) and 0.1 <= fps <= 120):
        raise MeshError(f"must be between 0.1 and 120, got {fps!r}", "fps")
    V, Fc, name = sc.subject(mesh_or_V, F)
    one = sc.pane(V, Fc, field, label=label, cmap=cmap, clip=clip, isolines=isolines,
                  vectors=vectors, edges=edges)  # fmt: skip
    one["title"] = str(title)
    turns = tuple(float(degrees) * k / count for k in range(count))
    scene = sc.build_scene([one], name, up=up, camera=camera, turns=turns, size=size)
    images, used, reason = render(scene, renderer)
    return Turntable([np.ascontiguousarray(f[..., :3]) for f in images], float(fps), used, reason)
