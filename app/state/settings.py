"""A panel's settings as one typed schema: each setting declared once, everything else derived.

A panel declares its settings in its :class:`~meshlap_app.panel_spec.PanelSpec` as a
:class:`Settings` of typed fields (:class:`Choice`, :class:`Toggle`, :class:`Integer`,
:class:`Number`, :class:`Text`, :class:`Custom`). Each carries its key, default, range or
choices, widget label and tooltip, whether it was added after the first session files, its
``meshlap view`` / ``meshlap animate`` flag (:class:`Flag`) and its value in a *quiet* session
(restored for another panel's animation: nothing computed). From that one declaration come:

- the panel's section of a saved session and its checks (:meth:`Settings.check`: every value
  refused names ``section.key``; huge JSON integers, NaN and wrong types included);
- the state's defaults (:meth:`Settings.default`);
- the command-line flags, their help and their checks (:meth:`Setting.from_flag`);
- the widgets' labels, tooltips and limits (:mod:`meshlap_app.setting_widgets`);
- the tests' tables (:meth:`Setting.sample`, :meth:`Setting.bad_values`).

Every number a user can type has both bounds: an integer at most :data:`MAX_INT` (imgui's
integer widgets hold 32 bits: a larger session value would overflow the slider), a float
finite (the bounds a mesh sets further are the spec's ``check_mesh``). No polyscope, no numpy.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Callable, Iterator
from dataclasses import KW_ONLY, dataclass
from typing import Any, ClassVar

from meshlap_core.errors import MeshError
from meshlap_core.options import check_choice

MAX_INT = 2**31 - 1
"""The largest integer a setting may hold (imgui's integer fields and sliders are 32-bit); a
vertex index, count or seed is bounded further by the mesh or the core."""
FLOAT_MAX = sys.float_info.max
"""The bound of a float that only the mesh limits (its check is the spec's ``check_mesh``)."""


class _Unset:
    """A marker: a :class:`Flag` or :class:`Setting` attribute not given."""

    def __repr__(self) -> str:
        return "UNSET"


UNSET: Any = _Unset()


def shown(x: Any) -> str:
    """``x`` as a message quotes it: JSON, and an integer of more than 40 digits by its size
    (never a page of digits)."""
    if isinstance(x, int) and not isinstance(x, bool) and abs(x) >= 10**40:
        digits = int(abs(x).bit_length() * math.log10(2)) + 1
        return f"a number of about {digits} digits"
    try:
        text = json.dumps(x)
    except (TypeError, ValueError):
        text = repr(x)
    return text if len(text) <= 80 else text[:77] + "..."


def integer_problem(x: Any, lo: int, hi: int) -> str | None:
    """What is wrong with ``x`` as an integer in ``[lo, hi]`` (``None``: nothing)."""
    if not isinstance(x, int) or isinstance(x, bool) or not lo <= x <= hi:
        return f"must be an integer {lo} to {hi}, got {shown(x)}"
    return None


def number_problem(x: Any, lo: float, hi: float, lo_open: bool = False) -> str | None:
    """What is wrong with ``x`` as a finite number in ``[lo, hi]`` (``(lo, hi]`` when
    ``lo_open``); a JSON integer too large for a float is refused, not an OverflowError."""
    low = f"> {lo:g}" if lo_open else f">= {lo:g}"
    if not isinstance(x, int | float) or isinstance(x, bool):
        return f"must be a finite number, got {shown(x)}"
    try:
        v = float(x)
    except OverflowError:
        return f"must be a finite number {low} and <= {hi:g}, got {shown(x)}"
    if not math.isfinite(v):
        return f"must be a finite number, got {shown(x)}"
    if (v <= lo if lo_open else v < lo) or v > hi:
        if lo_open:
            return f"must be {low} and <= {hi:g}, got {shown(x)}"
        return f"must be between {lo:g} and {hi:g}, got {shown(x)}"
    return None


@dataclass(frozen=True)
class Flag:
    """A setting's command-line flag (``--vertex``).

    ``help`` replaces the setting's label in ``--help``; ``default`` is the command's own
    default when it is not the setting's (``meshlap animate --lam``: 1, the window's 0.5).
    """

    name: str
    help: str = ""
    default: Any = UNSET

    def __post_init__(self) -> None:
        if not self.name.startswith("--") or len(self.name) < 3:
            raise ValueError(f"a flag is spelt --name, got {self.name!r}")

    @property
    def dest(self) -> str:
        """Its key in the options dict (``--heat-vertex`` → ``heat_vertex``)."""
        return self.name[2:].replace("-", "_")


@dataclass(frozen=True)
class Setting:
    """One setting of a panel (abstract: a typed subclass is declared, as
    ``Integer("steps", 1, lo=1, hi=1000, label="Euler steps", tooltip=...)``).

    Attributes
    ----------
    key : str
        Its key in the panel's session section.
    default : Any
        The viewer's start value (and the state's default).
    label : str
        The label of the widget that sets it ("": none of its own, e.g. derived from others or
        set by clicks); the widget tour checks that a test drove it.
    tooltip : str
        The widget's tooltip, and the flag's help when the flag has none.
    added : bool
        Added after the first session files: written only when it is not the default (an
        older meshlap, which refuses unknown keys, still reads a file that does not need it).
    view, animate : Flag or None
        Its ``meshlap view`` / ``meshlap animate`` flag.
    widget : str
        How it is drawn: ``"slider"`` or ``"input"`` for a number (its type's default when
        empty: a combo, a checkbox, an input field, a slider for a float), ``"button"`` when
        a button of that label sets it (the panel draws it), ``"none"`` when no widget does.
    quiet : Any
        Its value when the session is restored for another panel's animation (nothing
        computed: no basis read, no run replayed); UNSET keeps the saved one.
    example : Any
        A valid value other than the default for the tests (UNSET: derived).
    also : tuple of str
        The labels of its other widgets, when more than one sets it (the isolines' count
        beside their toggle, the control points of a drawn curve): with ``label``, every
        widget that changes it (the widget audit of ``tests/test_viewer_widgets.py``).
    """

    key: str
    default: Any
    _: KW_ONLY
    label: str = ""
    tooltip: str = ""
    added: bool = False
    view: Flag | None = None
    animate: Flag | None = None
    widget: str = ""
    quiet: Any = UNSET
    example: Any = UNSET
    also: tuple[str, ...] = ()

    widgets: ClassVar[tuple[str, ...]] = ("button", "none")

    def __post_init__(self) -> None:
        if not self.key.isidentifier():
            raise ValueError(f"a setting key is an identifier, got {self.key!r}")
        if self.widget and self.widget not in self.widgets:
            raise ValueError(f"{self.key}: widget {self.widget!r} is not one of {self.widgets}")
        if (self.drawn_as != "none") != bool(self.label):
            raise ValueError(f"{self.key}: a label names its widget (widget='none': no label)")
        if self.also and not self.label:
            raise ValueError(f"{self.key}: other widgets ({self.also}) but no label of its own")
        problem = self.problem(self.default)
        if problem:
            raise ValueError(f"{self.key}: its default {problem}")
        for what, value in (("quiet", self.quiet), ("example", self.example)):
            if value is not UNSET and (problem := self.problem(value)):
                raise ValueError(f"{self.key}: its {what} value {problem}")

    @property
    def drawn_as(self) -> str:
        """Its widget: ``widget``, or its type's default (the first of ``widgets``)."""
        return self.widget or self.widgets[0]

    @property
    def labels(self) -> tuple[str, ...]:
        """The labels of every widget that sets it (``label`` and ``also``; none when it has
        no widget)."""
        return (self.label, *self.also) if self.label else ()

    # -------------------------------------------------------------- values
    def problem(self, value: Any) -> str | None:
        """What is wrong with ``value`` (``None``: nothing); the message follows the name."""
        raise NotImplementedError

    def coerce(self, value: Any) -> Any:
        """A checked value as the section keeps it (a float setting holds floats)."""
        return value

    def checked(self, value: Any, name: str) -> Any:
        """``value`` coerced, or a :class:`MeshError` naming ``name`` (a widget's label, a
        flag)."""
        problem = self.problem(value)
        if problem:
            raise MeshError(problem, name)
        return self.coerce(value)

    def describe(self) -> str:
        """What it takes, for help texts (``an integer 1 to 1000``)."""
        return ""

    # -------------------------------------------------------------- flags
    def parse(self, text: str) -> Any:
        """The value a command line typed as ``text`` (before the range check)."""
        return text

    def from_flag(self, value: Any, flag: str) -> Any:
        """A flag's value (typed text, or a value given from Python) parsed and checked, or a
        :class:`MeshError` naming ``flag``."""
        if isinstance(value, str):
            try:
                value = self.parse(value)
            except (ValueError, OverflowError):
                expected = self.describe() or "a valid value"
                raise MeshError(f"{expected} expected, got {shown(value)}", flag) from None
        return self.checked(value, flag)

    def flag_help(self, flag: Flag, panel: str, default: bool = True) -> str:
        """``--help`` text of ``flag``: the panel, what it sets, what it takes and (when
        ``default``, or the flag has its own) its default."""
        what = flag.help or self.label or self.key
        text = f"{panel}: {what}; {self.describe()}"
        if flag.default is not UNSET:
            return f"{text} (default {flag.default})"
        return f"{text} (default {self.default})" if default else text

    def metavar(self) -> str | None:
        return None

    # -------------------------------------------------------------- the tests' tables
    def sample(self) -> Any:
        """A valid value other than the default (``example`` when declared)."""
        if self.example is not UNSET:
            return self.example
        return self._derived_sample()

    def _derived_sample(self) -> Any:
        raise ValueError(f"{self.key}: declare an example value")

    def bad_values(self) -> tuple[Any, ...]:
        """Values a session must refuse (wrong type, out of range, NaN, huge integers)."""
        return ()


@dataclass(frozen=True, kw_only=True)
class Choice(Setting):
    """One string of ``choices`` (a combo)."""

    choices: tuple[str, ...]
    widgets: ClassVar[tuple[str, ...]] = ("combo", "button", "none")

    def __post_init__(self) -> None:
        if not self.choices or len(set(self.choices)) != len(self.choices):
            raise ValueError(f"{self.key}: choices must be distinct and not empty")
        super().__post_init__()

    def problem(self, value: Any) -> str | None:
        if not isinstance(value, str):
            return f"must be a string, got {type(value).__name__}"
        if value not in self.choices:
            return f"must be one of {', '.join(self.choices)}, got {shown(value)}"
        return None

    def checked(self, value: Any, name: str) -> Any:
        """The one standard error of a choice (:func:`~meshlap_core.options.check_choice`:
        ``unknown <what> 'x'; choose one of ...``) naming ``name``."""
        if isinstance(value, str):
            return check_choice(value, self.choices, self.key.replace("_", " "), name)
        return super().checked(value, name)

    def describe(self) -> str:
        return "one of " + ", ".join(self.choices)

    def metavar(self) -> str | None:
        return "{" + ",".join(self.choices) + "}"

    def _derived_sample(self) -> Any:
        return next(c for c in self.choices if c != self.default)

    def bad_values(self) -> tuple[Any, ...]:
        return (3, None, "no such " + self.key)


@dataclass(frozen=True, kw_only=True)
class Toggle(Setting):
    """``true`` or ``false`` (a checkbox, or a button that switches it)."""

    widgets: ClassVar[tuple[str, ...]] = ("checkbox", "button", "none")

    def problem(self, value: Any) -> str | None:
        return None if isinstance(value, bool) else f"must be true or false, got {shown(value)}"

    def coerce(self, value: Any) -> Any:
        return bool(value)

    def describe(self) -> str:
        return "true or false"

    def _derived_sample(self) -> Any:
        return not self.default

    def bad_values(self) -> tuple[Any, ...]:
        return (1, "yes", None)


@dataclass(frozen=True, kw_only=True)
class Integer(Setting):
    """An integer in ``[lo, hi]`` (``hi`` at most :data:`MAX_INT`); ``above`` says why a
    larger value is refused (formatted with the value as ``{x}``)."""

    lo: int
    hi: int
    above: str = ""
    widgets: ClassVar[tuple[str, ...]] = ("input", "slider", "button", "none")

    def __post_init__(self) -> None:
        if not (isinstance(self.lo, int) and isinstance(self.hi, int) and self.lo < self.hi):
            raise ValueError(f"{self.key}: needs integer bounds lo < hi")
        if self.hi > MAX_INT or self.lo < -MAX_INT:
            raise ValueError(f"{self.key}: bounds beyond ±{MAX_INT} overflow the widgets")
        super().__post_init__()

    def problem(self, value: Any) -> str | None:
        if self.above and isinstance(value, int) and not isinstance(value, bool):
            if value > self.hi:  # a count too large: said why
                return f"must be {self.lo} to {self.hi} ({self.above.format(x=shown(value))})"
        return integer_problem(value, self.lo, self.hi)

    def coerce(self, value: Any) -> Any:
        return int(value)

    def clamp(self, value: int) -> int:
        return int(min(max(int(value), self.lo), self.hi))

    def describe(self) -> str:
        return f"an integer {self.lo} to {self.hi}"

    def parse(self, text: str) -> Any:
        return int(text.strip())

    def metavar(self) -> str | None:
        return "N"

    def _derived_sample(self) -> Any:
        return self.default + 1 if self.default < self.hi else self.default - 1

    def bad_values(self) -> tuple[Any, ...]:
        return (self.lo - 1, self.hi + 1, 1.5, "1", True, 10**400)


@dataclass(frozen=True, kw_only=True)
class Number(Setting):
    """A finite float in ``[lo, hi]`` (``(lo, hi]`` when ``lo_open``); a slider shows
    ``slider`` when given (a useful part of the range), else ``[lo, hi]``; ``fmt`` is how the
    widget prints it."""

    lo: float
    hi: float
    lo_open: bool = False
    slider: tuple[float, float] | None = None
    fmt: str = "%.3f"
    widgets: ClassVar[tuple[str, ...]] = ("slider", "input", "none")

    def __post_init__(self) -> None:
        if not (math.isfinite(self.lo) and math.isfinite(self.hi) and self.lo < self.hi):
            raise ValueError(f"{self.key}: needs finite bounds lo < hi")
        super().__post_init__()

    def problem(self, value: Any) -> str | None:
        return number_problem(value, self.lo, self.hi, self.lo_open)

    def coerce(self, value: Any) -> Any:
        return float(value)

    def clamp(self, value: float) -> float:
        return float(min(max(float(value), self.lo), self.hi))

    def describe(self) -> str:
        low = f"> {self.lo:g}" if self.lo_open else f">= {self.lo:g}"
        if self.hi >= FLOAT_MAX:  # bounded by the mesh (the spec's check_mesh)
            return f"a finite number {low}"
        return f"a number {low} and <= {self.hi:g}"

    def parse(self, text: str) -> Any:
        return float(text.strip())

    def metavar(self) -> str | None:
        return "X"

    def _derived_sample(self) -> Any:
        lo, hi = self.slider or (self.lo, self.hi)
        x = self.default + (hi - self.default) / 2 if self.default < hi else (lo + self.default) / 2
        return float(x)

    def bad_values(self) -> tuple[Any, ...]:
        below = self.lo if self.lo_open else self.lo - max(1.0, abs(self.lo))
        above = self.hi + max(1.0, abs(self.hi)) if self.hi < FLOAT_MAX / 4 else 10**309
        return ("1", True, float("nan"), float("inf"), 10**400, -(10**400), below, above)


@dataclass(frozen=True, kw_only=True)
class Text(Setting):
    """One line of text, at most ``max_len`` characters (a file name as typed)."""

    max_len: int = 4096
    widgets: ClassVar[tuple[str, ...]] = ("input", "none")

    def problem(self, value: Any) -> str | None:
        if not isinstance(value, str):
            return f"must be a string, got {type(value).__name__}"
        if len(value) > self.max_len or any(c in value for c in "\x00\n\r"):
            return f"must be one line of at most {self.max_len} characters"
        return None

    def describe(self) -> str:
        return f"one line of text (at most {self.max_len} characters)"

    def _derived_sample(self) -> Any:
        return self.default + "x"

    def bad_values(self) -> tuple[Any, ...]:
        return (3, None, "a\nb", "x" * (self.max_len + 1))


@dataclass(frozen=True, kw_only=True)
class Custom(Setting):
    """A structured value (a list, an object) with its own ``check`` (what is wrong, or
    ``None``) and ``normalize`` (the value as kept, e.g. without duplicates); ``refused``
    lists values the check must refuse (the tests' table). Flags cannot take one. Its
    widgets are drawn by its panel: ``"none"``, a ``"button"``, ``"drag"`` points in a plot,
    a ``"checkbox"`` with more widgets (``also``)."""

    check: Callable[[Any], str | None]
    normalize: Callable[[Any], Any] | None = None
    refused: tuple[Any, ...] = ()
    widgets: ClassVar[tuple[str, ...]] = ("none", "button", "drag", "checkbox")

    def __post_init__(self) -> None:
        if self.view is not None or self.animate is not None:
            raise ValueError(f"{self.key}: a structured setting has no flag")
        super().__post_init__()

    def problem(self, value: Any) -> str | None:
        return self.check(value)

    def coerce(self, value: Any) -> Any:
        return self.normalize(value) if self.normalize is not None else value

    def bad_values(self) -> tuple[Any, ...]:
        return self.refused


class Settings:
    """A panel's settings in order (its session section's keys, in the file's order):
    ``Settings(Choice(...), Integer(...), ...)``."""

    def __init__(self, *fields: Setting) -> None:
        by_key: dict[str, Setting] = {}
        for s in fields:
            if not isinstance(s, Setting) or type(s) is Setting:
                raise TypeError(f"a setting is a typed Setting, got {s!r}")
            if s.key in by_key:
                raise ValueError(f"setting {s.key!r} is declared twice")
            by_key[s.key] = s
        self.fields: tuple[Setting, ...] = tuple(fields)
        self._by_key = by_key

    def __repr__(self) -> str:
        return f"Settings({', '.join(self.keys())})"

    def __iter__(self) -> Iterator[Setting]:
        return iter(self.fields)

    def __len__(self) -> int:
        return len(self.fields)

    def __contains__(self, key: object) -> bool:
        return key in self._by_key

    def __getitem__(self, key: str) -> Any:
        return self._by_key[key]

    def keys(self) -> tuple[str, ...]:
        return tuple(self._by_key)

    def default(self, key: str) -> Any:
        """The default of ``key`` (a state's dataclass field takes it from here)."""
        return self._by_key[key].default

    def defaults(self) -> dict[str, Any]:
        """Every setting at its default (copies: a list default is not shared)."""
        return {s.key: json.loads(json.dumps(s.default)) for s in self.fields}

    def samples(self) -> dict[str, Any]:
        """Every setting at its :meth:`Setting.sample` value."""
        return {s.key: s.sample() for s in self.fields}

    def added(self) -> tuple[str, ...]:
        """The keys added after the first session files."""
        return tuple(s.key for s in self.fields if s.added)

    def quiet(self) -> dict[str, Any]:
        """The values restored for another panel's animation (nothing computed)."""
        return {s.key: s.quiet for s in self.fields if s.quiet is not UNSET}

    def check(self, values: Any, section: str, source: Any) -> dict[str, Any]:
        """The section ``values`` of a session file checked, missing keys at their defaults.

        Raises
        ------
        MeshError
            Not an object, an unknown key, or a value refused (named ``"section.key"``).
        """
        if not isinstance(values, dict):
            raise MeshError(f'"{section}" must be an object, got {shown(values)}', source)
        unknown = sorted(set(values) - set(self._by_key))
        if unknown:
            raise MeshError(
                f"unknown key(s) in {section!r}: {', '.join(map(repr, unknown))}", source
            )
        out = self.defaults()
        for s in self.fields:
            if s.key in values:
                problem = s.problem(values[s.key])
                if problem:
                    raise MeshError(f'"{section}.{s.key}" {problem}', source)
                out[s.key] = s.coerce(values[s.key])
        return out
