"""Numbers as the panels show them: written to a few significant digits, and recognised again.

:func:`sig` writes a computed quantity with 4 significant digits, printing round-off as ``0``;
:func:`is_number` tells a table cell holding a number (right-aligned by
:meth:`meshlap_app.ui.UI.row`) from a word. Pure Python: no imgui, no polyscope.
"""

from __future__ import annotations


def sig(x: float, scale: float, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits, or ``0`` when it is round-off.

    Parameters
    ----------
    x : float
        The value to show.
    scale : float
        The size of the quantity ``x`` belongs to: ``|x| < 1e-12 · |scale|`` is round-off and
        shows as ``0`` (``F = -3.5e-18`` beside ``E = 1``).
    digits : int
        Significant digits.

    Returns
    -------
    str
        ``"0"`` or ``f"{x:.{digits}g}"``.

    Examples
    --------
    >>> sig(-3.5e-18, 1.0), sig(0.123456, 1.0), sig(1234567.0, 1.0)
    ('0', '0.1235', '1.235e+06')
    """
    if abs(x) < 1e-12 * abs(scale) or x == 0:
        return "0"
    return f"{x:.{digits}g}"


def is_number(cell: str) -> bool:
    """Is the table cell a number (``-0.5007``, ``38.07°``, ``1e-05``)?

    Those are right-aligned; ``-`` (no value) counts as a number too, so a column of numbers
    stays one column.

    Parameters
    ----------
    cell : str
        The cell's text, as shown.

    Returns
    -------
    bool

    Examples
    --------
    >>> is_number(" 38.07° "), is_number("-"), is_number("sum")
    (True, True, False)
    """
    t = cell.strip().rstrip("°")
    if t == "-":
        return True
    try:
        float(t)
    except ValueError:
        return False
    return True


def plural(n: int, noun: str) -> str:
    """``"1 step"``, ``"3 steps"``: ``n`` and ``noun``, with an ``s`` unless ``n`` is 1."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"
