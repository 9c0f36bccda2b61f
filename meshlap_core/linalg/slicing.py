"""Spectrum slicing: the ``k`` smallest eigenpairs of a symmetric positive semidefinite pencil
from independent shift-invert block Lanczos runs on consecutive intervals, checked by inertia.

Mesh-free; the slices themselves are solved by :func:`meshlap_core.linalg.slice_worker.run_slice`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp

from .common import FloatArray, ProgressCallback, SolveInfo
from .factor import ShiftInvert
from .slice_worker import SliceContext, SliceResult, SliceSpec, run_slice

SPLIT = 0.42  # share of the interior slice when two workers split <= first_slice pairs


class FoundPairs:
    """Accumulates eigenpairs (``y = M^½ u`` coordinates) in a growing F-ordered store."""

    def __init__(self, n: int, capacity: int) -> None:
        self.n = n
        self.Y = np.empty((n, max(capacity, 1)), order="F")
        self.lam = np.empty(0)
        self.count = 0

    def add(self, lam: FloatArray, Y: FloatArray) -> None:
        """Append the pairs ``(lam, Y)`` (columns of ``Y``; not copied when ``Y`` is already
        :meth:`free` ``[:, :len(lam)]``, written there by the slice)."""
        need = self.count + len(lam)
        if need > self.Y.shape[1]:
            Y2 = np.empty((self.n, max(need, int(self.Y.shape[1] * 1.5))), order="F")
            Y2[:, : self.count] = self.Y[:, : self.count]
            self.Y = Y2
        dest = self.Y[:, self.count : need]
        if not (
            Y.shape == dest.shape
            and Y.strides == dest.strides
            and Y.ctypes.data == dest.ctypes.data
        ):
            dest[...] = Y
        self.lam = np.concatenate([self.lam, lam])
        self.count = need

    def free(self) -> FloatArray:
        """The unused columns of the store (F-ordered), where the next pairs go."""
        return self.Y[:, self.count :]

    def below(self, x: float) -> int:
        """How many stored eigenvalues are below ``x``."""
        return int(np.count_nonzero(self.lam < x))


class InlinePool:
    """A stand-in for ``ThreadPoolExecutor`` that runs each task at once in the caller."""

    def __enter__(self) -> InlinePool:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, fn: Callable[..., Any], *args: Any) -> Any:
        import concurrent.futures as cf

        fut: cf.Future[Any] = cf.Future()
        try:
            fut.set_result(fn(*args))
        except BaseException as exc:
            fut.set_exception(exc)
        return fut


def idle_cores(window: float = 0.05) -> float:
    """CPU cores not used by other processes right now: ``/proc/stat`` sampled over ``window``
    seconds (Linux), with this process's own CPU time counted as idle (threaded BLAS spins its
    threads for a while after a call: that is not load); else the number of cores minus the
    1-minute load average."""
    cpus = os.cpu_count() or 1

    def sample() -> tuple[float, float, float]:
        with open("/proc/stat") as f:
            vals = [int(x) for x in f.readline().split()[1:8]]
        # idle + iowait, total (user..softirq; guest time is inside user), own CPU seconds
        return vals[3] + vals[4], sum(vals), time.process_time()

    try:
        hz = os.sysconf("SC_CLK_TCK")
        i0, t0, p0 = sample()
        time.sleep(window)
        i1, t1, p1 = sample()
        free = (i1 - i0) + (p1 - p0) * hz
        return float(min(cpus, cpus * free / max(t1 - t0, 1)))
    except (OSError, ValueError, IndexError):
        try:
            return cpus - os.getloadavg()[0]
        except (AttributeError, OSError):  # pragma: no cover
            return float(cpus)


def default_workers(n: int, slice_size: int) -> int:
    """Two slice workers when two cores are idle, else one (on a busy machine threads only
    compete, and more slices cost more in total); one also when the Krylov bases of two
    slices would need more than ~1 GiB."""
    per = n * 8 * (2.6 * slice_size + 64) + 120 * n
    cpus = os.cpu_count() or 1
    if cpus < 2 or (1 << 30) // max(int(per), 1) < 2:
        return 1
    return 2 if idle_cores() >= 1.6 else 1


def dedupe(found: FoundPairs, old_count: int, scale: float) -> None:
    """Remove from the pairs added after ``old_count`` what the earlier ones already span.

    Pairs are compared within clusters of (nearly) equal eigenvalues: a later vector is
    orthogonalized against the cluster's earlier vectors and kept (normalized) only if more
    than half of it is new, so repeated eigenvalues are handled by subspace, not by vector.
    """
    lam = found.lam
    order = np.argsort(lam, kind="stable")
    keep: list[int] = list(range(old_count))
    kept_sorted = np.sort(lam[:old_count])
    kept_idx = np.argsort(lam[:old_count], kind="stable")
    extra: list[int] = []
    for i in order:
        if i < old_count:
            continue
        tol = 1e-6 * max(abs(lam[i]), scale)
        a, b = np.searchsorted(kept_sorted, [lam[i] - tol, lam[i] + tol + 1e-300])
        cl = [int(kept_idx[t]) for t in range(a, b)] + [
            j for j in extra if abs(lam[j] - lam[i]) <= tol
        ]
        if cl:
            Yc = found.Y[:, cl]
            w = found.Y[:, i].copy()
            for _ in range(2):
                w -= Yc @ (Yc.T @ w)
            nw = float(np.linalg.norm(w))
            if nw <= 0.5:
                continue
            if nw < 1.0 - 1e-8:
                found.Y[:, i] = w / nw
        extra.append(int(i))
    keep += sorted(extra)
    if len(keep) < found.count:
        ka = np.asarray(keep, dtype=np.int64)
        found.Y[:, : len(ka)] = found.Y[:, ka]
        found.lam = lam[ka]
        found.count = len(ka)


class SlicedLanczos:
    """The ``k`` smallest eigenpairs (``y = M^½u`` coordinates) by spectrum slicing.

    The range ``[0, λ_k]`` is cut into consecutive intervals ``[b_{i-1}, b_i)`` holding about
    ``slice_size`` eigenvalues each (widths from Weyl's law ``N(λ) ≈ area·λ/4π`` at first, then
    from the inertia counts at the shifts); each interval is one task for a pool of
    ``workers`` threads (BLAS and the sparse solves release the GIL), with its shift in its
    middle. Afterwards the inertia of every shift, and of one extra shift in a gap just above
    ``λ_k``, is compared with the number of eigenvalues found below it; a deficit is searched
    for again with the known eigenvectors deflated.

    Use: ``lam, Y = SlicedLanczos(K, m, k, Z, info, ...).solve()``; ``info`` (a
    :class:`SolveInfo`) receives the shifts, Krylov dimensions, counts, timings and messages.
    """

    seed = 20240611

    def __init__(
        self,
        K: sp.csr_matrix,
        m: FloatArray,
        k: int,
        Z: FloatArray,
        info: SolveInfo,
        *,
        known: tuple[FloatArray, FloatArray] | None,
        progress: ProgressCallback | None,
        tol: float,
        block: int,
        slice_size: int,
        first_slice: int,
        workers: int,
        weyl_density: float,
    ) -> None:
        n = len(m)
        d = np.sqrt(m)
        self.k, self.info, self.known = k, info, known
        self.workers, self.weyl_density = workers, weyl_density
        extra = 2 + k // 50  # a few beyond k to place the final inertia check in a gap
        self.target = min(k + extra, n)
        Zy = np.asfortranarray(Z * d[:, None])
        self.found = FoundPairs(n, self.target + slice_size)
        if known is None:
            self.found.add(np.zeros(Z.shape[1]), Zy)
            self.n_null = Z.shape[1]
        else:
            self.found.add(known[0], known[1])
            self.n_null = 0
        self.base = self.found.count
        self.ctx = SliceContext(
            K,
            m,
            Zy,
            tol=tol,
            block=block,
            target=self.target,
            base_count=self.base,
            progress=progress,
        )
        self.scale = self.ctx.scale
        self.checks: list[tuple[float, int]] = []  # (shift, eigenvalues below it) from inertia
        self.results: dict[int, SliceResult] = {}
        self.specs: list[SliceSpec] = []
        self.sizes = self._slice_sizes(slice_size, first_slice)
        self.n_total = len(self.sizes)
        self.lam_known_hi = float(self.found.lam.max(initial=0.0)) if known is not None else 0.0
        self.known_X: FloatArray | None = None
        self.near_all = False
        if known is not None and known[0].size:
            # the first new slice must not find the known eigenpairs near its lower end again
            w = self.sizes[0] / weyl_density
            near = np.flatnonzero(self.found.lam >= self.lam_known_hi - w)
            near = near[near >= self.n_null]
            self.near_all = len(near) == self.found.count
            self.known_X = np.asfortranarray(self.found.Y[:, near])

    # ---- planning --------------------------------------------------------------------------

    def _slice_sizes(self, slice_size: int, first_slice: int) -> list[int]:
        """Eigenpairs per slice. The lowest slice has no eigenvalues below it to resolve (the
        null space is deflated): with one worker it takes a larger share (``first_slice``)."""
        workers = self.workers
        todo = self.target - self.base
        first_big = self.known is None
        if first_big and (todo <= first_slice and not (workers >= 2 and todo >= 60)):
            sizes = [todo]
        elif first_big and todo <= first_slice:
            # two workers: split, the lowest slice (one-sided) taking a little more
            sizes = [todo - int(SPLIT * todo), int(SPLIT * todo)]
        elif workers >= 2:
            # equal slices, as many as a multiple of the workers (the last round keeps every
            # thread busy), of the size nearest to slice_size
            lo_n = max(workers, todo // slice_size // workers * workers)
            cands = [c for c in (lo_n, lo_n + workers) if todo >= 32 * c] or [1]
            n_sl = min(cands, key=lambda c: abs(np.log(todo / c / slice_size)))
            per = -(-todo // n_sl)
            sizes = [per] * n_sl
        else:
            first = min(first_slice, todo) if first_big else 0
            rest = todo - first
            n_int = max(1, -(-rest // slice_size))
            per = -(-rest // n_int)
            sizes = ([first] if first_big else []) + [per] * n_int
        return [max(s_, 4) for s_ in sizes]

    def plannable(self, i: int) -> bool:
        """Slice ``i`` is planned from the inertia counts of every slice below it, known as
        soon as each is factored (no thread waits for a long slice to end); the first
        ``workers`` slices from Weyl's law alone. So the plan never depends on which thread
        finishes first, nor on how busy the machine is."""
        if i < max(self.workers, 1):
            return True
        return all(j in self.ctx.inertia for j in range(i))

    def density_before(self, i: int) -> float:
        """Eigenvalue density for planning slice ``i``: between the last two inertia counts
        at the shifts of slices ``< i`` (the first point is ``(0, base)``), else over all of
        them, else Weyl's. The first ``workers`` slices (planned at once, while the others
        may or may not have been factored yet) use Weyl's alone."""
        if i < max(self.workers, 1):
            return self.weyl_density
        inertia = self.ctx.inertia
        pts = [(0.0, self.base if self.known is None else self.n_null)] + [
            inertia[j] for j in range(i)
        ]
        pts.sort()
        for (s0, n0), (s1, n1) in ((pts[-2], pts[-1]), (pts[0], pts[-1])):
            if s1 > s0 and n1 - n0 >= 4:
                return (n1 - n0) / (s1 - s0)
        return self.weyl_density

    def plan(self, i: int, settled: bool = False) -> SliceSpec:
        """The interval, shift and expected count of slice ``i``. ``settled``: every slice
        below ``i`` has finished (so the last slice can ask for exactly what is missing);
        true with one worker, and for the extra slices submitted after all others ended."""
        specs, results, known = self.specs, self.results, self.known
        # (the lowest slice starts just below 0: round-off can put a zero mode that the
        # component indicators do not cover a hair below 0)
        lo = (
            specs[-1].hi
            if specs
            else (self.lam_known_hi if known is not None else -1e-6 * self.scale)
        )
        rho = self.density_before(i)
        start = max(lo, 0.0)
        # the last planned slice reaches a little further: a cut just above lambda_k would
        # need the next slice for a few eigenvalues
        size = self.sizes[min(i, len(self.sizes) - 1)]
        count = None
        if i >= self.n_total - 1 and (settled or self.workers <= 1):
            # the last slice, with every lower eigenvalue known: ask for exactly what is missing
            have = self.base + sum(len(results[j].lam) for j in range(i))
            count = max(self.target - have, 1)
            size = count
        hi = start + size * (1.0 if count is not None or i < self.n_total - 1 else 1.05) / rho
        return SliceSpec(
            i,
            0.5 * (start + hi),
            lo,
            hi,
            size,
            self.known_X if (i == 0 and known is not None) else None,
            count,
            check_below=lo > 0 and not (i == 0 and self.known_X is not None and self.near_all),
            # (the top slice factors for the check above λ_k while it computes its Ritz
            # vectors; with two workers it also overlaps the other slice)
            check_top=i == self.n_total - 1,
            # (slice 0 is the first merged into the store after the slices: it may write its
            # vectors there directly)
            out=self.found.free() if i == 0 else None,
        )

    def absorb(self, r: SliceResult) -> None:
        """Record a finished slice (its result, shift, inertia counts, statistics)."""
        info = self.info
        self.results[r.spec.index] = r
        info.shifts.append(r.sigma)
        info.krylov_dims.append(r.krylov_dim)
        info.n_operator_applications += r.n_applied
        info.n_factorizations += 1
        self.checks.append((r.sigma, r.n_below))
        if r.check is not None:
            self.checks.append(r.check)
            info.n_factorizations += 1

    # ---- running ---------------------------------------------------------------------------

    def _submit(self, pool: Any, running: dict[Any, int], settled: bool = False) -> None:
        """Plan the next slice and submit it to the pool."""
        self.specs.append(self.plan(len(self.specs), settled))
        running[pool.submit(run_slice, self.ctx, self.specs[-1], self.seed)] = len(self.specs) - 1

    def _run_slices(self) -> None:
        """Run the planned slices in a pool of ``workers`` threads (more when the density
        estimate was short), then merge their pairs into :attr:`found`."""
        import concurrent.futures as cf

        workers, ctx = self.workers, self.ctx
        t_slices = time.perf_counter()
        with cf.ThreadPoolExecutor(max_workers=workers) if workers > 1 else InlinePool() as pool:
            running: dict[cf.Future[SliceResult], int] = {}
            try:
                while True:
                    while len(running) < max(workers, 1):
                        i = len(self.specs)
                        if not i < self.n_total or not self.plannable(i):
                            break
                        self._submit(pool, running)
                    if not running:
                        got = self.base + sum(len(r.lam) for r in self.results.values())
                        if got >= self.target or len(self.specs) > 4 * self.n_total + 20:
                            break
                        self.n_total += 1  # the density estimate was short: one more slice
                        self._submit(pool, running, settled=True)
                        continue
                    # (a short timeout while the next slice waits for an inertia count)
                    waiting = len(running) < max(workers, 1) and len(self.specs) < self.n_total
                    done, _ = cf.wait(
                        running, timeout=0.01 if waiting else None, return_when=cf.FIRST_COMPLETED
                    )
                    for f in sorted(done, key=lambda f: running[f]):
                        del running[f]
                        self.absorb(f.result())
            except BaseException:
                ctx.cancel.set()
                for f in running:
                    f.cancel()
                raise
            finally:
                if ctx.error is not None:
                    raise ctx.error
        for i in sorted(self.results):
            self.found.add(self.results[i].lam, self.results[i].Y)
        self.results.clear()
        dedupe(self.found, self.base, self.scale)
        self.info.timings["slices"] = time.perf_counter() - t_slices

    # ---- verification by inertia; repair deficits ----------------------------------------

    def _check_above_k(self, rng: np.random.Generator) -> None:
        """Factor at a shift in a gap just above the ``k``-th eigenvalue found (unless an
        inertia count above it exists already) and record its inertia."""
        found, k, scale = self.found, self.k, self.scale
        lam_sorted = np.sort(found.lam)
        if any(s > lam_sorted[min(k, found.count) - 1] for s, _ in self.checks):
            return
        tau = None
        for j in range(k - 1, found.count - 1):
            lo_, hi_ = lam_sorted[j], lam_sorted[j + 1]
            if hi_ - lo_ > 1e-7 * max(abs(hi_), scale):
                tau = 0.5 * (lo_ + hi_)
                break
        if tau is None:
            tau = lam_sorted[-1] * (1 + 1e-6) + 1e-6 * scale
        spare, self.ctx.local.spare = getattr(self.ctx.local, "spare", None), None
        op = ShiftInvert(
            self.ctx.A,
            tau,
            rng=rng,
            ordering=self.ctx.ordering,
            reuse=spare,
            spacing=1e-3 * max(lam_sorted[-1] - lam_sorted[k - 1], scale),
        )
        self.info.n_factorizations += 1
        self.checks.append((op.sigma, op.n_below))

    def _deficit(self) -> tuple[float, float, int] | None:
        """The first interval ``[previous shift, shift)`` with fewer eigenvalues found than
        the inertia counts, as ``(lo, hi, missing)``; ``None`` when every count matches.

        Raises
        ------
        RuntimeError
            More eigenvalues found below a shift than its inertia counts.
        """
        self.checks.sort()
        prev = -np.inf
        for s, nu in self.checks:
            have = self.found.below(s)
            if have > nu:
                raise RuntimeError(
                    f"eigensolver: {have} eigenvalues found below {s:.6g} but inertia counts {nu}"
                )
            if have < nu:
                return prev, s, nu - have
            prev = s
        return None

    def _repair(self, bad: tuple[float, float, int], index: int) -> None:
        """Search ``[lo, hi)`` again for ``missing`` eigenpairs, the found ones deflated."""
        found = self.found
        lo, hi, missing = bad
        lo = max(lo, 0.0) if np.isfinite(lo) else 0.0
        self.info.messages.append(
            f"inertia check: {missing} eigenvalue(s) in [{lo:.6g}, {hi:.6g}) were missed; "
            "searching again with the found ones deflated"
        )
        near = np.flatnonzero(
            (found.lam >= lo - 0.25 * (hi - lo)) & (found.lam <= hi + 0.25 * (hi - lo))
        )
        near = near[near >= self.n_null]  # the null space is deflated in every slice already
        below = bool(np.any(found.lam[: found.count] < lo - 0.25 * (hi - lo)))
        spec = SliceSpec(
            index,
            0.5 * (lo + hi),
            lo,
            hi,
            max(missing, 4),
            np.asfortranarray(found.Y[:, near]),
            check_below=below and lo > 0,
        )
        r = run_slice(self.ctx, spec, self.seed)
        self.absorb(r)
        old = found.count
        found.add(r.lam, r.Y)
        dedupe(found, old, self.scale)

    def _verify(self) -> None:
        """Compare the inertia counts with the eigenvalues found; repair deficits (6 tries)."""
        t_ver = time.perf_counter()
        rng = np.random.default_rng([self.seed, 999])
        for attempt in range(6):
            self._check_above_k(rng)
            bad = self._deficit()
            if bad is None:
                break
            self._repair(bad, 10_000 + attempt)
        else:
            raise RuntimeError("eigensolver: could not account for every eigenvalue (inertia)")
        self.info.timings["verification"] = time.perf_counter() - t_ver

    def solve(self) -> tuple[FloatArray, FloatArray]:
        """Run the slices, verify by inertia; returns ``(lam (k,), Y (n,k))``, ascending."""
        self._run_slices()
        self._verify()
        found, k = self.found, self.k
        if found.count < k:
            raise RuntimeError(f"eigensolver: found only {found.count} of {k} eigenpairs")
        o = np.argsort(found.lam, kind="stable")[:k]
        lam = found.lam[o]
        if np.array_equal(o, np.arange(k)):  # (in order already: a view, no n × k copy)
            Y = found.Y[:, :k]
        else:
            Y = np.asfortranarray(found.Y[:, o])
        self.info.messages.append(
            f"inertia checks at {len(self.checks)} shifts: every eigenvalue below "
            f"{max(s for s, _ in self.checks):.6g} was found"
        )
        return lam, Y
