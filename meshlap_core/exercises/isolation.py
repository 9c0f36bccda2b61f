"""How a student's worker is walled in, and how the checker says so.

Two levels (:func:`choose`; ``meshlap check --sandbox`` or ``MESHLAP_SANDBOX`` force one):

``bwrap`` — bubblewrap (Debian ``bubblewrap``; user namespaces, or root). The harness runs in
    new user, PID, network, IPC and UTS namespaces: no network at all, the system and Python
    mounted read-only, a private ``/tmp``, ``/proc`` of its own processes only, and, of the
    disk, only its own copy of the student's folder (writable) and the checker's inputs
    (read-only). meshlap's package and the other students' folders are not in its world; no
    capabilities, no nested namespaces; every process in it is killed when the check ends
    (the PID namespace dies with it).
``process`` — a plain child process, as the checker's user (``nobody`` when the checker runs as
    root and the interpreter is readable by others). It still has the checker's limits and
    clock, its own session (killed as a group, and any process carrying its token swept), its
    own copy of the folder as working directory, a scrubbed environment, and the fence
    (:class:`.harness.Fence`), which names and refuses what Python code tries; but native code
    could still reach the user's files and the network. The checker says so on every run.

The limits (soft = hard: CPU seconds, file size, processes, open files, no core dumps, address
space) are the checker's choice (:class:`Limits`), set by the harness before the student's
code starts. Linux does not apply the process limit to root: there the PID namespace (bwrap)
and the sweep keep forks from outliving the check.
"""

from __future__ import annotations

import functools
import os
import shutil
import signal
import site
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import MeshError

SANDBOX_ENV = "MESHLAP_SANDBOX"
"""Environment variable forcing a level: ``bwrap``, ``process`` (or ``auto``, the default)."""
LEVELS = ("auto", "bwrap", "process")
TOKEN_ENV = "MESHLAP_GRADING_TOKEN"
"""Every worker's environment carries its token: a process that kept it is swept at the end."""
HOW_TO_ISOLATE = (
    "install bubblewrap (Debian/Ubuntu: apt-get install bubblewrap; Fedora: dnf install "
    "bubblewrap) and allow user namespaces"
)
INSIDE = {
    "harness": "/grader/harness.py",
    "inputs": "/grader/in",
    "outputs": "/grader/out",
    "folder": "/submission",
    "tmp": "/tmp",
}
"""Where the worker sees its paths under bubblewrap."""
NOBODY = 65534
SYSTEM_DIRS = ("/usr", "/lib", "/lib32", "/lib64", "/bin", "/sbin")
ETC_FILES = (
    "/etc/ld.so.cache",
    "/etc/ld.so.conf",
    "/etc/ld.so.conf.d",
    "/etc/alternatives",
    "/etc/localtime",
)
TMP_BYTES = 256 * 2**20
"""Size of the worker's private ``/tmp`` (bubblewrap)."""


@dataclass(frozen=True)
class Limits:
    """What one student's worker may use (all set soft = hard before the student's code).

    Attributes
    ----------
    memory : int
        Address space the student may add to the harness's own, bytes.
    cpu : int
        CPU seconds of the worker process in all.
    fsize : int
        Largest file it may write, bytes.
    nproc : int
        Processes and threads of its user (not applied to root by Linux).
    nofile : int
        Open file descriptors.
    answer : int
        Bytes one answer may take on its way back.
    """

    memory: int
    cpu: int
    fsize: int = 256 * 2**20
    nproc: int = 64
    nofile: int = 256
    answer: int = 64 * 2**20

    def for_harness(self, user: int | None) -> dict[str, int]:
        nproc = self.nproc + (_processes_of(user) if user is not None and user != 0 else 0)
        return {
            "memory": self.memory,
            "cpu": self.cpu,
            "fsize": self.fsize,
            "nproc": nproc,
            "nofile": self.nofile,
            "core": 0,
        }


