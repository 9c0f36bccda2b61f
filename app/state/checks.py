"""Value checks of a saved session's settings (each panel's state module declares its section
with them, ``SESSION``): each returns what is wrong with a value, or ``None``."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from typing import Any

Check = Callable[[Any], str | None]  # returns what is wrong with a value, or None
Schema = dict[str, tuple[Any, Check]]  # key -> (default, check): a panel's session section


def one_of(choices: tuple[str, ...]) -> Check:
    """A string among ``choices``."""

    def check(x: Any) -> str | None:
        if not isinstance(x, str):
            return f"must be a string, got {type(x).__name__}"
        return None if x in choices else f"must be one of {', '.join(choices)}, got {x!r}"

    return check


def boolean(x: Any) -> str | None:
    """``true`` or ``false``."""
    return None if isinstance(x, bool) else f"must be true or false, got {json.dumps(x)}"


def integer(lo: int, hi: int | None = None) -> Check:
    """An integer in ``[lo, hi]`` (no upper bound when ``hi`` is ``None``)."""

    def check(x: Any) -> str | None:
        if not isinstance(x, int) or isinstance(x, bool):
            return f"must be an integer, got {json.dumps(x)}"
        if x < lo or (hi is not None and x > hi):
            top = f" and <= {hi}" if hi is not None else ""
            return f"must be >= {lo}{top}, got {x}"
        return None

    return check


def number(lo: float = -math.inf, hi: float = math.inf, positive: bool = False) -> Check:
    """A finite number in ``[lo, hi]`` (``> 0`` too when ``positive``)."""

    def check(x: Any) -> str | None:
        if not isinstance(x, int | float) or isinstance(x, bool) or not math.isfinite(x):
            return f"must be a finite number, got {json.dumps(x)}"
        if positive and not x > 0:
            return f"must be > 0, got {x}"
        if not lo <= x <= hi:
            return f"must be between {lo:g} and {hi:g}, got {x}"
        return None

    return check
