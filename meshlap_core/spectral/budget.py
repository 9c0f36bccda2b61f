"""The memory a spectral basis needs, checked before the solver starts.

A basis of ``k`` modes on ``n`` vertices holds the ``n × k`` eigenvectors (8 bytes each), and the
solver keeps a few blocks of the same size while it works (Lanczos bases, a copy for
reconstruction, orthogonalization). Asking for more than the machine gives would end in a
``MemoryError`` deep in the solver, reported as "out of memory" against the input, or in the
operating system killing the process: :func:`check_basis_memory` refuses such a ``k`` up front,
naming it and the largest ``k`` that fits.
"""

from __future__ import annotations

import os
import resource

from ..errors import MeshError

BYTES_PER_ENTRY = 64
"""Peak bytes per entry of the ``n × k`` eigenvector block: measured about 48 (6 blocks of
float64) on meshes of 2.5k vertices with k from n/8 to n, rounded up."""

FIXED_BYTES = 512 * 2**20
"""Left aside for the interpreter, numpy / scipy and the mesh's own operators."""


def memory_limit() -> int:
    """The bytes this process may use: the physical memory, or the address-space limit
    (``ulimit -v``, ``RLIMIT_AS``) when that is lower."""
    try:
        physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, AttributeError):  # pragma: no cover - not POSIX
        physical = 2**62
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY and soft > 0:
        return min(physical, int(soft))
    return int(physical)


def _gib(n: float) -> str:
    return f"{n / 2**30:.1f} GiB" if n >= 2**30 else f"{n / 2**20:.0f} MiB"


def check_basis_memory(n: int, k: int, name: str = "k") -> None:
    """Refuse a basis of ``k`` modes on ``n`` vertices that would not fit in memory.

    Parameters
    ----------
    n : int
        Vertices.
    k : int
        Modes asked for.
    name : str
        The argument named in the message (``"k"``; the CLI shows ``--k``).

    Raises
    ------
    MeshError
        ``BYTES_PER_ENTRY · n · k + FIXED_BYTES`` exceeds :func:`memory_limit`; the message
        gives the estimate, the limit and the largest ``k`` that fits.
    """
    need = BYTES_PER_ENTRY * int(n) * int(k) + FIXED_BYTES
    limit = memory_limit()
    if need <= limit:
        return
    k_max = max((limit - FIXED_BYTES) // (BYTES_PER_ENTRY * max(int(n), 1)), 0)
    fits = f"at most {k_max} modes fit" if k_max >= 1 else "no basis fits"
    raise MeshError(
        f"{k} modes on {n} vertices need about {_gib(need)} of memory and this process may use "
        f"{_gib(limit)}; {fits} (lower it)",
        name,
    )
