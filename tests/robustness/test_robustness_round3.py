"""Hostile round 3: one test per cause found (the class tests are in
``test_robustness_faults.py``, ``_reads.py``, ``_resources.py``, ``_writes.py`` and ``_api.py``).
"""

from __future__ import annotations

import errno
import itertools
import os
import shlex
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from meshlap_core import MeshError, SpectralBasis, add_noise, primitives, save_mesh
from meshlap_core.cli import main
from tests.support import hostile

V, F = primitives.icosphere(1)
PY = shlex.quote(sys.executable)


def _sh(cmd: str, cwd: Path, **env: str) -> subprocess.CompletedProcess[str]:
    """``cmd`` in a shell (to close descriptors with ``>&-``), ``meshlap`` meaning this
    interpreter's ``-m meshlap_core.cli``."""
    full = cmd.replace("meshlap ", f"{PY} -m meshlap_core.cli ")
    return subprocess.run(
        ["/bin/sh", "-c", full],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=cwd,
        env={**os.environ, **env},
    )


@pytest.fixture
def mesh(tmp_path: Path) -> Path:
    path = tmp_path / "sphere.obj"
    save_mesh(path, V, F)
    return path


# ---------------------------------------------------------------- output streams
@pytest.mark.parametrize(
    "env",
    [
        {"PYTHONIOENCODING": "ascii"},
        {"PYTHONIOENCODING": "latin-1"},
        {"LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"},
    ],
)
def test_a_stream_that_cannot_encode_greek_gets_ascii_spellings(mesh, tmp_path, env):
    res = _sh(f"meshlap info {mesh}", tmp_path, **env)
    assert res.returncode == 0, res.stderr
    assert "chi" in res.stdout and "Traceback" not in res.stderr


def test_the_ascii_fallback_spells_each_symbol():
    from meshlap_core.cli import ASCII_SPELLINGS

    text = "χ λ κ ≤ ≥ ν"
    assert text.encode("ascii", errors="meshlap-ascii") == b"chi lambda kappa <= >= nu"
    assert "🙂".encode("ascii", errors="meshlap-ascii") == b"?"
    assert all(v.isascii() for v in ASCII_SPELLINGS.values())


def test_closed_stderr_keeps_exit_code_2(tmp_path):
    res = _sh("meshlap info missing.obj 2>&-", tmp_path)
    assert res.returncode == 2 and res.stdout == ""


def test_closed_stdout_is_an_error_not_a_crash(mesh, tmp_path):
    res = _sh(f"meshlap inspect {mesh} --vertex 3 --json >&-", tmp_path)
    assert res.returncode == 2
    assert res.stderr.splitlines() == [
        "meshlap: error: <stdout>: standard output is closed; the output was not written"
    ]


def test_closed_stdout_on_bad_input_is_still_2(tmp_path):
    res = _sh("meshlap info missing.obj >&-", tmp_path)
    assert res.returncode == 2 and "no such file" in res.stderr


