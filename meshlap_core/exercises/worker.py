"""One harness process for one student's copy, driven by the checker.

:class:`Session` is a grading run: the isolation chosen once, a private temporary folder, the
calls' inputs written once for every student. :class:`Worker` starts the harness
(:mod:`.harness`) in it (:mod:`.isolation`), sends it commands, reads its replies against a
deadline the checker keeps, measures its CPU time from ``/proc``, captures what the student
prints into a capped log (:class:`CappedLog`: never the checker's own output), and at the end
kills its process group and sweeps every process that carries its token.
"""

from __future__ import annotations

import atexit
import json
import os
import secrets
import select
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from ..errors import check_cancel
from .isolation import (
    Isolation,
    Limits,
    choose,
    command,
    cpu_seconds,
    find_harness,
    process_tree,
    sweep,
)
from .plain import REPLY_CAP, InputStore, Tampered, parse_reply

QUIT_SECONDS = 3.0
"""An idle worker asked to quit may take this long before it is killed."""
LOG_CAP = 32 * 1024
"""Bytes of what a student's file prints that the report keeps (the rest is counted)."""
SIGNALS = {
    signal.SIGKILL: "killed (SIGKILL): over the CPU-time limit, or killed from outside",
    signal.SIGSEGV: "a segmentation fault in native code (a C extension, or ctypes)",
    signal.SIGABRT: "aborted in native code",
    signal.SIGXCPU: "over the CPU-time limit",
    signal.SIGXFSZ: "wrote a file over the size limit",
    signal.SIGBUS: "a bus error in native code",
}


class WorkerGone(RuntimeError):
    """The worker ended (its message says how)."""


class CappedLog(threading.Thread):
    """Reads the worker's standard output and error until they close, keeping the first
    :data:`LOG_CAP` bytes (the rest is counted, not kept)."""

    def __init__(self, fd: int) -> None:
        super().__init__(daemon=True)
        self.fd = fd
        self.kept = bytearray()
        self.total = 0

    def run(self) -> None:
        try:
            while chunk := os.read(self.fd, 65536):
                self.total += len(chunk)
                room = LOG_CAP - len(self.kept)
                if room > 0:
                    self.kept += chunk[:room]
        except OSError:
            pass
        finally:
            os.close(self.fd)

    def text(self) -> str:
        """What was kept, control characters escaped (a newline and a tab kept)."""
        raw = self.kept.decode("utf-8", errors="replace")
        out = "".join(c if c.isprintable() or c in "\n\t" else repr(c)[1:-1] for c in raw)
        if self.total > len(self.kept):
            out += f"\n… ({self.total - len(self.kept)} more bytes not kept)"
        return out


PREFIX = "meshlap-grade-"
"""A session's temporary folder: ``meshlap-grade-<pid>-<random>``."""


def _remove_orphans() -> None:
    """Remove the temporary folders of sessions whose process is gone (a viewer killed while
    a check's inputs were kept: its exit handler never ran)."""
    for path in Path(tempfile.gettempdir()).glob(f"{PREFIX}*-*"):
        pid = path.name[len(PREFIX) :].split("-")[0]
        if pid.isdigit() and not os.path.exists(f"/proc/{pid}") and path.owner() == _me():
            shutil.rmtree(path, ignore_errors=True)


def _me() -> str:
    import pwd

    return pwd.getpwuid(os.geteuid()).pw_name


class Session:
    """A grading run: the isolation, a private temporary folder, the inputs written once."""

    def __init__(self, sandbox: str | None = None) -> None:
        self.isolation: Isolation = choose(sandbox)
        _remove_orphans()
        self.root = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}-"))
        os.chmod(self.root, 0o711)
        inputs = self.root / "in"
        inputs.mkdir(mode=0o755)
        os.chmod(inputs, 0o755)
        self.store = InputStore(inputs)

    def private_folder(self, prefix: str) -> Path:
        """A new empty folder the worker's user may write (its copy, its answers)."""
        path = Path(tempfile.mkdtemp(prefix=prefix, dir=self.root))
        if self.isolation.user is not None:
            os.chown(path, self.isolation.user, self.isolation.user)
        return path

    def close(self) -> None:
        shutil.rmtree(self.root, ignore_errors=True)

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_DEFAULT: dict[str, Session] = {}
_DEFAULT_LOCK = threading.Lock()


def default_session(sandbox: str | None = None) -> Session:
    """The process's session for ``sandbox`` (made once, removed at exit)."""
    from .isolation import requested_level

    level = requested_level(sandbox)
    with _DEFAULT_LOCK:
        if level not in _DEFAULT:
            _DEFAULT[level] = Session(level)
            atexit.register(_DEFAULT[level].close)
        return _DEFAULT[level]


def _give(path: Path, user: int | None) -> None:
    """Hand the copy ``path`` (every file in it) to the worker's user."""
    if user is None:
        return
    for dirpath, _dirs, files in os.walk(path):
        os.chown(dirpath, user, user)
        for f in files:
            os.chown(os.path.join(dirpath, f), user, user, follow_symlinks=False)


