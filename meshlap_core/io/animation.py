"""Animation files from RGB(A) frames: GIF through Pillow, MP4 through ``imageio`` +
``imageio-ffmpeg`` (the optional extra ``meshlap[video]``), captions burned into the frames.

Mesh-free and polyscope-free: ``meshlap animate`` (and the viewer's *record* button) render the
frames; this module checks the output before any rendering (:func:`check_animation_output`),
draws captions (:func:`burn_caption`) and writes the file atomically (:class:`FrameWriter`).
"""

from __future__ import annotations

import contextlib
import errno
import importlib
import os
import secrets
import sys
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import MeshError
from ..progress import Progress, bar
from .atomic import atomic_write, check_output_path, os_cause, unwritable_cause

SUFFIXES = (".gif", ".mp4")
VIDEO_EXTRA = (
    "pip install -e '.[video]' in the meshlap checkout, as the README says (from a package "
    "index: pip install 'meshlap[video]')"
)


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
        raise MeshError(
            f"cannot write in this directory: {unwritable_cause(parent)}", os.fspath(parent)
        )
    if target.is_file() and not target.is_symlink() and not os.access(target, os.W_OK):
        # (a link is replaced, not written through: its target's permissions do not matter)
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


class _Aborted(Exception):
    """Thrown into the GIF's :func:`atomic_write` to drop the temporary file."""


#: the ``strerror`` texts that ffmpeg prints when its output fails (its error reaches Python
#: as a broken pipe, with the ffmpeg command line appended)
_FFMPEG_CAUSES = (
    "No space left on device",
    "Disk quota exceeded",
    "Read-only file system",
    "Permission denied",
    "File too large",
)


def video_cause(exc: BaseException, folder: str | os.PathLike) -> str:
    """Why writing a video failed, in a few words: ffmpeg's own reason when its output names
    one, ``"no space left on device"`` when the folder has no space left (a full disk ends
    ffmpeg, which Python sees as a broken pipe), else the first line of the error (never the
    ffmpeg command line).

    Parameters
    ----------
    exc : BaseException
        What the video writer raised.
    folder : path
        The folder the video is written in.

    Returns
    -------
    str
    """
    text = str(exc)
    for cause in _FFMPEG_CAUSES:
        if cause in text:
            return cause.lower()
    if isinstance(exc, OSError) and exc.errno not in (None, errno.EPIPE):
        return os_cause(exc)
    with contextlib.suppress(OSError):
        st = os.statvfs(folder)
        if st.f_bavail * st.f_frsize < 2**20:
            return "no space left on device"
    first = text.strip().splitlines()[0] if text.strip() else type(exc).__name__
    return first.split("FFMPEG COMMAND")[0].strip() or type(exc).__name__


class FrameWriter:
    """Write frames as they arrive, atomically, as GIF (Pillow) or MP4 (imageio-ffmpeg).

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
    GIF frames are quantized as they arrive to one 256-colour palette taken from the first
    frame (median cut; the colour bar, when shown, brings its whole colour map into it), with
    Floyd-Steinberg dithering against banding, and each is encoded into a temporary file beside
    the target at once: memory holds one frame, whatever the number of frames and their size.
    MP4 frames are streamed to a temporary file beside the target by ffmpeg.
    Nothing appears at ``path`` until :meth:`close` succeeds; :meth:`abort` removes the rest.
    A failed write (a full disk, a read-only file system) is a :class:`MeshError` naming
    ``path`` and the cause.
    """

    def __init__(self, path: str | os.PathLike, fps: float, overwrite_inputs: Any = ()) -> None:
        self.path = check_animation_output(path, overwrite_inputs)
        if not (np.isfinite(fps) and 0.1 <= fps <= 120):
            raise MeshError(f"must be between 0.1 and 120, got {fps}", "--fps")
        self.fps = float(fps)
        self.kind = self.path.suffix.lower()
        self.count = 0
        self.size: tuple[int, int] | None = None  # (width, height)
        self._palette: Any = None
        self._gif: contextlib.ExitStack | None = None  # the open atomic_write of the GIF
        self._fh: IO[bytes] | None = None
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
            self._add_gif(rgb)
        else:
            try:
                if self._video is None:
                    iio = require_video()
                    parent = self.path.parent
                    self._tmp = parent / f".{self.path.stem}.{secrets.token_hex(6)}.tmp.mp4"
                    self._video = iio.get_writer(
                        self._tmp, fps=self.fps, codec="libx264", macro_block_size=2, quality=7
                    )
                self._video.append_data(rgb[: rgb.shape[0] // 2 * 2, : rgb.shape[1] // 2 * 2])
            except (OSError, RuntimeError) as exc:
                self._video_failed(exc)
        self.count += 1

    def _add_gif(self, rgb: np.ndarray) -> None:
        from PIL import GifImagePlugin, Image

        img = Image.fromarray(rgb)
        if self._palette is None:  # one palette for all frames: no flicker between frames
            self._palette = img.quantize(colors=256, method=Image.Quantize.MEDIANCUT)
        frame = img.quantize(palette=self._palette, dither=Image.Dither.FLOYDSTEINBERG)
        duration = round(1000.0 / self.fps)
        if self._gif is None:
            stack = contextlib.ExitStack()
            self._fh = stack.enter_context(atomic_write(self.path, mode="wb"))
            self._gif = stack
            header, _ = GifImagePlugin.getheader(frame, info={"loop": 0, "duration": duration})
            self._write(b"".join(header))
        self._write(b"".join(GifImagePlugin.getdata(frame, duration=duration)))

    def _write(self, data: bytes) -> None:
        assert self._fh is not None
        try:
            self._fh.write(data)
        except OSError as exc:
            self.abort()
            raise MeshError(f"cannot write the file: {os_cause(exc)}", self.path) from exc

    def _video_failed(self, exc: BaseException) -> None:
        cause = video_cause(exc, self.path.parent)
        self.abort()
        raise MeshError(f"cannot write the video: {cause}", os.fspath(self.path)) from exc

    def close(self) -> Path:
        """Finish the file (atomically) and return its path."""
        if self.count == 0:
            raise MeshError("no frames were rendered", os.fspath(self.path))
        if self.kind == ".gif":
            assert self._gif is not None
            self._write(b";")  # the GIF trailer
            stack, self._gif, self._fh = self._gif, None, None
            stack.close()  # flush, fsync, rename (a failure: MeshError naming the file)
        else:
            if self._tmp is None:  # pragma: no cover - set with the video writer
                raise MeshError("the video was not started", os.fspath(self.path))
            try:
                self._video.close()
                self._video = None
                os.replace(self._tmp, self.path)
            except (OSError, RuntimeError) as exc:
                self._video_failed(exc)
            self._tmp = None
        return self.path

    def abort(self) -> None:
        """Drop what was written; remove a partial temporary file."""
        if self._gif is not None:
            stack, self._gif, self._fh = self._gif, None, None
            try:
                raise _Aborted
            except _Aborted:
                stack.__exit__(*sys.exc_info())  # atomic_write removes its temporary file
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
