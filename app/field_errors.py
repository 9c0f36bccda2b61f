"""Errors of typed values drawn under their field (mixed into :class:`.ui.UI`).

A field that was entered (Enter) records ``(section, label, typed text)`` in ``entered``; when
the section's handler then refuses the value, the host calls :meth:`FieldErrors.field_failed`
and the message (quoting the text) is drawn under that field until the field is fixed or the
context changes (:meth:`FieldErrors.clear_field_errors`).
"""

from __future__ import annotations

from typing import Any


def read_float(text: str, label: str) -> float:
    """The number typed into the float field ``label``, as a double (C's ``strtod``, as
    Python's ``float``: ``1e308`` stays ``1e308``, ``1e309`` is ``inf``, which the panel's
    check then refuses).

    Raises
    ------
    ValueError
        ``text`` is empty or not a number, naming the field.
    """
    t = text.strip()
    if not t:
        raise ValueError(f"{label}: the field is empty; type a number and press Enter")
    try:
        return float(t)
    except ValueError:
        raise ValueError(f"{label}: {text!r} is not a number") from None


class FieldErrors:
    """The field-error half of the UI adapter: ``entered`` (the field entered in this section
    this frame), ``field_errors`` ((section, label) -> message) and whether a field of the
    current section drew its error this frame."""

    im: Any  # the UI's imgui module
    section: str
    entered: tuple[str, str, str] | None
    field_errors: dict[tuple[str, str], str]
    _field_error_shown: bool

    def error(self, text: str) -> Any:  # pragma: no cover - the UI's
        raise NotImplementedError

    def _number_flags(self) -> int:
        """imgui flags of a numeric field: applied on Enter only, and a click into it selects
        its whole number, so what is typed replaces it (with the cursor put where the click
        was, a Ctrl+A that imgui did not see left ``0.50.25`` in the field, refused)."""
        flags = self.im.ImGuiInputTextFlags_EnterReturnsTrue
        return flags | self.im.ImGuiInputTextFlags_AutoSelectAll

    def field_failed(self, message: str) -> str:
        """``message`` (a refused value) belongs to the field entered in this section this
        frame, if one was: it is kept to be drawn right under that field (from the next frame
        on), quoting what was typed. Returns the message to keep for the section."""
        if self.entered is None or self.entered[0] != self.section:
            return message
        _, label, typed = self.entered
        typed = typed.strip()
        if typed and typed not in message:
            message = f"{message} (you typed {typed!r})"
        self.field_errors[(self.section, label)] = message
        return message

    def clear_field_errors(self, section: str | None = None) -> None:
        """Forget the field errors of ``section`` (``None``: of every section)."""
        self.field_errors = {
            k: m for k, m in self.field_errors.items() if section is not None and k[0] != section
        }

    def field_error_shown(self) -> bool:
        """Whether a field of the current section drew its error this frame."""
        return self._field_error_shown

    def _draw_field_error(self, label: str) -> None:
        message = self.field_errors.get((self.section, label))
        if message:
            self.error(message)
            self._field_error_shown = True

    def _entered(self, label: str, text: str) -> None:
        self.entered = (self.section, label, text)