class Worker:
    """The harness running on one student's copy (see module).

    Parameters
    ----------
    session : Session
    copy : Path
        The student's copy (the worker's folder and working directory).
    main : str
        The student's file, relative to ``copy``.
    functions : list of str
        The task functions to look for.
    limits : Limits
    """

    def __init__(
        self, session: Session, copy: Path, main: str, functions: list[str], limits: Limits
    ) -> None:
        self.iso = session.isolation
        self.token = secrets.token_hex(16)
        self.outputs = session.private_folder("out-")
        _give(copy, self.iso.user)
        paths = {
            "folder": str(copy),
            "inputs": str(session.store.folder),
            "outputs": str(self.outputs),
        }
        r_cmd, self.commands = os.pipe()
        self.replies, w_rep = os.pipe()
        r_log, w_log = os.pipe()
        config = {
            "student": main,
            "functions": functions,
            "commands": r_cmd,
            "replies": w_rep,
            "limits": limits.for_harness(self.iso.user),
            "answer_cap": limits.answer,
        }
        argv, env, cwd = command(self.iso, paths, config, self.token)
        user = (
            {}
            if self.iso.user is None
            else {"user": self.iso.user, "group": self.iso.user, "extra_groups": []}
        )
        try:
            self.proc = subprocess.Popen(
                argv,
                stdin=subprocess.DEVNULL,
                stdout=w_log,
                stderr=w_log,
                cwd=cwd,
                env=env or None,
                pass_fds=(r_cmd, w_rep),
                start_new_session=True,
                **user,
            )
        finally:
            for fd in (r_cmd, w_rep, w_log):
                os.close(fd)
        self.log = CappedLog(r_log)
        self.log.start()
        self.buffer = b""
        self.pid = self.proc.pid
        self.own: set[int] = {self.proc.pid}
        self.nonce = ""
        self.busy = False
        self.closed = False

    def send(self, message: dict[str, Any]) -> None:
        """One command, with a fresh nonce its reply must repeat (a closed pipe is left to
        :meth:`receive` to report)."""
        self.busy = True
        self.nonce = secrets.token_hex(12)
        data = (json.dumps({**message, "nonce": self.nonce}) + "\n").encode()
        try:
            while data:
                data = data[os.write(self.commands, data) :]
        except OSError:
            pass

    def receive(self, deadline: float, cancel: Any = None) -> dict[str, Any] | None:
        """The next reply, or None when ``deadline`` (``time.monotonic``) passes first.

        Raises
        ------
        WorkerGone
            The worker ended (closed its side).
        Tampered
            A line that is not a valid reply.
        Cancelled
            ``cancel`` was set.
        """
        while b"\n" not in self.buffer:
            if len(self.buffer) > REPLY_CAP:
                raise Tampered("a reply line without end")
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            check_cancel(cancel, "the check")
            ready, _, _ = select.select([self.replies], [], [], min(left, 0.1))
            if ready:
                chunk = os.read(self.replies, 65536)
                if not chunk:
                    raise WorkerGone(self.ending())
                self.buffer += chunk
        line, _, self.buffer = self.buffer.partition(b"\n")
        reply = parse_reply(line)
        if reply["nonce"] != self.nonce:
            raise Tampered(f"a {reply['ev']!r} reply that answers no command of the checker's")
        self.busy = False
        return reply

    def locate(self) -> None:
        """Find the harness's own process (under bubblewrap, two levels down) for its CPU time,
        and the worker's own processes (before the student's code runs: any other is theirs)."""
        self.pid = find_harness(self.proc.pid, self.token)
        self.own = set(process_tree(self.proc.pid))

    def cpu(self) -> float:
        """The harness's CPU seconds so far."""
        return cpu_seconds(self.pid)

    def ending(self) -> str:
        """How the worker ended (after its replies closed)."""
        try:
            code = self.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            return "the worker closed its replies but did not end"
        sig = -code if code < 0 else code - 128 if self.iso.isolated and code > 128 else 0
        if sig and sig in SIGNALS:
            return f"the worker was {SIGNALS[sig]}" if sig == signal.SIGKILL else SIGNALS[sig]
        if sig:
            return f"the worker ended on signal {sig}"
        return f"the worker exited (code {code}): os._exit(), or native code ended the process"

    def close(self) -> list[int]:
        """Kill the worker and everything it started; the pids that had to be killed."""
        if self.closed:
            return []
        self.closed = True
        if not self.busy and self.proc.poll() is None:  # idle: asked to end, as it should
            self.send({"op": "quit"})
            try:
                self.proc.wait(timeout=QUIT_SECONDS)
            except subprocess.TimeoutExpired:
                pass
        killed = sweep(self.proc.pid, self.token)
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        for fd in (self.commands, self.replies):
            try:
                os.close(fd)
            except OSError:
                pass
        self.log.join(5)
        shutil.rmtree(self.outputs, ignore_errors=True)
        return [p for p in killed if p not in self.own]