@dataclass(frozen=True)
class Isolation:
    """The level chosen, and why not the stronger one.

    Attributes
    ----------
    level : {"bwrap", "process"}
    why : str
        Why not bubblewrap (``""`` under it).
    user : int or None
        The user the worker runs as (None: the checker's own).
    """

    level: str
    why: str = ""
    user: int | None = None

    @property
    def isolated(self) -> bool:
        return self.level == "bwrap"

    def describe(self) -> str:
        """One line for every report."""
        if self.isolated:
            return (
                "isolated (bubblewrap): no network, system read-only, private /tmp, its "
                "own copy of its folder; meshlap and other submissions not visible"
            )
        who = (
            "as root"
            if self.user in (None, 0) and os.geteuid() == 0
            else ("as nobody" if self.user == NOBODY else "as your user")
        )
        return (
            f"NOT isolated ({self.why}): a separate process {who} with limits, its own "
            "copy and the fence; native code could still read or write your files and "
            f"use the network — {HOW_TO_ISOLATE}"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "level": self.level,
            "isolated": self.isolated,
            "why": self.why,
            "description": self.describe(),
        }


def _processes_of(user: int) -> int:
    """How many processes (threads counted as Linux counts them) ``user`` has now."""
    count = 0
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            try:
                if os.stat(entry.path).st_uid == user:
                    count += len(os.listdir(f"{entry.path}/task"))
            except OSError:
                continue
    return count


def _readable_by_others(paths: list[str]) -> bool:
    """Every folder on the way to ``paths`` is searchable by others, and the files readable."""
    for path in paths:
        p = Path(os.path.realpath(path))
        for part in [*reversed(p.parents), p]:
            mode = part.stat().st_mode
            if not mode & (0o001 if part != p or part.is_dir() else 0o004):
                return False
    return True


def _worker_user() -> int | None:
    """``nobody`` when the checker is root and the interpreter and its libraries are readable by
    others (then the process limit applies and root's files are out of reach); else None."""
    if os.geteuid() != 0:
        return None
    paths = [sys.executable, *site.getsitepackages(), harness_path()]
    try:
        return NOBODY if _readable_by_others(paths) else None
    except OSError:
        return None


def harness_path() -> str:
    """The harness script (a file of this package, run by path, never imported by a worker)."""
    return str(Path(__file__).with_name("harness.py"))


def requested_level(level: str | None = None) -> str:
    """The level asked for (argument, else ``MESHLAP_SANDBOX``, else ``auto``).

    Raises
    ------
    MeshError
        Not one of :data:`LEVELS`.
    """
    asked = (level or os.environ.get(SANDBOX_ENV) or "auto").strip().lower()
    if asked not in LEVELS:
        raise MeshError(f"must be one of {', '.join(LEVELS)}, not {asked!r}", "sandbox")
    return asked


def choose(level: str | None = None) -> Isolation:
    """The isolation a worker gets: bubblewrap when asked or available (tried once per
    process), else a plain process with the reason.

    Raises
    ------
    MeshError
        ``bwrap`` asked for and bubblewrap does not work here.
    """
    asked = requested_level(level)
    if asked == "process":
        return Isolation("process", f"{SANDBOX_ENV}=process or --sandbox process", _worker_user())
    problem = bwrap_problem()
    if problem is None:
        return Isolation("bwrap", "", _worker_user())
    if asked == "bwrap":
        raise MeshError(f"bubblewrap does not work here: {problem}; {HOW_TO_ISOLATE}", "sandbox")
    return Isolation("process", problem, _worker_user())


def bwrap_problem() -> str | None:
    """Why bubblewrap cannot run a worker here (``None``: it can)."""
    return _bwrap_setup()[1]


