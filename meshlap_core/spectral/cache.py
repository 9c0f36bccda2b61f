"""The disk cache of spectral bases: one ``.npz`` per mesh and options, keyed by a hash.

A file is used only after it is checked against the mesh's own pencil (see
:func:`validate_arrays`); anything unusable is ignored (and said so) and recomputed.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import zipfile
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


def write_npz(
    path: Path, arrays: dict[str, Any], overwrite_inputs: Any = (), *, keep_mode: bool = True
) -> None:
    """Write ``arrays`` to ``path`` as ``.npz`` (uncompressed), atomically (temporary file,
    ``os.replace``). ``keep_mode=False`` (cache entries) gives the new file the default
    permissions rather than those of the file it replaces (an entry someone made unreadable
    would otherwise be rewritten unreadable, and recomputed on every run)."""
    from ..io import atomic_write

    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs, keep_mode=keep_mode) as f:
        np.savez(f, **arrays)


def _member_ok(name: str, shape: tuple[int, ...], dtype: np.dtype, n: int) -> str | None:
    """Why the header of member ``name`` cannot belong to a basis of a mesh with ``n``
    vertices (None when it can)."""
    if dtype.hasobject:
        return "holds Python objects"
    if name in ("format", "n_faces"):
        return None if shape == () and dtype.kind in "iu" else "is not one integer"
    if name in ("key", "options"):
        if shape != () or dtype.kind != "U" or dtype.itemsize > 4 * 4096:
            return "is not one short string"
        return None
    if dtype != np.float64:
        return f"has dtype {dtype}, not float64"
    if name == "mass":
        return None if shape == (n,) else f"has shape {shape}, not ({n},)"
    if name == "eigenvalues":
        return None if len(shape) == 1 and 1 <= shape[0] <= n else f"has shape {shape}"
    if name == "vectors":
        ok = len(shape) == 2 and shape[0] == n and 1 <= shape[1] <= n
        return None if ok else f"has shape {shape}, not ({n}, k) with k <= {n}"
    return "is not part of a basis"  # pragma: no cover - names are checked first


CACHE_MEMBERS = ("format", "key", "options", "eigenvalues", "vectors", "mass", "n_faces")


def load_entry(path: str | os.PathLike, n: int) -> dict[str, np.ndarray]:
    """Read a basis file written by :func:`write_npz` for a mesh of ``n`` vertices, checking
    each member's header before its data is loaded.

    The file goes through the project's reader (:func:`meshlap_core.io.reader.open_input`:
    a regular file within the cache-file size limit). It must be a zip archive of
    uncompressed ``.npy`` members with the names of :data:`CACHE_MEMBERS`; each member's
    header (shape, dtype) must fit a basis of ``n`` vertices and the bytes it declares must be
    those the archive holds, so that no header can make this allocate more than the file's
    own size (a 9 MB file declaring 8 GB of zeros is refused from its header).

    Parameters
    ----------
    path : path
    n : int
        The mesh's vertex count.

    Returns
    -------
    arrays : dict of str to ndarray

    Raises
    ------
    MeshError
        The reader refused the file (not a regular file, too large, unreadable).
    ValueError
        Not an ``.npz`` archive, an unexpected or compressed member, a header that does not
        fit, or a member shorter or longer than its header says; the message says which.
    """
    from ..io.reader import open_input

    out: dict[str, np.ndarray] = {}
    with open_input(path, what="cache file") as f:
        if not zipfile.is_zipfile(f):
            raise ValueError("not a basis file (not an .npz archive)")
        f.seek(0)
        try:
            archive = zipfile.ZipFile(f)
        except (zipfile.BadZipFile, OSError, ValueError) as exc:
            raise ValueError(f"not a readable .npz archive ({exc})") from None
        with archive:
            for info in archive.infolist():
                name = info.filename.removesuffix(".npy")
                if name not in CACHE_MEMBERS or name in out or not info.filename.endswith(".npy"):
                    raise ValueError(f"unexpected member {info.filename!r}")
                if info.compress_type != zipfile.ZIP_STORED:
                    raise ValueError(f"member {name!r} is compressed (entries are written plain)")
                out[name] = _read_member(archive, info, name, n)
    return out


def _read_member(archive: zipfile.ZipFile, info: zipfile.ZipInfo, name: str, n: int) -> Any:
    fmt = np.lib.format
    with archive.open(info) as mf:
        try:
            version = fmt.read_magic(mf)
            if version == (1, 0):
                shape, fortran, dtype = fmt.read_array_header_1_0(mf)
            elif version == (2, 0):
                shape, fortran, dtype = fmt.read_array_header_2_0(mf)
            else:
                raise ValueError(f"unsupported .npy version {version}")
        except ValueError as exc:
            raise ValueError(f"member {name!r}: bad .npy header ({exc})") from None
        why = _member_ok(name, tuple(shape), np.dtype(dtype), n)
        if why is not None:
            raise ValueError(f"member {name!r} {why}")
        nbytes = math.prod(shape) * np.dtype(dtype).itemsize
        if info.file_size != mf.tell() + nbytes:
            raise ValueError(
                f"member {name!r} declares {nbytes:,} bytes of data but holds "
                f"{info.file_size - mf.tell():,}"
            )
        flat = np.empty(math.prod(shape), dtype=dtype)
        raw = flat.view(np.uint8)
        done = 0
        while done < nbytes:  # straight into the array, 16 MiB at a time: no second copy
            chunk = mf.read(min(nbytes - done, 16 * 2**20))
            if not chunk:
                raise ValueError(f"member {name!r} ends early")
            raw[done : done + len(chunk)] = np.frombuffer(chunk, dtype=np.uint8)
            done += len(chunk)
    arr = flat.reshape(shape, order="F" if fortran else "C")
    return arr if arr.ndim else arr[()]


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
    if not os.path.lexists(path):
        return None
    try:
        data = load_entry(path, len(m))
        return validate_arrays(data, key, options, K, m)
    except Exception as exc:  # any unreadable or inconsistent file is ignored and rebuilt
        why = exc.problem if isinstance(exc, MeshError) else exc
        messages.append(f"ignored cache file {path}: {why}")
        return None


# --------------------------------------------------------------------------------------------
# The basis
# --------------------------------------------------------------------------------------------
