"""The checker's side of the wall: nothing of the student's crosses but plain data.

- The inputs of every call are written here, by the checker, as ``.npz`` files the harness
  reads (:class:`InputStore`).
- A reply of the harness is one JSON line, capped in length, and checked against its schema
  (:func:`parse_reply`): anything else means the student's code wrote on the checker's channel
  (:class:`Tampered`).
- An answer is an ``.npz`` of stored (uncompressed) ``.npy`` members; each header is read and
  checked before any data (numbers only — no object, string or structured dtype —, at most 3
  dimensions, ``shape × itemsize`` equal to its size, all under the cap) and the data taken with
  ``np.frombuffer``: no pickle, no decompression, no allocation the cap has not allowed
  (:func:`read_answer`). :func:`unpack` rebuilds it (a CSR matrix checked entry by entry, the
  pair ``(λ, U)``, the rings) or says what is wrong with it (:class:`BadAnswer`).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import threading
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

REPLY_CAP = 256 * 1024
"""Bytes of one reply line."""
MEMBERS = {
    "none": set(),
    "array": {"value"},
    "sparse": {"data", "indices", "indptr", "shape"},
    "pair": {"lam", "U"},
    "ragged": {"values", "offsets"},
}
"""The arrays of each answer tag."""
RAISED_KINDS = ("not_implemented", "error", "memory", "refused", "exit", "unsendable")
MAX_DIM = 50_000_000
"""Largest length of one axis of an answer (a vertex count well past any mesh checked)."""


class Tampered(ValueError):
    """A reply that is not the harness's: the student's code wrote on the checker's channel."""


@dataclass(frozen=True)
class BadAnswer:
    """An answer that could not be taken as numbers: what is wrong, and its diagnosis key."""

    message: str
    key: str | None = None


def _text(cap: int) -> Any:
    return lambda v: isinstance(v, str) and len(v) <= cap


def _key(v: Any) -> bool:
    return v is None or (isinstance(v, str) and len(v) <= 64)


def _int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and 0 <= v < 2**53


def _hot(value: Any) -> bool:
    """The profiler's hottest lines: ``[[file, line, samples], ...]``."""
    return (
        isinstance(value, list)
        and len(value) <= 8
        and all(
            isinstance(h, list) and len(h) == 3 and _text(512)(h[0]) and _int(h[1]) and _int(h[2])
            for h in value
        )
    )


def _names(v: Any) -> bool:
    return isinstance(v, list) and len(v) <= 256 and all(_text(128)(x) for x in v)


_FAILURE = {
    "kind": lambda v: v in RAISED_KINDS,
    "key": _key,
    "text": _text(64_000),
    "what": _text(4096),
}
_NONCE = {"nonce": _text(64)}
SCHEMA: dict[str, dict[str, Any]] = {
    "ready": _NONCE,
    "imported": {"functions": _names, **_NONCE},
    "import_error": {**_FAILURE, **_NONCE},
    "answer": {"id": _int, "tag": lambda v: v in MEMBERS, "hot": _hot, **_NONCE},
    "raised": {"id": _int, **_FAILURE, **_NONCE},
}
"""Reply name -> its fields and their checks (``what`` is optional)."""


def parse_reply(line: bytes) -> dict[str, Any]:
    """One reply line as a dict, checked against :data:`SCHEMA`.

    Raises
    ------
    Tampered
        Not JSON, an unknown reply, a missing, extra or ill-typed field.
    """
    if len(line) > REPLY_CAP:
        raise Tampered(f"a reply of {len(line)} bytes")
    try:
        message = json.loads(line)
    except (ValueError, UnicodeDecodeError) as exc:
        raise Tampered(f"not a reply: {line[:60]!r}") from exc
    if not isinstance(message, dict) or message.get("ev") not in SCHEMA:
        raise Tampered(f"an unknown reply {str(message)[:60]!r}")
    fields = SCHEMA[message["ev"]]
    given = set(message) - {"ev"}
    required = set(fields) - {"what"}
    if not required <= given <= set(fields):
        raise Tampered(f"a {message['ev']!r} reply with fields {sorted(given)}")
    for name, ok in fields.items():
        if name in message and not ok(message[name]):
            raise Tampered(f"a {message['ev']!r} reply with a bad {name!r}")
    return message


# ---- answers -------------------------------------------------------------------------------


