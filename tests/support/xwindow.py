"""A small real-window harness: Xvfb, ``xdotool`` input, ``xwd`` screenshots as PNG, and a count
of the frames the viewer draws.

The viewer is driven only as a user drives it: a ``meshlap view`` subprocess on a virtual X
display, real mouse and keyboard events, screenshots of the whole screen. Nothing here imports
polyscope or the ``app`` package.

Screenshots come from ``xwd -root -silent`` (X Window Dump, the X11 format); :func:`read_xwd`
decodes the 24/32-bit TrueColor dumps that Xvfb produces into an ``(h, w, 3) uint8`` array and
:func:`write_png` writes that with numpy and zlib only (PNG, ISO/IEC 15948: IHDR, one IDAT,
IEND, filter type 2 "Up" on every row).

:class:`Frames` counts the frames a window draws with the X DAMAGE extension (``libXdamage``
through ``ctypes``): every buffer swap of the viewer damages its window, also when the pixels do
not change. A test waits for the viewer to have *drawn frames after an input event* (so it has
processed it) instead of sleeping a guessed time: a loaded machine may take seconds per frame.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import select
import shutil
import struct
import subprocess
import time
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

TOOLS = ("Xvfb", "xdotool", "xwd")
LIBS = ("X11", "Xdamage")  # loaded with ctypes by Frames

WINDOW_TEST = True
"""Whether the running test may open a real window: ``tests/conftest.py`` sets it before each
test (its ``window`` marker), so an unmarked test that starts Xvfb fails instead of running
when ``pytest -m "not window"`` was asked for the fast tiers alone."""


def missing_tools() -> list[str]:
    """Names of the X tools (on ``PATH``) and libraries the harness needs that are missing."""
    missing = [t for t in TOOLS if shutil.which(t) is None]
    return missing + [f"lib{n}" for n in LIBS if ctypes.util.find_library(n) is None]


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
        if not WINDOW_TEST:
            raise RuntimeError("a test that starts Xvfb must be marked @pytest.mark.window")
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


# ---------------------------------------------------------------------------- frames drawn
_XDAMAGE_REPORT_NON_EMPTY = 3  # one DamageNotify each time the damage goes from empty to not
_XErrorHandler = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p)


@_XErrorHandler
def _ignore_x_error(_display: int, _event: int) -> int:
    """Xlib's default handler exits the process (pytest with it) on any error, e.g. a
    ``BadDamage`` once the viewer's window is gone: ignore instead (the caller sees no frames)."""
    return 0


class _XImage(ctypes.Structure):
    """The head of Xlib's ``XImage`` (the fields :meth:`Frames.grab` reads)."""

    _fields_ = [
        ("width", ctypes.c_int),
        ("height", ctypes.c_int),
        ("xoffset", ctypes.c_int),
        ("format", ctypes.c_int),
        ("data", ctypes.c_void_p),
        ("byte_order", ctypes.c_int),
        ("bitmap_unit", ctypes.c_int),
        ("bitmap_bit_order", ctypes.c_int),
        ("bitmap_pad", ctypes.c_int),
        ("depth", ctypes.c_int),
        ("bytes_per_line", ctypes.c_int),
        ("bits_per_pixel", ctypes.c_int),
    ]