@functools.cache
def _bwrap_setup() -> tuple[bool, str | None]:
    """``(newer, problem)``: whether bubblewrap takes the options of 0.8 (``--disable-userns``,
    ``--size``: tried first, then without), and why it cannot run a worker here (``None``: it
    can), tried with the real mounts, once per process."""
    exe = shutil.which("bwrap")
    if exe is None:
        return False, "bubblewrap is not installed"
    probe = Path(os.environ.get("TMPDIR", "/tmp"))
    user = _worker_user()
    where = {"folder": str(probe), "inputs": str(probe), "outputs": str(probe)}
    problem = ""
    for newer in (True, False):
        argv = [*_bwrap_argv(exe, where, {}, user, newer), sys.executable, "-I", "-c", "pass"]
        try:
            res = subprocess.run(argv, capture_output=True, timeout=60, user=user)
        except (OSError, subprocess.TimeoutExpired) as exc:
            return False, f"bubblewrap did not start ({exc})"
        if res.returncode == 0:
            return newer, None
        lines = res.stderr.decode(errors="replace").strip().splitlines()
        problem = problem or f"bubblewrap failed: {lines[-1] if lines else res.returncode}"
    return False, problem


def _mounts() -> list[str]:
    """Read-only binds: the system's libraries and Python (with its packages), the few /etc
    files the dynamic loader reads; meshlap's own package hidden if it is among them."""
    out: list[str] = []
    for d in SYSTEM_DIRS:
        if os.path.islink(d):
            out += ["--symlink", os.readlink(d), d]
        elif os.path.isdir(d):
            out += ["--ro-bind", d, d]
    roots = {
        os.path.realpath(p)
        for p in (
            sys.prefix,
            sys.base_prefix,
            sys.exec_prefix,
            sys.base_exec_prefix,
            *site.getsitepackages(),
        )
    }
    for r in sorted(roots):
        if os.path.isdir(r) and not any(r.startswith(d + os.sep) for d in SYSTEM_DIRS):
            out += ["--ro-bind", r, r]
    if sys.prefix != os.path.realpath(sys.prefix) and os.path.isdir(sys.prefix):
        out += ["--ro-bind", sys.prefix, sys.prefix]  # the venv as the interpreter names it
    for f in ETC_FILES:
        out += ["--ro-bind-try", f, f]
    for name in ("meshlap_core", "meshlap_app"):
        module = sys.modules.get(name)
        if module is not None and module.__file__:
            pkg = os.path.dirname(os.path.realpath(module.__file__))
            if any(pkg.startswith(r + os.sep) for r in roots):
                out += ["--tmpfs", pkg, "--remount-ro", pkg]
    return out


def _bwrap_argv(
    exe: str, paths: dict[str, str], env: dict[str, str], user: int | None, newer: bool
) -> list[str]:
    """bubblewrap's command line up to (not including) the program it runs (``user``: the
    user bubblewrap itself runs as, None for the checker's; ``newer``: bubblewrap 0.8's
    options, no nested user namespace and a size for ``/tmp``)."""
    argv = [
        exe,
        "--unshare-all",
        "--unshare-user",
        *(["--disable-userns"] if newer else []),
        "--uid",
        str(NOBODY),
        "--gid",
        str(NOBODY),
        "--die-with-parent",
        "--new-session",
        "--hostname",
        "grader",
    ]
    if os.geteuid() == 0 and user is None:  # bubblewrap as root keeps capabilities otherwise
        argv += ["--cap-drop", "ALL"]
    # the private /tmp first: an interpreter or venv that lives under /tmp (a checkout in a
    # temporary folder) is bound on top of it, not hidden by it
    argv += [*(["--size", str(TMP_BYTES)] if newer else []), "--tmpfs", "/tmp"]
    argv += _mounts()
    argv += ["--proc", "/proc", "--dev", "/dev"]
    argv += ["--ro-bind", harness_path(), INSIDE["harness"]]
    argv += ["--ro-bind", paths["inputs"], INSIDE["inputs"]]
    argv += ["--bind", paths["outputs"], INSIDE["outputs"]]
    argv += ["--bind", paths["folder"], INSIDE["folder"], "--chdir", INSIDE["folder"]]
    argv += ["--clearenv"]
    for k, v in env.items():
        argv += ["--setenv", k, v]
    return argv


