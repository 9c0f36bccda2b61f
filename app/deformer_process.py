"""A handle set's deformers in a persistent child process: the window keeps drawing while a big
mesh's systems are factorized and while each move is solved.

CHOLMOD holds the GIL while it factorizes and back-substitutes (seconds at 692k vertices), so a
worker thread froze the window for as long. Here :func:`build_remote` builds the handle set
(:func:`~.state.handle_sets.build_set`: discs, fixed region, each method's factorization) in a
child process (:class:`~.ipc.Child`) and the deformers stay there: the factors never cross a
process boundary. The window holds a :class:`RemoteSet` (what the Deform state reads of a
:class:`~.state.handle_sets.Built`) whose :class:`RemoteDeformer` s answer with what the child
sent last (energy, iterations, system figures) and solve by a round trip: targets down, the
positions (and the rotation-error map, computed there) up through shared memory
(:func:`~.ipc.pack`). A solve is called from a job's thread, which waits on the pipe without
the GIL. Cancel ends the child; so do :meth:`RemoteSet.close` and garbage collection.
"""

from __future__ import annotations

import dataclasses
import weakref
from typing import Any

import numpy as np

from meshlap_core.deform import SystemStats, rotation_error

from .ipc import Child, ChildReporter, error_message, pack, unpack


def _figures(d: Any) -> dict[str, Any]:
    """What the window shows of a deformer (plain data)."""
    return {
        "energy": float(d.energy()),
        "handle_error": float(d.handle_error()),
        "iteration": int(getattr(d, "iteration", 0)),
        "energies": [float(e) for e in getattr(d, "energies", [])],
    }


def _serve(conn: Any, mesh: Any, key: tuple[Any, ...]) -> None:
    """The child: build the set, describe it, then answer solves until told to stop."""
    from .state.deform import DeformState
    from .state.handle_sets import build_set

    try:
        V, F = unpack(mesh)
        built = build_set(V, F, key, None, ChildReporter(conn), None)
        about = {
            m: {
                "handles": d.handles,
                "fixed": d.fixed,
                "stats": dataclasses.asdict(d.stats),
                "setup_seconds": float(d.setup_seconds),
                "energy_name": d.energy_name,
                **_figures(d),
            }
            for m, d in built.deformers.items()
        }
        r = built.regions
        regions = (r.seeds, r.vertices, r.region, r.distance, float(r.radius))
        conn.send(("built", pack((regions, built.fixed, built.region_of, about, built.seconds))))
    except BaseException as exc:  # reported, never lost
        conn.send(("error", error_message(exc)))
        return
    terms: dict[str, Any] = {}
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message[0] != "solve":
            return
        _, method, targets, iterations, tolerance, colour = message
        try:
            d = built.deformers[method]
            U, done, seconds = DeformState.solve_work(d, unpack(targets), iterations, tolerance)
            field = None
            if colour == "rotation error":
                field, terms[method] = rotation_error(d.V, d.F, U, terms=terms.get(method))
            conn.send(("solved", pack((U, done, seconds, _figures(d), field))))
        except BaseException as exc:
            conn.send(("error", error_message(exc)))


class RemoteDeformer:
    """One method's deformer in the child, as the Deform state reads it (see the module
    docstring): attributes from the child's last answer, :meth:`solve` a round trip."""

    def __init__(self, owner: RemoteSet, method: str, about: dict[str, Any], V: Any, F: Any):
        self.owner, self.method, self.V, self.F = owner, method, V, F
        self.handles, self.fixed = np.asarray(about["handles"]), np.asarray(about["fixed"])
        self.stats = SystemStats(**about["stats"])
        self.setup_seconds = about["setup_seconds"]
        self.energy_name = about["energy_name"]
        self.remote_field: tuple[str, Any] | None = None  # (colour, values) of the last solve
        self._take(about)

    def _take(self, fig: dict[str, Any]) -> None:
        self._energy, self._handle_error = fig["energy"], fig["handle_error"]
        self.iteration, self.energies = fig["iteration"], fig["energies"]

    def energy(self) -> float:
        return self._energy

    def handle_error(self) -> float:
        return self._handle_error

    def solve(
        self, targets: Any, iterations: int, tolerance: float, colour: str
    ) -> tuple[Any, bool, float]:
        """Solve in the child (a job's thread: waits on the pipe without the GIL)."""
        child = self.owner.child
        child.send(("solve", self.method, pack(np.asarray(targets)), iterations, tolerance, colour))
        _, payload = child.receive()
        U, done, seconds, fig, field = payload
        self._take(fig)
        self.remote_field = (colour, field) if field is not None else None
        return np.array(U), bool(done), float(seconds)


class RemoteSet:
    """A :class:`~.state.handle_sets.Built` whose deformers live in a child process."""

    remote = True

    def __init__(self, child: Child, key: tuple[Any, ...], V: Any, F: Any, built: Any) -> None:
        from meshlap_core.deform import HandleRegions

        regions, fixed, region_of, about, seconds = built
        self.child, self.key, self.seconds = child, key, seconds
        self.regions = HandleRegions(*regions)
        self.fixed, self.region_of, self.graph = np.asarray(fixed), region_of, None
        self.deformers = {m: RemoteDeformer(self, m, a, V, F) for m, a in about.items()}
        self._end = weakref.finalize(self, child.end, ("stop",), 1.0)

    def close(self) -> None:
        """End the child (its factors go with it)."""
        self._end()


def build_remote(V: Any, F: Any, key: tuple[Any, ...], reporter: Any) -> RemoteSet:
    """Build the handle set ``key`` in a new child process (a job's work: progress relayed to
    ``reporter``; Cancel ends the child).

    Raises
    ------
    NoChildProcess
        No child process can start here (the caller builds in its thread instead).
    """
    child = Child(_serve, pack((np.asarray(V), np.asarray(F))), key, duplex=True, name="deformer")
    try:
        _, built = child.receive(reporter)
    except BaseException:
        child.end()
        raise
    return RemoteSet(child, key, V, F, built)