class Frames:
    """Count the frames a window draws (X DAMAGE: each buffer swap damages the window).

    Parameters
    ----------
    display : str
        The X display (``":91"``).
    window : int
        The window's id (as ``xdotool search`` prints it).

    Notes
    -----
    The damage is reported at the "non empty" level and cleared after each report, so one
    report stands for one or more drawings since the last one. :meth:`mark` clears it (with
    round trips, so nothing drawn before is counted after); :meth:`wait` then counts reports.
    """

    def __init__(self, display: str, window: int) -> None:
        x11 = ctypes.CDLL(ctypes.util.find_library("X11") or "libX11.so.6")
        xd = ctypes.CDLL(ctypes.util.find_library("Xdamage") or "libXdamage.so.1")
        vp, ul, ci = ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int
        x11.XOpenDisplay.restype, x11.XOpenDisplay.argtypes = vp, [ctypes.c_char_p]
        x11.XSetErrorHandler.argtypes = [_XErrorHandler]
        for name in ("XPending", "XFlush", "XConnectionNumber", "XCloseDisplay"):
            getattr(x11, name).argtypes = [vp]
        x11.XNextEvent.argtypes = [vp, vp]
        x11.XSync.argtypes = [vp, ci]
        xd.XDamageQueryExtension.argtypes = [vp, ctypes.POINTER(ci), ctypes.POINTER(ci)]
        xd.XDamageCreate.restype, xd.XDamageCreate.argtypes = ul, [vp, ul, ci]
        xd.XDamageSubtract.argtypes = [vp, ul, ul, ul]
        self._x11, self._xd = x11, xd
        x11.XSetErrorHandler(_ignore_x_error)
        self._dpy = x11.XOpenDisplay(display.encode())
        if not self._dpy:
            raise RuntimeError(f"cannot open X display {display}")
        base, err = ctypes.c_int(), ctypes.c_int()
        if not xd.XDamageQueryExtension(self._dpy, ctypes.byref(base), ctypes.byref(err)):
            raise RuntimeError(f"X display {display} has no DAMAGE extension")
        self._notify = base.value  # XDamageNotify is the extension's first event
        self._window = window
        self._damage = xd.XDamageCreate(self._dpy, window, _XDAMAGE_REPORT_NON_EMPTY)
        self._event = (ctypes.c_long * 24)()  # an XEvent (a union of 24 longs)
        self.count = 0  # damage reports since the last mark()
        self.mark()

    def _drain(self) -> None:
        """Read the events that arrived, counting the damage reports (each re-arms the report).
        Ends with nothing queued and nothing readable, so ``select`` on the connection wakes
        at the next report (no round trip here: it would queue events behind ``select``)."""
        x11 = self._x11
        while x11.XPending(self._dpy):  # flushes, reads what arrived, counts the queue
            x11.XNextEvent(self._dpy, self._event)
            if ctypes.c_int.from_buffer(self._event).value == self._notify:
                self.count += 1
                self._xd.XDamageSubtract(self._dpy, self._damage, 0, 0)
        x11.XFlush(self._dpy)

    def mark(self) -> None:
        """Count from now: clear the window's damage and forget the reports before (the round
        trip brings in every report sent before the clear)."""
        self._xd.XDamageSubtract(self._dpy, self._damage, 0, 0)
        self._x11.XSync(self._dpy, 0)
        self._drain()
        self.count = 0

    def wait(self, n: int, timeout: float, alive: Callable[[], bool] = lambda: True) -> bool:
        """Wait until ``n`` damage reports arrived since :meth:`mark` (``False`` after
        ``timeout`` seconds, or as soon as ``alive()`` says the window's owner is gone)."""
        deadline = time.monotonic() + timeout
        fd = self._x11.XConnectionNumber(self._dpy)
        while True:
            self._drain()
            if self.count >= n:
                return True
            left = deadline - time.monotonic()
            if left <= 0 or not alive():
                return False
            select.select([fd], [], [], min(left, 0.25))

    def grab(self) -> np.ndarray:
        """The window's pixels now, ``(h, w, 3) uint8`` (``XGetImage`` on this connection:
        milliseconds, where ``xwd`` takes a process; right after a damage report it shows the
        frame that report stands for)."""
        x11 = self._x11
        if not getattr(self, "_typed_get_image", False):
            x11.XGetImage.restype = ctypes.POINTER(_XImage)
            x11.XGetImage.argtypes = [ctypes.c_void_p, ctypes.c_ulong, *[ctypes.c_int] * 2]
            x11.XGetImage.argtypes += [ctypes.c_uint, ctypes.c_uint, ctypes.c_ulong, ctypes.c_int]
            x11.XGetWindowAttributes.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_void_p]
            x11.XFree.argtypes = [ctypes.c_void_p]
            self._typed_get_image = True
        attrs = (ctypes.c_int * 64)()  # XWindowAttributes: x, y, width, height first
        x11.XGetWindowAttributes(self._dpy, self._window, attrs)
        w, h = attrs[2], attrs[3]
        ptr = x11.XGetImage(self._dpy, self._window, 0, 0, w, h, 0xFFFFFFFF, 2)  # ZPixmap
        if not ptr:
            raise RuntimeError("XGetImage failed (the window is gone?)")
        im = ptr.contents
        try:
            if im.bits_per_pixel != 32:
                raise RuntimeError(f"XGetImage gave {im.bits_per_pixel} bits per pixel")
            size = im.bytes_per_line * im.height
            raw = np.ctypeslib.as_array(
                ctypes.cast(im.data, ctypes.POINTER(ctypes.c_uint8)), (size,)
            )
            rows = raw.reshape(im.height, im.bytes_per_line)[:, : 4 * im.width]
            out = np.ascontiguousarray(rows.reshape(im.height, im.width, 4)[..., 2::-1])
        finally:
            x11.XFree(im.data)
            x11.XFree(ptr)
        return out

    def close(self) -> None:
        if self._dpy:
            self._x11.XCloseDisplay(self._dpy)
            self._dpy = None


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
    frames: Frames | None = None  # counts the window's frames once it is found

    def start(self, title: str = "Polyscope|meshlap", timeout: float = 60.0) -> App:
        self.stderr_path = self.cwd / "stderr.txt"
        self.proc = subprocess.Popen(
            self.argv,
            cwd=self.cwd,
            # nothing lands in the user's home; the window's layout (meshlap's config folder)
            # starts fresh in each test, so a layout saved by another run cannot move the panel
            env=dict(self.x.env(), HOME=str(self.cwd), XDG_CONFIG_HOME=str(self.cwd / ".config")),
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
        self.frames = Frames(self.x.display, int(self.window))
        return self

    def drawn(self, n: int = 2, timeout: float = 30.0) -> None:
        """Wait until the viewer drew ``n`` frames from now on. Called right after an input
        event was sent, it returns once the viewer has processed the event and drawn the outcome.

        Two frames, not one: the first may end a frame that read its input before the event
        arrived; the one after it read it.

        Raises
        ------
        AssertionError
            When the viewer died or drew fewer than ``n`` frames in ``timeout`` seconds.
        """
        assert self.frames is not None, "App.start() first"
        self.frames.mark()
        if not self.frames.wait(n, timeout, self.alive):
            if not self.alive():
                raise AssertionError("the viewer died while drawing frames after an input event")
            raise AssertionError(f"the viewer drew fewer than {n} frames in {timeout:.0f} s")

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
        if self.frames is not None:
            self.frames.close()
            self.frames = None
        terminate(self.proc)
