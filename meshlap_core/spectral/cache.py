"""The disk cache of spectral bases: one ``.npz`` per mesh and options, keyed by a hash.

A file is used only after it is checked against the mesh's own pencil (see
:func:`validate_arrays`); anything unusable is ignored (and said so) and recomputed.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from ..linalg.checks import (
    RESIDUAL_TOL,
    inertia_check,
    orthogonality,
    orthonormality_probe,
    pair_residuals,
)
from ..linalg.components import components
from ..types import FloatArray, IntArray, as_mesh

CACHE_FORMAT = 1


def default_cache_dir() -> Path:
    """``$MESHLAP_CACHE_DIR``, else ``$XDG_CACHE_HOME/meshlap``, else ``~/.cache/meshlap``."""
    env = os.environ.get("MESHLAP_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    if xdg:
        return Path(xdg) / "meshlap"
    return Path.home() / ".cache" / "meshlap"


def mesh_key(V: FloatArray, F: IntArray, options: dict[str, str]) -> str:
    """SHA-256 of the vertices, faces, options and cache format (hex)."""
    V, F = as_mesh(V, F)
    h = hashlib.sha256()
    h.update(f"meshlap-spectral-{CACHE_FORMAT}".encode())
    h.update(json.dumps(options, sort_keys=True).encode())
    h.update(np.array(V.shape + F.shape, dtype=np.int64).tobytes())
    h.update(V.tobytes())
    h.update(F.tobytes())
    return h.hexdigest()


def cache_file(cache_dir: Path, key: str) -> Path:
    """The cache file of the basis with hash ``key`` in ``cache_dir``."""
    return Path(cache_dir) / f"spectral-{key[:40]}.npz"


def write_npz(path: Path, arrays: dict[str, Any], overwrite_inputs: Any = ()) -> None:
    """Write ``arrays`` to ``path`` as ``.npz``, atomically (temporary file, ``os.replace``)."""
    from ..io import atomic_write

    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        np.savez(f, **arrays)


def validate_arrays(
    data: Any, key: str, options: dict[str, str], K: sp.csr_matrix, m: FloatArray
) -> tuple[FloatArray, FloatArray, float]:
    """Check a loaded basis in full before it is trusted (format, hash, options, shapes, finite
    values, ascending non-negative eigenvalues, the mass; ``M``-orthonormality: a sample of
    columns against all, every column's norm and random probes of the whole ``UᵀMU = I``; the
    residual of every pair, one sparse product; Sylvester's inertia at a gap, so that no
    eigenvalue is missing below it); raise ``ValueError`` with the reason if anything is off.
    A file whose key and checksum are right but whose numbers were altered is refused.
    Returns the eigenvalues, vectors and the sampled orthogonality error."""
    need = ("format", "key", "options", "eigenvalues", "vectors", "mass")
    missing = [x for x in need if x not in data]
    if missing:
        raise ValueError(f"missing {', '.join(missing)}")
    if int(data["format"]) != CACHE_FORMAT:
        raise ValueError("other cache format")
    if str(data["key"]) != key:
        raise ValueError("stale (the mesh or the options differ)")
    if json.loads(str(data["options"])) != options:
        raise ValueError("options differ")
    lam = np.asarray(data["eigenvalues"], dtype=np.float64)
    U = np.asarray(data["vectors"])
    mm = np.asarray(data["mass"], dtype=np.float64)
    n = len(m)
    if U.dtype != np.float64 or lam.ndim != 1 or U.shape != (n, len(lam)) or mm.shape != (n,):
        raise ValueError("wrong shapes")
    if len(lam) == 0:
        raise ValueError("empty basis")
    if not (np.isfinite(lam).all() and np.isfinite(U).all()):
        raise ValueError("non-finite values")
    if lam.min() < 0 or np.any(np.diff(lam) < 0):
        raise ValueError("eigenvalues not ascending and >= 0")
    if not np.allclose(mm, m, rtol=1e-12, atol=0):
        raise ValueError("mass differs")
    orth = orthogonality(U, m)
    probe = orthonormality_probe(U, m, np.random.default_rng())  # (unseeded: unpredictable)
    if orth > 1e-8 or probe > 1e-6:
        raise ValueError(
            f"vectors are not M-orthonormal (max|U^T M U - I| {orth:.1e}, probe {probe:.1e})"
        )
    _, labels = components(K)
    res = pair_residuals(K, m, lam, U, labels)
    bad = np.flatnonzero(~(res <= RESIDUAL_TOL))
    if len(bad):
        j = int(bad[0])
        raise ValueError(
            f"{len(bad)} of {len(lam)} pairs are not eigenpairs of this mesh (pair {j}, "
            f"lambda = {lam[j]:.6g}: relative residual {res[j]:.1e} > {RESIDUAL_TOL:.0e})"
        )
    try:
        inertia_check(K, m, lam, len(lam))
    except MeshError as exc:
        raise ValueError(exc.problem) from None
    return lam, np.asfortranarray(U), orth


def read_cache(
    path: Path,
    key: str,
    options: dict[str, str],
    K: sp.csr_matrix,
    m: FloatArray,
    messages: list[str],
) -> tuple[FloatArray, FloatArray, float] | None:
    """The validated cached basis, or ``None`` (missing, or unusable: reason in ``messages``)."""
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            return validate_arrays(data, key, options, K, m)
    except Exception as exc:  # any unreadable or inconsistent file is ignored and rebuilt
        messages.append(f"ignored cache file {path}: {exc}")
        return None


# --------------------------------------------------------------------------------------------
# The basis
# --------------------------------------------------------------------------------------------
