"""Animation output under faults: a read-only file system is said so, a full disk during MP4
output names the cause (ffmpeg's own reason first) and leaves no file, and GIF frames go to disk
as they arrive."""

from __future__ import annotations

import errno
import itertools
import os
from pathlib import Path

import numpy as np
import pytest

from meshlap_core import MeshError


def test_read_only_file_system_is_not_called_permission_denied(tmp_path, monkeypatch):
    import meshlap_core.io.animation as frames
    from meshlap_core.io import atomic

    class ReadOnly:
        f_flag = os.ST_RDONLY

    monkeypatch.setattr(frames.os, "access", lambda p, m: False)
    monkeypatch.setattr(atomic.os, "statvfs", lambda p: ReadOnly())
    with pytest.raises(MeshError, match="cannot write in this directory: read-only file system"):
        frames.check_animation_output(tmp_path / "a.gif")


def test_a_full_disk_during_mp4_output_says_so(tmp_path, monkeypatch):
    """ffmpeg dies on a full disk and Python sees a broken pipe with ffmpeg's command line
    appended: the message is the cause, the temporary file is removed."""
    import meshlap_core.io.animation as frames

    class Full:
        f_bavail, f_frsize, f_flag = 0, 4096, 0

    class DyingWriter:
        def __init__(self, path: Path) -> None:
            self.path = path
            Path(path).write_bytes(b"partial")

        def append_data(self, frame: np.ndarray) -> None:
            raise OSError(errno.EPIPE, "[Errno 32] Broken pipe\n\nFFMPEG COMMAND:\nffmpeg -y ...")

        def close(self) -> None:
            pass

    class FakeIio:
        @staticmethod
        def get_writer(path, **kw):
            return DyingWriter(path)

    monkeypatch.setattr(frames, "require_video", lambda: FakeIio)
    monkeypatch.setattr(frames.os, "statvfs", lambda p: Full())
    w = frames.FrameWriter(tmp_path / "v.mp4", 10)
    with pytest.raises(MeshError) as info:
        w.add(np.zeros((16, 16, 3), dtype=np.uint8))
    message = str(info.value)
    assert message == f"{tmp_path / 'v.mp4'}: cannot write the video: no space left on device"
    assert list(tmp_path.iterdir()) == []


def test_video_cause_prefers_ffmpegs_own_reason(tmp_path):
    from meshlap_core.io.animation import video_cause

    exc = OSError(errno.EPIPE, "Broken pipe\nFFMPEG STDERR: ... Read-only file system")
    assert video_cause(exc, tmp_path) == "read-only file system"
    assert video_cause(RuntimeError("boom\nFFMPEG COMMAND: x"), tmp_path) == "boom"


def test_gif_frames_go_to_disk_as_they_arrive(tmp_path):
    """Memory holds one frame: after each frame the temporary file has grown by about one
    encoded frame (the old writer kept every frame until close)."""
    from meshlap_core.io.animation import FrameWriter

    rng = np.random.default_rng(0)
    w = FrameWriter(tmp_path / "a.gif", fps=10)
    sizes = []
    for _ in range(5):
        w.add(rng.integers(0, 255, (64, 96, 3), dtype=np.uint8))
        tmp = [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
        assert len(tmp) == 1 and not (tmp_path / "a.gif").exists()
        w._fh.flush()
        sizes.append(tmp[0].stat().st_size)
    assert all(b - a > 64 * 96 // 4 for a, b in itertools.pairwise(sizes))
    assert not hasattr(w, "_frames") and w._gif is not None
    w.close()
    from PIL import Image

    with Image.open(tmp_path / "a.gif") as im:
        assert im.n_frames == 5 and im.info["duration"] == 100 and im.info.get("loop") == 0