def _member(z: zipfile.ZipFile, info: zipfile.ZipInfo, cap: int) -> np.ndarray:
    """One ``.npy`` member, its header checked before its data is read."""
    if info.compress_type != zipfile.ZIP_STORED or info.file_size > cap:
        raise ValueError(f"{info.filename}: compressed, or over the size cap")
    with z.open(info) as f:
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
        elif version == (2, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
        else:
            raise ValueError(f"{info.filename}: npy version {version}")
        if dtype.kind not in "biufc" or dtype.fields is not None or dtype.subdtype is not None:
            raise ValueError(f"{info.filename}: dtype {dtype} is not numbers")
        if len(shape) > 3 or any(d < 0 or d > MAX_DIM for d in shape):
            raise ValueError(f"{info.filename}: shape {shape}")
        count = int(np.prod(shape, dtype=np.int64))
        nbytes = count * dtype.itemsize
        if f.tell() + nbytes != info.file_size:
            raise ValueError(f"{info.filename}: the header does not match its size")
        data = np.frombuffer(f.read(nbytes), dtype=dtype, count=count)
    return data.reshape(shape, order="F" if fortran else "C").copy()


def read_answer(path: Path, tag: str, cap: int) -> dict[str, np.ndarray]:
    """The arrays of the answer file ``path`` (tag ``tag``).

    Raises
    ------
    ValueError
        Missing, not a regular file, over ``cap`` bytes, not the tag's members, or a member
        that is not plain numbers (see module).
    """
    if not path.is_file() or path.is_symlink() or path.stat().st_size > cap + 64 * 1024:
        raise ValueError("no answer file, or over the size cap")
    with zipfile.ZipFile(path) as z:
        infos = z.infolist()
        names = {i.filename.removesuffix(".npy") for i in infos}
        if len(infos) != len(names) or names != MEMBERS[tag]:
            raise ValueError(f"members {sorted(names)}, expected {sorted(MEMBERS[tag])}")
        if sum(i.file_size for i in infos) > cap:
            raise ValueError("over the size cap")
        return {i.filename.removesuffix(".npy"): _member(z, i, cap) for i in infos}


def _csr(a: dict[str, np.ndarray]) -> sp.csr_matrix:
    shape, indptr, indices, data = a["shape"], a["indptr"], a["indices"], a["data"]
    if shape.shape != (2,) or shape.dtype.kind not in "iu" or (shape < 0).any():
        raise ValueError(f"a sparse matrix of shape {shape.tolist()}")
    rows, cols = (int(x) for x in shape)
    if indptr.shape != (rows + 1,) or indices.shape != data.shape or data.ndim != 1:
        raise ValueError("a sparse matrix whose parts disagree")
    if indptr.dtype.kind not in "iu" or indices.dtype.kind not in "iu":
        raise ValueError("a sparse matrix with non-integer indices")
    if indptr[0] != 0 or indptr[-1] != len(data) or (np.diff(indptr) < 0).any():
        raise ValueError("a sparse matrix with a bad row pointer")
    if len(indices) and (indices.min() < 0 or indices.max() >= cols):
        raise ValueError("a sparse matrix with a column out of range")
    return sp.csr_matrix((data, indices.astype(np.int64), indptr.astype(np.int64)), (rows, cols))


def unpack(tag: str, arrays: dict[str, np.ndarray]) -> Any:
    """The answer object the comparison reads, or a :class:`BadAnswer` saying why not."""
    try:
        if tag == "none":
            return BadAnswer(
                "returned None (nothing): the function must return its answer", "no_answer"
            )
        if tag == "array":
            return arrays["value"]
        if tag == "sparse":
            return _csr(arrays)
        if tag == "pair":
            return arrays["lam"], arrays["U"]
        values, offsets = arrays["values"], arrays["offsets"]
        if offsets.ndim != 1 or len(offsets) == 0 or offsets[0] != 0:
            raise ValueError("rings whose offsets do not start at 0")
        if offsets[-1] != len(values) or (np.diff(offsets) < 0).any():
            raise ValueError("rings whose offsets do not match their values")
        return [values[a:b] for a, b in itertools.pairwise(offsets.tolist())]
    except (KeyError, ValueError) as exc:
        return BadAnswer(f"an answer that could not be read back: {exc}", "not_numbers")


# ---- inputs --------------------------------------------------------------------------------


class InputStore:
    """The calls' inputs as ``.npz`` files in one folder (written once per key, thread-safe):
    arrays and sparse matrices as arrays, numbers and strings in the command itself."""

    def __init__(self, folder: Path) -> None:
        self.folder = Path(folder)
        self._lock = threading.Lock()
        self._done: dict[str, tuple[str, list[list[Any]]]] = {}

    def put(self, key: str, args: tuple[Any, ...]) -> tuple[str, list[list[Any]]]:
        """``(file name, argument specs)`` of the call ``key`` with arguments ``args``."""
        with self._lock:
            if key in self._done:
                return self._done[key]
            name = hashlib.sha256(key.encode()).hexdigest()[:24] + ".npz"
            arrays: dict[str, np.ndarray] = {}
            specs: list[list[Any]] = []
            for i, a in enumerate(args):
                specs.append(_spec(f"a{i}", a, arrays))
            tmp = self.folder / (name + ".part.npz")
            np.savez(tmp, **arrays)
            os.replace(tmp, self.folder / name)
            self._done[key] = (name, specs)
            return name, specs


def _spec(k: str, a: Any, arrays: dict[str, np.ndarray]) -> list[Any]:
    if sp.issparse(a):
        C = sp.csr_matrix(a)
        arrays.update(
            {
                f"{k}.data": C.data,
                f"{k}.indices": C.indices,
                f"{k}.indptr": C.indptr,
                f"{k}.shape": np.asarray(C.shape),
            }
        )
        return ["csr", k]
    if isinstance(a, np.ndarray):
        arrays[k] = a
        return ["array", k]
    if isinstance(a, np.generic):
        return ["value", a.item()]
    if isinstance(a, (bool, int, float, str)):
        return ["value", a]
    raise TypeError(f"an input of type {type(a).__name__}")


def save_arguments(path: str | os.PathLike, args: tuple[Any, ...]) -> None:
    """A call's arguments as one ``.npz`` (``a0``, ``a1``...; a number as a 0-d array; a sparse
    matrix as ``aK.data``, ``aK.indices``, ``aK.indptr``, ``aK.shape``), written atomically."""
    from ..io.atomic import atomic_write

    arrays: dict[str, np.ndarray] = {}
    for i, a in enumerate(args):
        spec = _spec(f"a{i}", a, arrays)
        if spec[0] == "value":
            arrays[f"a{i}"] = np.asarray(spec[1])
    with atomic_write(path, "wb") as f:
        np.savez(f, **arrays)
