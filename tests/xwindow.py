"""A small real-window harness: Xvfb, ``xdotool`` input, ``xwd`` screenshots as PNG.

The viewer is driven only as a user drives it: a ``meshlap view`` subprocess on a virtual X
display, real mouse and keyboard events, screenshots of the whole screen. Nothing here imports
polyscope or the ``app`` package.

Screenshots come from ``xwd -root -silent`` (X Window Dump, the X11 format); :func:`read_xwd`
decodes the 24/32-bit TrueColor dumps that Xvfb produces into an ``(h, w, 3) uint8`` array and
:func:`write_png` writes that with numpy and zlib only (PNG, ISO/IEC 15948: IHDR, one IDAT,
IEND, filter type 2 "Up" on every row).
"""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

TOOLS = ("Xvfb", "xdotool", "xwd")


def missing_tools() -> list[str]:
    """Names of the X tools the harness needs that are not on ``PATH``."""
    return [t for t in TOOLS if shutil.which(t) is None]


# ---------------------------------------------------------------------------- images
def read_xwd(data: bytes) -> np.ndarray:
    """Decode an X Window Dump (ZPixmap, TrueColor, 24 or 32 bits per pixel).

    Parameters
    ----------
    data : bytes
        The output of ``xwd`` (header of ``header_size`` bytes, ``ncolors`` 12-byte colour
        entries, then ``height`` rows of ``bytes_per_line`` bytes).

    Returns
    -------
    (h, w, 3) uint8
        RGB pixels, row 0 at the top.
    """
    if len(data) < 100:
        raise ValueError(f"xwd dump too short ({len(data)} bytes)")
    fields = struct.unpack(">25I", data[:100])
    header_size, version, fmt, _depth, width, height = fields[:6]
    byte_order, bpp, bpl = fields[7], fields[11], fields[12]
    masks = fields[14:17]
    ncolors = fields[19]
    if version != 7 or fmt != 2 or bpp not in (24, 32):
        raise ValueError(f"unsupported xwd dump (version {version}, format {fmt}, {bpp} bpp)")
    start = header_size + 12 * ncolors
    raw = np.frombuffer(data, dtype=np.uint8, count=bpl * height, offset=start)
    if bpp == 32 and byte_order == 0 and masks == (0xFF0000, 0x00FF00, 0x0000FF):
        # Xvfb's usual dump: bytes B, G, R, pad per pixel (a slice, no per-channel shifts)
        return np.ascontiguousarray(
            raw.reshape(height, bpl)[:, : 4 * width].reshape(height, width, 4)[..., 2::-1]
        )
    rows = raw.reshape(height, bpl)[:, : width * (bpp // 8)].reshape(height, width, bpp // 8)
    if bpp == 32:
        pix = rows.view("<u4" if byte_order == 0 else ">u4")[..., 0]
    else:
        b = rows.astype(np.uint32)
        pix = (
            b[..., 0] | (b[..., 1] << 8) | (b[..., 2] << 16)
            if byte_order == 0
            else (b[..., 0] << 16) | (b[..., 1] << 8) | b[..., 2]
        )
    out = np.empty((height, width, 3), dtype=np.uint8)
    for c, mask in enumerate(masks):
        shift = (mask & -mask).bit_length() - 1
        out[..., c] = ((pix & mask) >> shift).astype(np.uint8)
    return out


def write_png(path: Path, rgb: np.ndarray) -> None:
    """Write an ``(h, w, 3) uint8`` image as an 8-bit RGB PNG (numpy + zlib only)."""
    rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
    h, w, _ = rgb.shape
    flat = rgb.reshape(h, 3 * w)
    up = flat.copy()
    up[1:] -= flat[:-1]  # filter type 2 ("Up"), modulo 256: screenshots compress ~3x better
    rows = np.concatenate([np.full((h, 1), 2, dtype=np.uint8), up], axis=1)

    def chunk(kind: bytes, body: bytes) -> bytes:
        crc = zlib.crc32(kind + body) & 0xFFFFFFFF
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", crc)

    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    png = (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
        + chunk(b"IEND", b"")
    )
    tmp = path.with_suffix(path.suffix + ".part")
    tmp.write_bytes(png)
    tmp.replace(path)


def read_png(path: Path) -> np.ndarray:
    """Read back a PNG written by :func:`write_png` (8-bit RGB, "Up" filter on every row)."""
    data = path.read_bytes()
    pos, idat, (w, h) = 8, b"", (0, 0)
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        if kind == b"IHDR":
            w, h = struct.unpack(">II", body[:8])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    rows = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(h, 3 * w + 1)
    if np.any(rows[:, 0] != 2):
        raise ValueError(f"{path}: only filter type 2 (Up) on every row is supported")
    return np.cumsum(rows[:, 1:], axis=0, dtype=np.uint8).reshape(h, w, 3)


# ---------------------------------------------------------------------------- X server
def terminate(proc: subprocess.Popen | None) -> None:
    """Stop ``proc`` if it still runs: SIGTERM, then SIGKILL after 10 s."""
    if proc is not None and proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def free_display(start: int = 90, stop: int = 190) -> int:
    """A display number with neither a lock file nor a socket (``/tmp/.X<n>-lock``)."""
    for n in range(start, stop):
        if not Path(f"/tmp/.X{n}-lock").exists() and not Path(f"/tmp/.X11-unix/X{n}").exists():
            return n
    raise RuntimeError(f"no free X display number in {start}..{stop - 1}")


@dataclass
class XServer:
    """An ``Xvfb`` on a free display; ``xdotool``/``xwd`` run against it."""

    width: int
    height: int
    display: str = ""
    proc: subprocess.Popen | None = None

    def start(self, timeout: float = 20.0) -> XServer:
        for _ in range(5):  # another process may take the number between check and start
            n = free_display()
            self.display = f":{n}"
            screen = f"{self.width}x{self.height}x24"
            self.proc = subprocess.Popen(
                ["Xvfb", self.display, "-screen", "0", screen, "-nolisten", "tcp", "-noreset"],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline and self.proc.poll() is None:
                if Path(f"/tmp/.X11-unix/X{n}").exists():
                    return self
                time.sleep(0.05)
            self.stop()
        raise RuntimeError("Xvfb did not start")

    def env(self) -> dict[str, str]:
        env = dict(os.environ, DISPLAY=self.display)
        env.pop("WAYLAND_DISPLAY", None)
        return env

    def run(self, *args: str, timeout: float = 30.0) -> str:
        res = subprocess.run(
            list(args), env=self.env(), capture_output=True, text=True, timeout=timeout
        )
        if res.returncode != 0:
            raise RuntimeError(f"{' '.join(args)} failed: {res.stderr.strip()}")
        return res.stdout

    def xdotool(self, *args: str) -> str:
        return self.run("xdotool", *args)

    def screenshot(self) -> np.ndarray:
        res = subprocess.run(
            ["xwd", "-root", "-silent"], env=self.env(), capture_output=True, timeout=30
        )
        if res.returncode != 0:
            raise RuntimeError(f"xwd failed: {res.stderr.decode(errors='replace')}")
        return read_xwd(res.stdout)

    def stop(self) -> None:
        terminate(self.proc)


# ---------------------------------------------------------------------------- the viewer
@dataclass
class App:
    """A ``meshlap view`` process on an :class:`XServer`, its window and its stderr."""

    x: XServer
    argv: list[str]
    cwd: Path
    proc: subprocess.Popen | None = None
    window: str = ""
    stderr_path: Path = field(init=False)

    def start(self, title: str = "Polyscope|meshlap", timeout: float = 60.0) -> App:
        self.stderr_path = self.cwd / "stderr.txt"
        self.proc = subprocess.Popen(
            self.argv,
            cwd=self.cwd,
            env=dict(self.x.env(), HOME=str(self.cwd)),  # nothing lands in the user's home
            stdout=subprocess.DEVNULL,
            stderr=self.stderr_path.open("w"),
        )
        # --sync waits until a window with that name exists; it prints its id
        res = subprocess.run(
            ["xdotool", "search", "--sync", "--onlyvisible", "--name", title],
            env=self.x.env(),
            capture_output=True,
            text=True,
            timeout=timeout,
        )
        ids = res.stdout.split()
        if not ids:
            raise RuntimeError(f"no window titled {title!r}: {self.stderr()}")
        self.window = ids[0]
        return self

    def title(self) -> str:
        return self.x.xdotool("getwindowname", self.window).strip()

    def geometry(self) -> tuple[int, int, int, int]:
        """Window position and size ``(x, y, w, h)`` on the screen."""
        out = self.x.xdotool("getwindowgeometry", "--shell", self.window)
        g = dict(line.split("=", 1) for line in out.split())
        return int(g["X"]), int(g["Y"]), int(g["WIDTH"]), int(g["HEIGHT"])

    def alive(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    def stderr(self) -> str:
        return self.stderr_path.read_text(errors="replace") if self.stderr_path.exists() else ""

    def stop(self) -> None:
        terminate(self.proc)
