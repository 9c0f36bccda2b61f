"""What the README documents, read as the tests check it: the keys of its **Keys:** item."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"
SYMBOLS = {"→": "right", "←": "left", "space": "space"}


def readme_keys() -> list[str]:
    """The keys in the README's **Keys:** item, as the adapter names them."""
    text = README.read_text(encoding="utf-8")
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
            raise AssertionError(f"README key {token!r} is not understood by this check")
    digits = sorted(int(k) for k in keys if k.isdigit())
    if len(digits) >= 2:  # `1`–`6`: the range
        keys += [str(i) for i in range(digits[0], digits[-1] + 1)]
    return sorted(set(keys))
