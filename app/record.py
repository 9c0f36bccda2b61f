"""The viewer's *record* button: what a panel plays, written to the same GIF/MP4 as
``meshlap animate``.

Each panel that plays something (Smoothing: play; Spectral: the k sweep and the eigenmodes;
Surfaces: the normal section turning) owns a :class:`Recorder` and calls :func:`draw_record` at
the end of its ``draw``: the collapsed *record* header (file name, record / stop), then, while
recording, one frame of the 3D view each time what the panel shows changes, with the caption
the CLI burns into the same kind of frame (the panel's state module has the caption function
its animation uses too). The file's frame rate follows what was recorded: the rate the panel's
animation declares for it (smoothing 10, k sweep 15, eigenmodes 1.5, θ turn 15 frames per
second).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import polyscope as ps

from meshlap_core.errors import MeshError
from meshlap_core.io.animation import FrameWriter, burn_caption

from .scene import crop_to_scene

if TYPE_CHECKING:
    from .host import Host

RECORD_HEADER = "record (GIF / MP4)"
FIRST_FPS = 10.0
"""The frame rate a recording opens with, until its first change sets the panel's own."""


class Recorder:
    """The *record* / *stop* buttons of a panel: while recording, every change of what the
    panel plays (a smoothing step, a new k or mode, a new θ) adds a frame of the 3D view;
    *stop* writes the GIF/MP4 atomically and says where.

    The frame rate is that of the first change recorded (``fps`` of :meth:`capture`): the
    frame shown when *record* was pressed waits for it, so starting a recording and then
    playing the eigenmodes gives a 1.5 fps file, dragging k a 15 fps one. An MP4 streams from
    its first frame, so the rate cannot change later.

    Parameters
    ----------
    stem : str
        Default file name (without folder), e.g. ``smoothing.gif``.
    """

    def __init__(self, stem: str) -> None:
        self.file_text = stem
        self.writer: FrameWriter | None = None
        self.status = ""
        self.rate_set = False  # the first change has set the frame rate
        self.last: Any = None
        self._held: tuple[np.ndarray, str] | None = None  # the first frame, until a change
        self._capturing = False

    @property
    def recording(self) -> bool:
        return self.writer is not None

    @property
    def count(self) -> int:
        """Frames recorded so far."""
        if self.writer is None:
            return 0
        return self.writer.count + (self._held is not None)

    def draw(self, host: Host) -> None:
        """The collapsed *record* header: file name, record / stop, where the last one went."""
        ui = host.ui
        if not ui.header(RECORD_HEADER, default_open=False):
            return
        _, self.file_text = ui.input_text(
            "record file",
            self.file_text,
            "a .gif or .mp4 name (in the Export folder unless a full path)",
        )
        if not self.recording:
            if ui.button("record", "start recording what this panel plays (a frame per change)"):
                self.start(host)
        elif ui.button("stop", "stop and write the file"):
            if host.background:
                self.stop_in_background(host)
            else:
                self.status = self.stop()
        host.draw_job(self._job_owner())
        if self.recording:
            ui.text(f"recording: {self.count} frames")
        if self.status:
            ui.text_whole_words(self.status)

    def start(self, host: Host) -> None:
        """Begin a recording into the file named in the field.

        Raises
        ------
        MeshError
            Already recording, a bad name, extension or folder, or MP4 without the video extra
            (nothing changes).
        """
        if self.recording:
            raise MeshError("already recording: stop first", "record")
        if not self.file_text.strip():
            raise MeshError("the file name is empty", "record file")
        self.writer = FrameWriter(host.state.in_folder(self.file_text), FIRST_FPS)
        self.last, self._held, self.rate_set = None, None, False
        self.status = ""

    def stop(self) -> str:
        """Write the file; the message says where (or why not)."""
        writer, self.writer = self.writer, None
        held, self._held = self._held, None
        if writer is None:
            return ""
        try:
            if held is not None:
                writer.add(burn_caption(*held))
            return f"wrote {writer.count} frames ({writer.fps:g} fps) to {writer.close()}"
        except MeshError:
            writer.abort()
            raise

    def _job_owner(self) -> str:
        return f"record {id(self)}"

    def stop_in_background(self, host: Host) -> None:
        """*stop* in the window: the file is written (encoded) as a job, the window goes on;
        the message says where when it is done (or why not)."""
        writer, self.writer = self.writer, None
        held, self._held = self._held, None
        if writer is None:
            return
        if held is not None:
            writer.add(burn_caption(*held))
        self.status = f"writing {writer.count} frames ..."

        def done(path: Any) -> None:
            self.status = f"wrote {writer.count} frames ({writer.fps:g} fps) to {path}"

        def failed(message: str) -> None:
            writer.abort()
            self.status = message

        host.state.jobs.start(
            self._job_owner(),
            f"writing {writer.count} frames",
            lambda reporter: writer.close(),
            done,
            failed,
        )

    def restart(self) -> None:
        """A play starts over right after *record*: drop the frame held from the moment of
        *record* (the file then starts with the first k or mode played)."""
        if self.writer is not None and self.writer.count == 0:
            self._held, self.last = None, None

    def capture(self, host: Host, key: Any, caption: str, fps: float) -> None:
        """Add a frame when recording and ``key`` (what the panel shows) changed; ``fps`` is
        the frame rate of what changed (taken by the file at its first change)."""
        if self.writer is None or self._capturing or key == self.last:
            return
        self._capturing = True
        try:
            host.flush_frame()  # a copy appeared this frame: frame it before the picture
            buf = host.picture()  # the view as on screen: its colour bars and captions
            if self.last is None:  # the frame on screen when *record* was pressed
                self._held = (buf, caption)
            else:
                self._add(buf, caption, fps)
            self.last = key
        finally:
            self._capturing = False

    def _add(self, buf: np.ndarray, caption: str, fps: float) -> None:
        """Write the held first frame (the rate set by this first change) and ``buf``; a
        frame the writer refuses (the window was resized) ends the recording, nothing written.
        """
        writer = self.writer
        if writer is None:
            return
        if not self.rate_set:
            self.rate_set = True
            writer.fps = fps
        try:
            if self._held is not None:
                writer.add(burn_caption(*self._held))
                self._held = None
            writer.add(burn_caption(buf, caption))
        except MeshError as exc:
            writer.abort()
            self.writer, self._held = None, None
            raise MeshError(f"recording stopped, nothing written: {exc}", "record") from exc


def crop_scene(host: Host, buf: np.ndarray) -> np.ndarray:
    """The part of a window buffer ``(h, w, 4)`` left of meshlap's panel (where the viewer
    frames the scene; :func:`.scene.crop_to_scene`)."""
    return crop_to_scene(buf, ps.get_window_size()[0], host.state.ui_scale)


def draw_record(
    host: Host,
    recorder: Recorder,
    key: Any,
    caption: Callable[[], str],
    fps: float | Callable[[], float],
) -> None:
    """The panels' hook: draw the record header, then capture a frame if recording.

    ``caption`` (and ``fps`` when a function) are called only when a frame is captured.
    """
    recorder.draw(host)
    if recorder.recording and key != recorder.last:
        recorder.capture(host, key, caption(), fps() if callable(fps) else fps)