# ---------------------------------------------------------------- file names in messages
@pytest.mark.parametrize(
    "name", ["a\x1b[31mred\x1b[0m.obj", "bell\x07.obj", "rtl\u202e.obj", "cr\rline.obj"]
)
def test_control_characters_in_a_file_name_are_escaped(name, capsys, tmp_path):
    code = main(["info", str(tmp_path / name)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert err.isprintable() or (err.endswith("\n") and err[:-1].isprintable())
    assert "\x1b" not in err and "\x07" not in err and "no such file" in err


def test_printable_escapes_what_the_terminal_would_act_on():
    from meshlap_core.errors import printable

    assert printable("a\x00b\x1b[2Jc\udcff.obj") == "a\\x00b\\x1b[2Jc\\udcff.obj"
    assert printable("χ é 漢.obj") == "χ é 漢.obj"
    err = MeshError("bad", "x\x1b.obj")
    assert str(err) == "x\\x1b.obj: bad" and err.source == "x\x1b.obj"


# ---------------------------------------------------------------- read-only file systems
def test_read_only_file_system_is_not_called_permission_denied(tmp_path, monkeypatch):
    import meshlap_core.frames as frames
    from meshlap_core.io import atomic

    class ReadOnly:
        f_flag = os.ST_RDONLY

    monkeypatch.setattr(frames.os, "access", lambda p, m: False)
    monkeypatch.setattr(atomic.os, "statvfs", lambda p: ReadOnly())
    with pytest.raises(MeshError, match="cannot write in this directory: read-only file system"):
        frames.check_animation_output(tmp_path / "a.gif")


# ---------------------------------------------------------------- videos
def test_a_full_disk_during_mp4_output_says_so(tmp_path, monkeypatch):
    """ffmpeg dies on a full disk and Python sees a broken pipe with ffmpeg's command line
    appended: the message is the cause, the temporary file is removed."""
    import meshlap_core.frames as frames

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
    from meshlap_core.frames import video_cause

    exc = OSError(errno.EPIPE, "Broken pipe\nFFMPEG STDERR: ... Read-only file system")
    assert video_cause(exc, tmp_path) == "read-only file system"
    assert video_cause(RuntimeError("boom\nFFMPEG COMMAND: x"), tmp_path) == "boom"


# ---------------------------------------------------------------- GIF frames are streamed
def test_gif_frames_go_to_disk_as_they_arrive(tmp_path):
    """Memory holds one frame: after each frame the temporary file has grown by about one
    encoded frame (the old writer kept every frame until close)."""
    from meshlap_core.frames import FrameWriter

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


# ---------------------------------------------------------------- the cache
def _cache_path(cache_dir: Path) -> Path:
    from meshlap_core.spectral.basis import problem_options
    from meshlap_core.spectral.cache import cache_file, mesh_key

    return cache_file(cache_dir, mesh_key(V, F, problem_options("cotan", "voronoi")))


def test_a_cache_entry_declaring_8_gb_is_refused_from_its_header(tmp_path):
    cache = tmp_path / "cache"
    cache.mkdir()
    entry = hostile.npz_bomb(_cache_path(cache), len(V))
    assert entry.stat().st_size < 100_000
    basis = SpectralBasis.compute(V, F, 4, cache_dir=cache)
    notes = [m for m in basis.info.messages if m.startswith("ignored cache file")]
    assert len(notes) == 1 and "'vectors'" in notes[0] and "compressed" in notes[0]
    assert not basis.info.from_cache


def test_a_stored_member_whose_header_lies_is_refused(tmp_path):
    """An uncompressed member declaring more data than it holds (the header alone would make a
    trusting loader allocate it)."""
    import zipfile

    from meshlap_core.spectral.cache import load_entry

    path = tmp_path / "e.npz"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("mass.npy", hostile._npy_header((len(V),)) + bytes(8))
    with pytest.raises(ValueError, match=r"'mass' declares 336 bytes of data but holds 8"):
        load_entry(path, len(V))
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("vectors.npy", hostile._npy_header((len(V), 10**9)))
    with pytest.raises(ValueError, match=r"'vectors' has shape \(42, 1000000000\)"):
        load_entry(path, len(V))


def test_random_bytes_in_the_cache_give_no_pickle_advice(tmp_path, capsys):
    cache = tmp_path / "cache"
    cache.mkdir()
    hostile.random_entry(_cache_path(cache))
    basis = SpectralBasis.compute(V, F, 4, cache_dir=cache)
    notes = [m for m in basis.info.messages if m.startswith("ignored cache file")]
    assert len(notes) == 1 and "not an .npz archive" in notes[0]
    assert "pickle" not in notes[0]


def test_an_unreadable_cache_entry_is_replaced_by_a_readable_one(tmp_path):
    cache = tmp_path / "cache"
    cache.mkdir()
    entry = _cache_path(cache)
    hostile.random_entry(entry)
    entry.chmod(0)
    SpectralBasis.compute(V, F, 4, cache_dir=cache)
    mode = stat.S_IMODE(entry.stat().st_mode)
    assert mode & stat.S_IRUSR and mode & stat.S_IWUSR, oct(mode)
    again = SpectralBasis.compute(V, F, 4, cache_dir=cache)
    assert again.info.from_cache  # read back: not recomputed on every run


def test_a_user_basis_file_keeps_its_mode(tmp_path):
    """``SpectralBasis.save`` (``spectral --out``) keeps the mode of the file it replaces."""
    out = tmp_path / "b.npz"
    out.write_bytes(b"old")
    out.chmod(0o600)
    SpectralBasis.compute(V, F, 3, cache=False).save(out)
    assert stat.S_IMODE(out.stat().st_mode) == 0o600


# ---------------------------------------------------------------- extreme option values
def test_noise_that_would_overflow_blames_the_noise(tmp_path, capsys, mesh):
    with pytest.raises(MeshError, match=r"^alpha: noise alpha 1e\+308 would move") as info:
        add_noise(V, F, 1e308)
    assert "vertex 0" not in str(info.value)
    code = main(["denoise-eval", str(mesh), "--noise", "0.01,1e308", "--iters", "1"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("meshlap: error: --noise: noise alpha 1e+308")
    assert np.isfinite(add_noise(V, F, 1e70)).all()  # large but within the limit works


@pytest.mark.parametrize(
    "seed", [2**31, 2**63, 2**64 + 5, -1, True, 1.0, 10**5000], ids=lambda s: type(s).__name__
)
def test_seeds_beyond_what_the_fields_hold_are_refused(seed):
    from meshlap_core.noise import MAX_SEED, check_seed

    with pytest.raises(MeshError, match=f"must be an integer 0 to {MAX_SEED}"):
        check_seed(seed, "seed")
    with pytest.raises(MeshError, match="seed"):
        add_noise(V, F, 0.01, seed=seed)
    assert check_seed(MAX_SEED) == MAX_SEED and check_seed(np.int64(5)) == 5


def test_spectral_k_too_large_for_memory_names_k(mesh, capsys, monkeypatch):
    import meshlap_core.spectral.budget as budget

    monkeypatch.setattr(budget, "memory_limit", lambda: 512 * 2**20 + 64 * 42 * 10)
    code = main(["spectral", str(mesh), "--k", "42", "--no-cache"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("meshlap: error: --k: 42 modes on 42 vertices need")
    assert "at most 10 modes fit" in err and "input is too large" not in err
    assert main(["spectral", str(mesh), "--k", "10", "--no-cache"]) == 0
