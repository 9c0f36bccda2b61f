"""Animation files from RGB(A) frames: GIF through Pillow, MP4 through ``imageio`` +
``imageio-ffmpeg`` (the optional extra ``meshlap[video]``), captions burned into the frames.

Mesh-free and polyscope-free: ``meshlap animate`` (and the viewer's *record* button) render the
frames; this module checks the output before any rendering (:func:`check_animation_output`),
draws captions (:func:`burn_caption`) and writes the file atomically (:class:`FrameWriter`).
"""

from __future__ import annotations

import contextlib
import importlib
import os
import secrets
from pathlib import Path
from typing import IO, Any

import numpy as np

from .errors import MeshError
from .io import atomic_write, check_output_path
from .progress import Progress, bar

SUFFIXES = (".gif", ".mp4")
VIDEO_EXTRA = "pip install 'meshlap[video]'"


def parse_range(text: str, name: str, lo: int = 1, hi: int | None = None) -> tuple[int, int]:
    """Parse ``"A:B"`` (or a single ``"B"`` meaning ``lo:B``) into ``(A, B)`` with
    ``lo <= A <= B`` (and ``B <= hi`` when given).

    Raises
    ------
    MeshError
        Not two integers, ``A > B``, or outside ``[lo, hi]``, naming the argument ``name``.
    """
    parts = str(text).split(":")
    try:
        values = [int(p) for p in parts]
    except ValueError:
        raise MeshError(f"expected A:B with integers A <= B, got {text!r}", name) from None
    if len(values) == 1:
        values = [lo, values[0]]
    if len(values) != 2:
        raise MeshError(f"expected A:B with integers A <= B, got {text!r}", name)
    a, b = values
    if a > b:
        raise MeshError(f"the range {a}:{b} is empty (A must be <= B)", name)
    if a < lo:
        raise MeshError(f"must start at {lo} or more, got {a}", name)
    if hi is not None and b > hi:
        raise MeshError(f"must end at {hi} or less on this mesh, got {b}", name)
    return a, b


def require_video() -> Any:
    """``imageio.v2`` with its ffmpeg plugin, or a one-line :class:`MeshError` saying how to
    install the ``video`` extra."""
    try:
        iio = importlib.import_module("imageio.v2")
        importlib.import_module("imageio_ffmpeg")
    except ImportError:
        raise MeshError(
            f"writing MP4 needs imageio and imageio-ffmpeg: {VIDEO_EXTRA} (or write a .gif)",
            "--out",
        ) from None
    return iio


def check_animation_output(path: str | os.PathLike, overwrite_inputs: Any = ()) -> Path:
    """Check an animation output path before any rendering: a ``.gif`` or ``.mp4`` in an
    existing, writable directory (an MP4 also needs the ``video`` extra).

    Raises
    ------
    MeshError
        Unknown extension, missing or unwritable directory, a directory or an input as target,
        or MP4 without imageio.
    """
    target = check_output_path(path, overwrite_inputs, suffixes=SUFFIXES)
    parent = target.parent if str(target.parent) else Path(".")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise MeshError("cannot write in this directory: permission denied", os.fspath(parent))
    if target.exists() and not os.access(target, os.W_OK):
        raise MeshError("the output file is not writable", os.fspath(target))
    if target.suffix.lower() == ".mp4":
        require_video()
    return target


_FONT_CACHE: dict[int, Any] = {}


def _font(size: int) -> Any:
    """DejaVu Sans (shipped with matplotlib: Greek letters and subscripts) at ``size`` px."""
    from PIL import ImageFont

    if size not in _FONT_CACHE:
        import matplotlib

        path = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"
        try:
            _FONT_CACHE[size] = ImageFont.truetype(str(path), size)
        except OSError:  # pragma: no cover - matplotlib always ships it
            _FONT_CACHE[size] = ImageFont.load_default()
    return _FONT_CACHE[size]


def caption_box(height: int, width: int) -> tuple[int, int, int, int]:
    """Pixel box ``(x0, y0, x1, y1)`` of the caption band of a ``height × width`` frame."""
    band = max(18, round(height * 0.075))
    return 0, height - band, width, height


