"""The eigenbasis cache against hostile entries: a compressed bomb and a header that lies are
refused before anything is allocated, random bytes get no pickle advice, an unreadable entry is
replaced by a readable one; a user's basis file keeps its mode."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from meshlap_core import SpectralBasis, primitives
from tests.support import hostile

V, F = primitives.icosphere(1)


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
