"""What the window's page documents, read as the tests check it: the keys of the **Keys:** item
of docs/window.md (the README's window section moved there)."""

from __future__ import annotations

import re
from pathlib import Path

WINDOW_PAGE = Path(__file__).resolve().parents[2] / "docs" / "window.md"
SYMBOLS = {"→": "right", "←": "left", "space": "space"}


def window_page_keys() -> list[str]:
    """The keys in the **Keys:** item of the window's page (docs/window.md), as the adapter
    names them."""
    text = WINDOW_PAGE.read_text(encoding="utf-8")
    start = text.index("**Keys:**")
    item = text[start : text.index("\n\n", start)]
    keys: list[str] = []
    for token in re.findall(r"`([^`]+)`", item):
        if re.fullmatch(r"\d", token):
            keys.append(token)
        elif token in SYMBOLS:
            keys.append(SYMBOLS[token])
        elif re.fullmatch(r"[A-Z]", token):
            keys.append(token.lower())
        elif token.startswith("--"):
            continue  # an option, not a key
        else:
            raise AssertionError(f"documented key {token!r} is not understood by this check")
    digits = sorted(int(k) for k in keys if k.isdigit())
    if len(digits) >= 2:  # `1`–`6`: the range
        keys += [str(i) for i in range(digits[0], digits[-1] + 1)]
    return sorted(set(keys))
