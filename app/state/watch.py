"""The one invalidation rule of the viewer: derived things remember the inputs they were made
from, and are remade when those inputs differ.

Every input that can change carries a value that changes with it (``MeshState.version``, a
setting, ``SmoothingState.version``...). Whatever is derived from inputs (a registered
structure, an uploaded colour map, a cached offset) asks its :class:`Watch` whether the tuple of
inputs differs from the last one it was made from, instead of keeping a private counter.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any


class Watch:
    """Remembers, per name, the inputs a derived thing was last made from.

    >>> w = Watch()
    >>> w.changed("field", 1, "cotan"), w.changed("field", 1, "cotan")
    (True, False)
    >>> w.changed("field", 2, "cotan")
    True
    """

    def __init__(self) -> None:
        self._seen: dict[str, tuple[Any, ...]] = {}
        self._values: dict[str, Any] = {}

    def changed(self, name: str, *inputs: Hashable) -> bool:
        """Whether ``inputs`` differ from those of the last call for ``name`` (or there was
        none); they are remembered either way."""
        if self._seen.get(name) == inputs and name in self._seen:
            return False
        self._seen[name] = inputs
        return True

    def cached(self, name: str, inputs: tuple[Hashable, ...], make: Callable[[], Any]) -> Any:
        """The value ``make()`` gave for ``inputs``, made again only when they changed."""
        if self.changed(name, *inputs) or name not in self._values:
            self._values[name] = make()
        return self._values[name]

    def forget(self, *names: str) -> None:
        """Forget ``names`` (all when none is given): the next :meth:`changed` says True."""
        for name in names or tuple(self._seen):
            self._seen.pop(name, None)
            self._values.pop(name, None)

    def seen(self, name: str) -> tuple[Any, ...] | None:
        """The inputs last remembered for ``name`` (``None``: never, or forgotten)."""
        return self._seen.get(name)