def environment(home: str, tmp: str, token: str) -> dict[str, str]:
    """The worker's whole environment: no display, one BLAS thread, its token."""
    return {
        "PATH": "/usr/local/bin:/usr/bin:/bin",
        "HOME": home,
        "TMPDIR": tmp,
        "LANG": "C.UTF-8",
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
        "NUMEXPR_NUM_THREADS": "1",
        "MPLBACKEND": "Agg",
        "PYTHONDONTWRITEBYTECODE": "1",
        "PYTHONHASHSEED": "0",
        TOKEN_ENV: token,
    }


def command(
    iso: Isolation, paths: dict[str, str], config: dict[str, Any], token: str
) -> tuple[list[str], dict[str, str], str]:
    """``(argv, env, cwd)`` of a worker on the student's copy ``paths["folder"]`` (also
    ``inputs``, ``outputs``); ``config`` is completed with the paths as the worker sees them."""
    import json

    if iso.isolated:
        config = {
            **config,
            **{k: INSIDE[k] for k in ("inputs", "outputs", "folder")},
            "student": INSIDE["folder"] + "/" + config["student"],
        }
        env = environment(INSIDE["folder"], INSIDE["tmp"], token)
        exe = shutil.which("bwrap") or "bwrap"
        argv = _bwrap_argv(exe, paths, env, iso.user, _bwrap_setup()[0])
        argv += [sys.executable, "-I", "-B", INSIDE["harness"], json.dumps(config)]
        return argv, {}, paths["folder"]
    tmp = os.path.join(paths["folder"], ".tmp")
    os.makedirs(tmp, exist_ok=True)
    config = {
        **config,
        **{k: paths[k] for k in ("inputs", "outputs", "folder")},
        "student": os.path.join(paths["folder"], config["student"]),
    }
    argv = [sys.executable, "-I", "-B", harness_path(), json.dumps(config)]
    return argv, environment(paths["folder"], tmp, token), paths["folder"]


# ---- the worker's processes: CPU time, the end -------------------------------------------


def _stat(pid: int) -> list[str] | None:
    try:
        with open(f"/proc/{pid}/stat") as f:
            text = f.read()
    except OSError:
        return None
    return text[text.rfind(")") + 2 :].split()


def cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` (0 once it is gone)."""
    fields = _stat(pid)
    if fields is None:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _carries(pid: int, token: str) -> bool:
    try:
        with open(f"/proc/{pid}/environ", "rb") as f:
            return f"{TOKEN_ENV}={token}".encode() in f.read()
    except OSError:
        return False


def process_tree(root: int) -> list[int]:
    """``root`` and its descendants (from ``/proc``'s parent links)."""
    children: dict[int, list[int]] = {}
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            fields = _stat(int(entry.name))
            if fields is not None:
                children.setdefault(int(fields[1]), []).append(int(entry.name))
    out, todo = [], [root]
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo.extend(children.get(pid, []))
    return out


def find_harness(root: int, token: str) -> int:
    """The harness's process among ``root``'s descendants (bubblewrap starts it two levels
    down): the one that carries the token and runs Python; ``root`` if none does."""
    for pid in process_tree(root):
        fields = _stat(pid)
        try:
            with open(f"/proc/{pid}/comm") as f:
                comm = f.read()
        except OSError:
            continue
        if fields is not None and comm.startswith("python") and _carries(pid, token):
            return pid
    return root


def sweep(root: int, token: str) -> list[int]:
    """Kill ``root``'s process group, its descendants and every process carrying ``token``
    (a child that left the group by ``setsid``), until none is left; the pids killed."""
    killed: list[int] = []
    for _ in range(20):
        with_token = [
            int(e.name)
            for e in os.scandir("/proc")
            if e.name.isdigit() and _carries(int(e.name), token)
        ]
        found = sorted(set(with_token) | set(process_tree(root)) - {os.getpid()})
        alive = [p for p in found if _stat(p) is not None and _stat(p)[0] != "Z"]
        if not alive:
            return killed
        for sig_target in ("group", *alive):
            try:
                if sig_target == "group":
                    os.killpg(root, signal.SIGKILL)
                else:
                    os.kill(int(sig_target), signal.SIGKILL)
                    killed.append(int(sig_target))
            except (ProcessLookupError, PermissionError):
                continue
        time.sleep(0.02)
    return killed
