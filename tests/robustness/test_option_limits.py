"""Option values at the edge of what the numbers hold: noise that would overflow blames the noise,
seeds beyond what the fields hold are refused, and a spectral k too large for memory names k."""

from __future__ import annotations

import numpy as np
import pytest

from meshlap_core import MeshError, add_noise, primitives
from meshlap_core.cli import main

V, F = primitives.icosphere(1)


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