def burn_caption(frame: np.ndarray, text: str) -> np.ndarray:
    """The frame ``(h, w, 3|4) uint8`` as RGB with ``text`` written in a light band along the
    bottom (the input is not modified).

    Returns
    -------
    rgb : (h, w, 3) uint8
    """
    from PIL import Image, ImageDraw

    img = Image.fromarray(np.ascontiguousarray(np.asarray(frame, dtype=np.uint8)[..., :3]))
    if not text:
        return np.asarray(img)
    h, w = img.height, img.width
    x0, y0, x1, y1 = caption_box(h, w)
    draw = ImageDraw.Draw(img)
    draw.rectangle((x0, y0, x1, y1), fill=(245, 245, 245))
    size = max(10, int((y1 - y0) * 0.62))
    font = _font(size)
    while size > 8 and font.getlength(text) > w - 24:  # shrink to fit a narrow frame
        size -= 1
        font = _font(size)
    draw.text((x0 + 12, (y0 + y1) // 2), text, fill=(20, 20, 20), font=font, anchor="lm")
    return np.asarray(img)


class FrameWriter:
    """Collect frames and write them atomically as GIF (Pillow) or MP4 (imageio-ffmpeg).

    Parameters
    ----------
    path : path
        ``.gif`` or ``.mp4`` (checked with :func:`check_animation_output` first).
    fps : float
        Frames per second.
    overwrite_inputs : iterable of path
        Files the output must not replace.

    Notes
    -----
    GIF frames are quantized as they arrive (a frame costs ``w·h`` bytes while collecting) to
    one 256-colour palette taken from the first frame (median cut; the colour bar, when shown,
    brings its whole colour map into it), with Floyd-Steinberg dithering against banding;
    MP4 frames are streamed to a temporary file beside the target.
    Nothing appears at ``path`` until :meth:`close` succeeds; :meth:`abort` removes the rest.
    """

    def __init__(self, path: str | os.PathLike, fps: float, overwrite_inputs: Any = ()) -> None:
        self.path = check_animation_output(path, overwrite_inputs)
        if not (np.isfinite(fps) and 0.1 <= fps <= 120):
            raise MeshError(f"must be between 0.1 and 120, got {fps}", "--fps")
        self.fps = float(fps)
        self.kind = self.path.suffix.lower()
        self.count = 0
        self.size: tuple[int, int] | None = None  # (width, height)
        self._gif: list[Any] = []
        self._palette: Any = None
        self._tmp: Path | None = None
        self._video: Any = None

    def add(self, frame: np.ndarray) -> None:
        """Append one frame ``(h, w, 3|4) uint8`` (every frame has the first frame's size)."""
        rgb = np.ascontiguousarray(np.asarray(frame, dtype=np.uint8)[..., :3])
        size = (rgb.shape[1], rgb.shape[0])
        if self.size is None:
            self.size = size
        elif size != self.size:
            raise MeshError(f"frame {self.count} is {size}, the first was {self.size}", "frames")
        if self.kind == ".gif":
            from PIL import Image

            img = Image.fromarray(rgb)
            if self._palette is None:  # one palette for all frames: no flicker between frames
                self._palette = img.quantize(colors=256, method=Image.Quantize.MEDIANCUT)
            self._gif.append(
                img.quantize(palette=self._palette, dither=Image.Dither.FLOYDSTEINBERG)
            )
        else:
            if self._video is None:
                iio = require_video()
                parent = self.path.parent
                self._tmp = parent / f".{self.path.stem}.{secrets.token_hex(6)}.tmp.mp4"
                self._video = iio.get_writer(
                    self._tmp, fps=self.fps, codec="libx264", macro_block_size=2, quality=7
                )
            self._video.append_data(rgb[: rgb.shape[0] // 2 * 2, : rgb.shape[1] // 2 * 2])
        self.count += 1

    def close(self) -> Path:
        """Write the file (atomically) and return its path."""
        if self.count == 0:
            raise MeshError("no frames were rendered", os.fspath(self.path))
        if self.kind == ".gif":
            first, rest = self._gif[0], self._gif[1:]
            with atomic_write(self.path, mode="wb") as fh:
                self._save_gif(fh, first, rest)
            self._gif = []
        else:
            self._video.close()
            self._video = None
            if self._tmp is None:  # pragma: no cover - set with the video writer
                raise MeshError("the video was not started", os.fspath(self.path))
            os.replace(self._tmp, self.path)
            self._tmp = None
        return self.path

    def _save_gif(self, fh: IO[bytes], first: Any, rest: list[Any]) -> None:
        first.save(
            fh,
            format="GIF",
            save_all=True,
            append_images=rest,
            duration=round(1000.0 / self.fps),
            loop=0,
            optimize=False,
        )

    def abort(self) -> None:
        """Drop what was collected; remove a partial temporary file."""
        self._gif = []
        if self._video is not None:
            with contextlib.suppress(Exception):
                self._video.close()
            self._video = None
        if self._tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(self._tmp)
            self._tmp = None


def frame_progress(total: int, label: str = "animate", stream: Any = "stderr") -> Progress:
    """The frame counter of an animation on stderr, redrawn in place on any stream:
    ``meshlap: animate [#####.....] 12/60 frames``; :meth:`Progress.close` ends the line."""
    return Progress(max(int(total), 1), _frames_line, label, stream=stream, in_place=True)


def _frames_line(p: Progress) -> str:
    width = 30
    return f"meshlap: {p.label} [{bar(int(width * p.fraction), width)}] {p.done}/{p.total} frames"
