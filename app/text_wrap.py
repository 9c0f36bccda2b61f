"""Text wrapped only at spaces (imgui's own wrap also breaks after ``.``, inside a file name)."""

from __future__ import annotations

from collections.abc import Callable


def wrap_at_spaces(text: str, width: float, measure: Callable[[str], float]) -> list[str]:
    """Split ``text`` into lines at most ``width`` wide, breaking only at spaces.

    Parameters
    ----------
    text : str
        The text (its own line breaks are kept).
    width : float
        The widest a line may be (a word wider than that is a line of its own).
    measure : callable
        The width of a string.

    Returns
    -------
    list of str
        The lines, each word whole.
    """
    lines: list[str] = []
    for paragraph in text.split("\n"):
        line = ""
        for word in paragraph.split(" "):
            candidate = f"{line} {word}" if line else word
            if line and measure(candidate) > width:
                lines.append(line)
                line = word
            else:
                line = candidate
        lines.append(line)
    return lines
